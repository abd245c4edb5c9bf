"""Building restitution tables: the workflow above the sweep and the lookup.

The sweep (:mod:`vimpact.sweep`) makes rows and the lookup (:mod:`vimpact.lookup`)
reads tables; neither imports the other. What needs both lives here:
:mod:`vimpact.tablebuild.verify` measures a table's interpolation error against
direct simulation, :mod:`vimpact.tablebuild.refine` refines a grid until its lookup
meets a tolerance, :mod:`vimpact.tablebuild.sweep` runs a sweep with that
refinement (``vimpact sweep``), and
:mod:`vimpact.tablebuild.adaptive` builds an adaptive table from a sweep spec
with ``[grid] refine = "adaptive"`` (``vimpact table build SPEC``).
"""
