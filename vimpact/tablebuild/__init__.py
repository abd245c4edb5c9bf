"""Building restitution tables: the workflow above the sweep spec and the lookup.

:mod:`vimpact.tablebuild.adaptive` builds an adaptive table from a sweep spec
with ``[grid] refine = "adaptive"`` (``vimpact table build SPEC``).
"""
