"""vimpact: restitution of a rigid sphere on a viscoelastic half-space (MDR).

Public API::

    from vimpact import Material, Scene, Numerics, simulate, simulate_batch

    mat = Material.kelvin_voigt(nu=0.5, E=5e10, eta=1e5)       # Pa, Pa s
    scene = Scene(mat, R=0.2, m=10.0, v_z0=10.0, v_x0=5.0)      # m, kg, m/s
    res = simulate(scene)                                       # ImpactResult
    res.e_z, res.e_x

Physics: PHYSICS.md (shipped with the project's docs); units in every docstring.
"""

from importlib.metadata import PackageNotFoundError, version

from .hertz import HERTZ_TIME_FACTOR, HertzScales, hertz_scales
from .material import MODELS, Material
from .numerics import PRESETS, Numerics
from .result import STATUSES, UNITS, ImpactResult
from .scene import Scene
from .paths import Path, choose_path
from .simulate import HalfSpaceError, explain, simulate, simulate_batch
from .table import RestitutionTable

try:
    __version__ = version("vimpact")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0+unknown"

__all__ = [
    "HERTZ_TIME_FACTOR", "HalfSpaceError", "HertzScales", "ImpactResult", "MODELS",
    "Material", "Numerics", "PRESETS", "Path", "RestitutionTable", "STATUSES", "Scene", "UNITS",
    "choose_path", "explain", "hertz_scales",
    "simulate", "simulate_batch", "__version__",
]
