"""vimpact: restitution of a sphere on a viscoelastic half-space (method of dimensionality reduction).

Public API (loaded lazily: ``import vimpact`` imports no numba, pandas or
pyarrow until a name that needs them is used)::

    import vimpact as v

    mat = v.Material.kelvin_voigt(nu=0.5, E=5e10, eta=1e5)       # Pa, Pa s
    scene = v.Scene(mat, R=0.2, m=10.0, v_z0=10.0, v_x0=5.0)      # m, kg, m/s
    res = v.simulate(scene)                                       # ImpactResult
    res.e_z, res.beta_x

Physics, conventions and units: ``docs/physics.md``.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from vimpact import _lazy
from vimpact.kernels.threads import configure as _configure_threads

_configure_threads()  # before numba starts its threads (vimpact.kernels.threads)

try:
    __version__ = version("vimpact")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0+unknown"

#: public name -> module that defines it
_EXPORTS = {
    "HERTZ_TIME_FACTOR": "vimpact.model.hertz",
    "HertzScales": "vimpact.model.hertz",
    "hertz_scales": "vimpact.model.hertz",
    "InputError": "vimpact.model.validation",
    "MODELS": "vimpact.model.material",
    "Material": "vimpact.model.material",
    "PronyFit": "vimpact.model.fit",
    "ShiftLaw": "vimpact.model.temperature",
    "load_material": "vimpact.model.material_file",
    "PRESETS": "vimpact.model.numerics",
    "Numerics": "vimpact.model.numerics",
    "Scene": "vimpact.model.scene",
    "STATUSES": "vimpact.engine.result",
    "UNITS": "vimpact.engine.result",
    "ImpactResult": "vimpact.engine.result",
    "KernelPath": "vimpact.engine.routing",
    "choose_path": "vimpact.engine.routing",
    "HalfSpaceError": "vimpact.engine.simulate",
    "explain": "vimpact.engine.simulate",
    "simulate": "vimpact.engine.simulate",
    "simulate_batch": "vimpact.engine.simulate",
    "RestitutionTable": "vimpact.lookup.table",
    "Body": "vimpact.model.pair",
    "Wall": "vimpact.model.pair",
    "pair_material": "vimpact.model.pair",
    "simulate_pair": "vimpact.engine.pairs",
    "simulate_pair_batch": "vimpact.engine.pairs",
}

__all__ = sorted(_EXPORTS) + ["__version__"]


def __getattr__(name: str):
    return _lazy.load(__name__, _EXPORTS, globals(), name)


def __dir__() -> list[str]:
    return __all__
