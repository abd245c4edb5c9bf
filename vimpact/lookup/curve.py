"""e(v) curves: a table turned into restitution against impact speed for one sphere.

``e_z`` and ``e_x`` depend on the dimensionless parameters only
(docs/physics.md#dimensionless-parameters), and ``Q1`` depends on the speed through
the Hertz time ``T`` (``Q1`` grows as ``v_z0^(1/5)``): each speed is turned into a
:class:`vimpact.Scene` for its ``Q1`` (``Q2``) and looked up in the table, which gives
``e_z(v_z0)``, ``e_x(v_z0)`` for one material and sphere, the form a DEM code needs.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from vimpact.lookup.columns import OUTPUTS
from vimpact.lookup.query import incidence
from vimpact.model.scene import HALF_SPACE_LIMIT, Scene
from vimpact.model.validation import InputError, positive, require

if TYPE_CHECKING:
    from vimpact.lookup.table import RestitutionTable

__all__ = ["MAX_CURVE_POINTS", "export_curve", "restitution_curve"]

#: The most points of an e(v) curve (:func:`restitution_curve`,
#: ``vimpact table export --n``).
MAX_CURVE_POINTS = 100_000


def restitution_curve(table: RestitutionTable, material, R: float, m: float, v_z0,
                      theta_ratio=None, extrapolate: bool = False, allow_large_contact: bool = False,
                      angle_deg: float | None = None,
                      mu: float | None = None) -> pd.DataFrame:
    """Return ``e_z``, ``e_x``, ``beta_x`` of ``table`` against impact speed.

    :meth:`vimpact.lookup.table.RestitutionTable.restitution_curve` describes the
    parameters and the result.
    """
    from vimpact.model.material import Material

    require("material", material, isinstance(material, Material), "a vimpact.Material")
    if material.model != table.model:
        raise InputError(f"material model {material.model!r} does not match the table's "
                         f"model {table.model!r}")
    R, m = positive("R", R), positive("m", m)
    speeds = np.atleast_1d(np.asarray(v_z0, dtype=float)).ravel()
    require("v_z0", v_z0, speeds.size > 0, "at least one speed (m/s)")
    if speeds.size > MAX_CURVE_POINTS:
        raise InputError(f"v_z0 = {speeds.size} speeds is not allowed: at most "
                         f"{MAX_CURVE_POINTS} points per curve")
    psi = None
    if len(table.tensor.psi_values()):
        if angle_deg is None or mu is None:
            missing = " and ".join(n for n, x in (("angle_deg", angle_deg), ("mu", mu))
                                   if x is None)
            raise InputError(f"{missing} missing: the table has a friction incidence axis "
                             "psi, so the curve needs the impact angle from the normal "
                             "(degrees) and the friction coefficient mu")
        psi = incidence(angle_deg, mu, material.nu)
    else:
        if mu is not None and not math.isinf(float(mu)):
            raise InputError(f"mu = {mu!r} is not allowed: the table has no psi column (it "
                             "is for full stick, mu = inf); use a table swept over psi")
        if angle_deg is not None:
            incidence(angle_deg, math.inf, material.nu)  # range check only: under full
            # stick beta_x does not depend on the angle
    scenes = [Scene(material, R=R, m=m, v_z0=float(v), allow_large_contact=True) for v in speeds]
    if not allow_large_contact:
        big = [s for s in scenes if s.hertz.a_H > HALF_SPACE_LIMIT * R]
        if big:
            s = big[0]
            raise InputError(
                f"v_z0 = {s.v_z0:.6g} m/s is not allowed: its Hertz contact radius "
                f"{s.hertz.a_H:.4g} m exceeds 0.2 R = {HALF_SPACE_LIMIT * R:.4g} m (outside "
                "the half-space model; allow_large_contact=True / --allow-large-contact "
                "accepts it)")
    q1 = np.array([s.Q1 for s in scenes])
    q2 = np.array([s.Q2 for s in scenes]) if table.model == "standard_solid" else None
    res = table.lookup(q1, material.nu, q2, extrapolate=extrapolate, theta_ratio=theta_ratio,
                      psi=None if psi is None else np.full(len(q1), psi))
    columns = {"v_z0_m_s": speeds, "Q1": q1}
    if q2 is not None:
        columns["Q2"] = q2
    if psi is not None:
        columns["psi"] = np.full(len(q1), psi)
    columns.update({k: res[k] for k in OUTPUTS})
    df = pd.DataFrame(columns)
    df.attrs.update({
        "units": {"v_z0_m_s": "m/s", **{k: "1" for k in columns if k != "v_z0_m_s"}},
        "model": material.model, "nu": material.nu, "R_m": R, "m_kg": m,
        "angle_deg": None if angle_deg is None else float(angle_deg),
        "mu": None if mu is None else float(mu),
        "table": None if table.path is None else str(table.path),
    })
    return df


def export_curve(table: RestitutionTable, path, material, R: float, m: float, v_z0,
                 **options) -> pd.DataFrame:
    """Write :func:`restitution_curve` of ``table`` to the CSV file ``path``; return it.

    :meth:`vimpact.lookup.table.RestitutionTable.export_curve` describes the
    parameters and the result.
    """
    p = Path(path)
    require("out", str(path), p.suffix.lower() == ".csv", "a file name ending in .csv")
    require("out", str(path), p.parent.is_dir(), "in an existing directory")
    from vimpact.tableformat.files import atomic_file, refuse_symlink
    refuse_symlink(p, "out")  # before the work
    df = table.restitution_curve(material, R, m, v_z0, **options)
    with atomic_file(p, "out", mode="w") as f:  # never through a symbolic link
        df.to_csv(f, index=False, float_format="%.10g")
    return df

