"""DEM export: fit each DEM code's own contact constants to vimpact's restitution.

Modules: :mod:`~vimpact.dem.laws` (the codes' one-contact force laws, integrated
independently), :mod:`~vimpact.dem.fit` (constants fitted to ``e_z(v)``,
``beta_x(v)``), :mod:`~vimpact.dem.problem` (particle types, walls and contacts
from a TOML file), one module per code (:mod:`~vimpact.dem.lammps`,
:mod:`~vimpact.dem.liggghts`, :mod:`~vimpact.dem.mercurydpm`,
:mod:`~vimpact.dem.yade`, :mod:`~vimpact.dem.mfix`, :mod:`~vimpact.dem.rebound`)
and :mod:`~vimpact.dem.report`. Guide: ``docs/dem.md``.
"""

#: The DEM codes ``vimpact dem --for`` exports to (one module each).
CODES = ("lammps", "liggghts", "mercurydpm", "yade", "mfix", "rebound")
