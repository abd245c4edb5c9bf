"""Impacts of two bodies, or of a body on a wall, run through the engine.

The mapping of a pair onto one rigid-sphere scene (and back to both bodies'
end states) is plain data in :mod:`vimpact.model.pair`; this module runs the
equivalent scenes (:func:`vimpact.engine.simulate.simulate`,
:func:`~vimpact.engine.simulate.simulate_batch`).
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

from vimpact.engine.simulate import simulate, simulate_batch
from vimpact.model.pair import Body, PairResult, Wall, end_states, pair_scene
from vimpact.model.scene import Scene
from vimpact.model.validation import message, require


def simulate_pair(body1: Body, other: Body | Wall, numerics=None, **scene_options) -> PairResult:
    """Simulate body 1 hitting body 2 (or a wall).

    Parameters
    ----------
    body1 : the first body; ``other`` : the second body or a :class:`~vimpact.model.pair.Wall`
    numerics : :class:`vimpact.Numerics` (default: the engine's default)
    scene_options : ``tangential``, ``tangential_memory``, ``mu``,
        ``allow_large_contact`` of the equivalent scene (:func:`~vimpact.model.pair.pair_scene`)

    Returns
    -------
    PairResult
    """
    scene = pair_scene(body1, other, **scene_options)
    res = simulate(scene, numerics)
    b1, b2, J_z, J_x = end_states(body1, other, scene, res.e_z, res.beta_x)
    return PairResult(res.e_z, res.beta_x, b1, b2, J_z, J_x, res.status, scene, res)


def simulate_pair_batch(pairs: Sequence[tuple[Body, Body | Wall]], numerics=None,
                        **scene_options):
    """Simulate many pair impacts in one batch.

    Parameters
    ----------
    pairs : sequence of ``(body1, body2_or_wall)``
    numerics, scene_options : as :func:`simulate_pair`

    Returns
    -------
    pandas.DataFrame
        one row per pair: ``e_z, beta_x, status, t_contact_s`` and the end
        states ``v_z1, v_x1, omega1, v_z2, v_x2, omega2`` (m/s, rad/s; NaN for a
        wall) and the impulses on body 1 ``J_z, J_x`` (N s), and ``error``. A pair
        that is not a valid ``(body, body or wall)`` approaching along ``z`` gets
        status ``invalid``, its reason in ``error`` and NaN numbers; the other pairs
        are unaffected (nothing is raised for a bad pair).
    """
    pairs = list(pairs)
    n = len(pairs)
    scenes: list = [None] * n
    reasons: list = [None] * n
    for i, pair in enumerate(pairs):
        try:
            b1, b2 = pair
            require(f"pairs[{i}]", pair, isinstance(b1, Body) and isinstance(b2, (Body, Wall)),
                    "a (vimpact.Body, vimpact.Body or vimpact.Wall) pair")
            scenes[i] = pair_scene(b1, b2, **scene_options)
        except (ValueError, TypeError) as exc:
            reasons[i] = (f"pairs[{i}]: {exc}" if isinstance(exc, ValueError) else
                          message(f"pairs[{i}]", pair, "a (vimpact.Body, vimpact.Body or "
                                                       "vimpact.Wall) pair"))
    good = [i for i in range(n) if scenes[i] is not None]
    df = simulate_batch([scenes[i] for i in good], numerics)
    columns = ["e_z", "beta_x", "status", "t_contact", "v_z1", "v_x1", "omega1", "v_z2", "v_x2",
               "omega2", "J_z", "J_x", "error"]
    rows = [dict(e_z=np.nan, beta_x=np.nan, status="invalid", t_contact=np.nan, v_z1=np.nan,
                 v_x1=np.nan, omega1=np.nan, v_z2=np.nan, v_x2=np.nan, omega2=np.nan,
                 J_z=np.nan, J_x=np.nan, error=reasons[i]) for i in range(n)]
    for k, i in enumerate(good):
        row = df.iloc[k]
        e_z, beta_x = float(row["e_z"]), float(row["beta_x"])
        rows[i].update(e_z=e_z, beta_x=beta_x, status=row["status"],
                       t_contact=float(row["t_contact"]), error=row.get("error"))
        if math.isfinite(e_z):
            b1, b2 = pairs[i]
            end1, end2, J_z, J_x = end_states(b1, b2, scenes[i], e_z, beta_x)
            end2 = end2 or (np.nan, np.nan, np.nan)
            rows[i].update(zip(("v_z1", "v_x1", "omega1", "v_z2", "v_x2", "omega2", "J_z",
                                "J_x"), (*end1, *end2, J_z, J_x)))
    out = pd.DataFrame(rows, columns=columns)
    out["error"] = out["error"].astype("str")  # as simulate_batch's: missing when none
    return out.rename(columns={"t_contact": "t_contact_s"})


def pair_restitution(body1: Body, other: Body | Wall, speeds, *, tangential: bool = False,
                     vc_ratio: float = 1.0, numerics=None, mu: float = math.inf):
    """``e_z`` (and ``beta_x``) of a pair over approach speeds: the curves DEM fits need.

    Parameters
    ----------
    body1, other : the pair (their velocities are ignored)
    speeds : approach speeds ``v_z0``, m/s (array)
    tangential : also solve the tangential problem (full stick unless ``mu``)
        with ``v_c0 = vc_ratio * v_z0``; otherwise normal only (fast)
    numerics : :class:`vimpact.Numerics`

    Returns
    -------
    pandas.DataFrame with columns ``v_z0, e_z, beta_x, t_contact, a_max, status``.
    """
    return pair_restitutions([(body1, other, speeds, {"tangential": tangential,
                                                      "vc_ratio": vc_ratio, "mu": mu})],
                             numerics)[0]


def pair_restitutions(curves: Sequence[tuple[Body, Body | Wall, object, dict]], numerics=None
                      ) -> list[pd.DataFrame]:
    """:func:`pair_restitution` of several pairs and options, all in one engine batch.

    ``curves``: ``(body1, other, speeds, options)`` with ``options`` the keywords
    ``tangential``, ``vc_ratio``, ``mu`` of :func:`pair_restitution` (absent: its
    defaults). Every impact is a row of one :func:`~vimpact.engine.simulate.simulate_batch`
    call (rows are independent: each gets what it gets alone). Returns one DataFrame per
    curve, as :func:`pair_restitution` returns it.
    """
    scenes: list[Scene] = []
    bounds = []
    for body1, other, speeds, options in curves:
        unknown = sorted(set(options) - set(_CURVE_DEFAULTS))
        require("options", unknown, not unknown,
                "keywords among " + ", ".join(_CURVE_DEFAULTS))
        options = {**_CURVE_DEFAULTS, **options}
        speeds = np.asarray(speeds, dtype=float)
        require("speeds", speeds, speeds.ndim == 1 and speeds.size > 0
                and bool(np.all(speeds > 0)) and bool(np.all(np.isfinite(speeds))),
                "a non-empty 1-D array of finite speeds > 0")
        tangential, vc_ratio, mu = (bool(options["tangential"]), float(options["vc_ratio"]),
                                    options["mu"])
        base = pair_scene(Body(body1.material, body1.R, body1.m, body1.Theta, v_z=1.0,
                               rotation=body1.rotation),
                          other if isinstance(other, Wall) else
                          Body(other.material, other.R, other.m, other.Theta,
                               rotation=other.rotation),
                          tangential="stick" if tangential else "none", mu=mu,
                          allow_large_contact=True)
        start = len(scenes)
        scenes += [Scene(base.material, R=base.R, m=base.m, v_z0=v,
                         v_x0=vc_ratio * v if tangential else 0.0,
                         Theta=base.Theta if base.rotation else None, rotation=base.rotation,
                         tangential=base.tangential, mu=mu, allow_large_contact=True)
                   for v in speeds]
        bounds.append((start, len(scenes), speeds))
    df = simulate_batch(scenes, numerics)[["e_z", "beta_x", "t_contact", "a_max", "status"]]
    out = []
    for start, stop, speeds in bounds:
        part = df.iloc[start:stop].reset_index(drop=True)
        part.insert(0, "v_z0", speeds)
        out.append(part)
    return out


#: the options of one curve of :func:`pair_restitutions` and their defaults: the keywords
#: of :func:`pair_restitution` (its signature is their one home)
_CURVE_DEFAULTS = {name: p.default for name, p in
                   inspect.signature(pair_restitution).parameters.items()
                   if p.kind is inspect.Parameter.KEYWORD_ONLY and name != "numerics"}
