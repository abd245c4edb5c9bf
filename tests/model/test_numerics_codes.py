"""The integrator codes written out in the model are the kernels' own."""

from vimpact.kernels import layout
from vimpact.model.numerics import INTEGRATORS


def test_integrator_codes_are_the_kernel_codes():
    assert INTEGRATORS == {"euler": layout.EULER, "symplectic_euler": layout.SYMPLECTIC_EULER,
                           "verlet": layout.VERLET}
