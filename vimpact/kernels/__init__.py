"""numba kernels in kernel units: nothing here imports the API side (only numpy and numba).

- :mod:`~vimpact.kernels.jit`: the one decorator factory with every numba option
- :mod:`~vimpact.kernels.status`: the status table: names, kernel codes, meanings (no numba)
- :mod:`~vimpact.kernels.threads`: how numba's threads wait (set before they start)
- :mod:`~vimpact.kernels.layout`: integrator and status codes, output and record columns (no numba)
- :mod:`~vimpact.kernels.record`: the trajectory record writer
- :mod:`~vimpact.kernels.arms`: exact Maxwell-arm updates
- :mod:`~vimpact.kernels.elements`: MDR element kernels, compiled per effect set
- :mod:`~vimpact.kernels.continuum_kv`: the normal Kelvin-Voigt impact as a 1-DOF ODE
- :mod:`~vimpact.kernels.continuum_maxwell`: the full-stick impact of every rheology as an ODE
  (the continuum limit of the element row)
- :mod:`~vimpact.kernels.hermite`: cubic Hermite interpolation of restitution tables
"""
