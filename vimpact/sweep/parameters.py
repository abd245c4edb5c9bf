"""Parameter sets per chunk, made lazily: any chunk anywhere, in any order, same rows.

- grid: the flat row indices of the chunk are unravelled into the axes
  (outermost first, so ``Q1`` runs fastest), no product of the axes is built;
- random: the rows of chunk ``c`` are drawn from
  ``numpy.random.default_rng(SeedSequence(seed, spawn_key=(c,)))``: each key
  for all rows of the chunk in a fixed order (material, sphere, ``nu``,
  ``theta_ratio``, then ``G_Pa``, ``tau_s`` of every arm).

A random ``angle_deg`` (impact angle from the normal) is drawn instead of
``v_x0_m_s``; the chunk's ``v_x0_m_s = v_z0 tan(angle)`` is added to its
parameters (it takes no draw).

Memory is bounded by the chunk size. :func:`engine_columns` turns the parameters of a
chunk into the scene columns of :func:`vimpact.simulate_batch` and the physical input
columns of the table, with NumPy only. Friction: a grid row at incidence ``psi`` is
the reference scene with ``v_x0`` and ``mu`` from
:func:`~vimpact.tableformat.parameters.psi_reference`; a random row with ``mu`` gets
its ``psi`` from :func:`~vimpact.tableformat.parameters.incidence`. Kelvin-Voigt and
elastic grid rows get ``Q2 = NaN`` (no ``G2``: the limit ``G2 -> inf``), and
``inputs["model"]`` holds each row's rheology (a string, for the table's ``model``
column). Adhesion: a grid row at adhesion number ``lam`` gets the work of adhesion
that gives its reference scene this number (and ``v_x0 = 0``: normal impact); a random
row with ``adhesion_J_m2`` gets its ``lam``.
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.model.hertz import Q1_PER_TAU
from vimpact.model.material import shear_modulus
from vimpact.model.scene import REFERENCE_INDENTATION
from vimpact.model.toml_input import tangential_speed
from vimpact.tableformat.parameters import incidence, psi_reference

#: The reference scene of :meth:`vimpact.Scene.from_dimensionless`: R = 1 m,
#: m = 1 kg, v_z0 = v_x0 = 1 m/s, omega0 = 0, Hertz indentation d = 1e-4 m.
REFERENCE = {"R_m": 1.0, "m_kg": 1.0, "v_z0_m_s": 1.0, "v_x0_m_s": 1.0, "omega0_rad_s": 0.0}


def chunk_generator(seed: int, chunk: int) -> np.random.Generator:
    """Return the random generator of ``chunk``: ``SeedSequence(seed, spawn_key=(chunk,))``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(chunk,)))


def part_rows(part: tuple[int, int], rows: int, chunk: int) -> tuple[int, int]:
    """Return ``part`` (``(lo, hi)``: rows ``lo`` to ``hi - 1`` of a chunk of ``rows``).

    Raises
    ------
    ValueError
        unless ``0 <= lo < hi <= rows``.
    """
    lo, hi = part
    if not 0 <= lo < hi <= rows:
        raise ValueError(f"part = {part!r} is not allowed: must be rows (lo, hi) with "
                         f"0 <= lo < hi <= {rows} of chunk {chunk}")
    return lo, hi


def chunk_parameters(spec, chunk: int, part: tuple[int, int] | None = None
                     ) -> dict[str, np.ndarray]:
    """Return the parameter sets of ``chunk`` of ``spec``: one array per input.

    Grid mode: the axis values of rows ``chunk_rows(chunk)``. Random mode: the
    drawn physical inputs, ``G_arm<i>_Pa`` and ``tau_arm<i>_s`` for Prony arms.
    ``part``: ``(lo, hi)``, only the chunk's rows ``lo`` to ``hi - 1`` (counted from its
    first row, ``0 <= lo < hi <=`` its rows): the same values as the chunk's there (a
    grid's made for those rows only; a random chunk's drawn whole, then cut: its draws
    follow each other).
    """
    if not 0 <= chunk < spec.n_chunks:
        raise ValueError(f"chunk = {chunk} is not allowed: must be in [0, {spec.n_chunks - 1}]")
    start, stop = spec.chunk_rows(chunk)
    n = stop - start
    if part is not None:
        lo, hi = part_rows(part, n, chunk)
        if spec.mode != "grid":
            return {k: v[lo:hi] for k, v in chunk_parameters(spec, chunk).items()}
        start, stop = start + lo, start + hi
    if spec.mode == "grid":
        names = list(spec.axes)
        shape = tuple(len(spec.axes[k]) for k in names)
        index = np.unravel_index(np.arange(start, stop, dtype=np.int64), shape)
        return {k: spec.axes[k][i] for k, i in zip(names, index)}
    rng = chunk_generator(spec.seed, chunk)
    out = {key: draw.sample(rng, n) for key, draw in spec.draws.items()}
    for i, arm in enumerate(spec.arms, start=1):
        out[f"G_arm{i}_Pa"] = arm["G_Pa"].sample(rng, n)
        out[f"tau_arm{i}_s"] = arm["tau_s"].sample(rng, n)
    if "angle_deg" in out:  # drawn instead of v_x0 (no draw of its own)
        out["v_x0_m_s"] = tangential_speed(out["v_z0_m_s"], out["angle_deg"])
    return out


def engine_columns(spec, p: dict[str, np.ndarray]) -> tuple[list[tuple[np.ndarray, dict]], dict]:
    """Scene columns for :func:`vimpact.simulate_batch` and the table's input columns.

    Returns ``(batches, inputs)``: ``batches`` is a list of ``(rows, columns)``
    (row indices into the chunk and their scene columns; a standard solid whose
    dashpot is 0 has no Maxwell arm, so its rows form a batch of their own) and
    ``inputs`` the physical input columns and ``Q1``/``Q2`` known before the run
    (grid: the reference scene's values and the grid's ``Q1``, ``Q2``).
    """
    n = len(p["nu"])
    nu = p["nu"]
    # the effect choices: one str in every row as a read-only view of one element (a
    # str array of n rows costs some 4 ms per 1e5 rows to make and to compare; the
    # engine reads a view's one value once, vimpact.engine.columns)
    common = {"tangential": np.broadcast_to(np.array(spec.tangential), (n,)),
              "tangential_memory": np.broadcast_to(np.array(spec.tangential_memory), (n,)),
              "rotation": np.full(n, spec.rotation)}
    # no "model" column: the engine infers it from the rheology (it only decides how the
    # engine reports Q1, Q2, which the table takes from the spec for a grid)
    # the row's rheology, for a string column "model" (Q2 = NaN: Kelvin-Voigt, not 0)
    # one str in every row (np.full makes one per row: 30x slower), read only: a view of
    # one element, which the table's column is made from without comparing the rows
    inputs: dict[str, np.ndarray] = {
        "model": np.broadcast_to(np.array(spec.model, dtype=object), (n,))}
    if spec.mode == "grid":
        # Scene.from_dimensionless, vectorized with the same floating-point operations
        R, m, v_z0 = 1.0, 1.0, 1.0
        E_star = 15.0 * m * v_z0**2 / (16.0 * math.sqrt(R) * REFERENCE_INDENTATION**2.5)
        G = E_star * (1.0 - nu) / 2.0
        Q1 = p.get("Q1", np.zeros(n))
        tau = Q1 / Q1_PER_TAU * REFERENCE_INDENTATION / v_z0
        eta = tau * G
        # the reference sphere: one value viewed in every row (read only; the engine
        # checks it once, the table's columns are copies)
        sphere = {k: np.broadcast_to(np.float64(v), (n,)) for k, v in REFERENCE.items()}
        if "lam" in p:  # the adhesive impact is normal only: v_x0 = 0
            sphere["v_x0_m_s"] = np.zeros(n)
        if "psi" in p:
            sphere["v_x0_m_s"], mu = psi_reference(p["psi"], nu, spec.grid_mu, v_z0)
            common["mu"] = inputs["mu"] = mu
        cols = {"nu": nu, "G_inf_Pa": G, **sphere, "theta_ratio": p["theta_ratio"], **common}
        inputs.update(sphere)
        if spec.model == "standard_solid":
            G2 = G / p["Q2"]
            with np.errstate(divide="ignore", invalid="ignore"):
                tau_arm = eta / G2
            inputs.update(G1_Pa=G, G2_Pa=G2, eta_Pa_s=G * ((G2 * tau_arm) / G))
            inputs["eta_Pa_s"][eta == 0.0] = 0.0
            cols.update(G_arm1_Pa=G2, tau_arm1_s=tau_arm)
            inputs.update(Q1=Q1, Q2=p["Q2"])
        else:
            inputs["G_Pa"] = G
            if spec.model == "kelvin_voigt":
                cols["eta0_Pa_s"] = eta
                inputs["eta_Pa_s"] = eta
                inputs["Q1"] = Q1
            # no Q2: G2 -> inf, the Kelvin-Voigt limit (Q2 = 0 would be log 0 on a log axis)
            inputs["Q2"] = np.full(n, np.nan)
    else:
        sphere = {k: p[k] for k in ("R_m", "m_kg", "v_z0_m_s", "v_x0_m_s", "omega0_rad_s")}
        if "mu" in p:
            common["mu"] = p["mu"]
            inputs["psi"] = incidence(p["mu"], nu, sphere["v_x0_m_s"]
                                      + sphere["R_m"] * sphere["omega0_rad_s"], sphere["v_z0_m_s"])
        cols = {"nu": nu, **sphere, "theta_ratio": p["theta_ratio"], **common}
        inputs.update(sphere)
        if spec.model == "standard_solid":
            G1, G2, eta = p["G1_Pa"], p["G2_Pa"], p["eta_Pa_s"]
            with np.errstate(divide="ignore", invalid="ignore"):
                tau_arm = eta / G2
            cols.update(G_inf_Pa=G1, G_arm1_Pa=G2, tau_arm1_s=tau_arm)
            inputs.update(G1_Pa=G1, G2_Pa=G2, eta_Pa_s=eta)
        else:
            if "E_Pa" in p:
                G = shear_modulus(p["E_Pa"], nu)
                inputs["E_Pa"] = p["E_Pa"]
            else:
                G = p["G_Pa"]
            cols["G_inf_Pa"] = G
            inputs["G_Pa"] = G
            if spec.model != "elastic":
                cols["eta0_Pa_s"] = p["eta_Pa_s"]
                inputs["eta_Pa_s"] = p["eta_Pa_s"]
            for i in range(1, len(spec.arms) + 1):
                for key in (f"G_arm{i}_Pa", f"tau_arm{i}_s"):
                    cols[key] = inputs[key] = p[key]
    if spec.has_adhesion:  # docs/physics.md#adhesion: lam <-> dgamma on the row's scales
        from vimpact.engine.adhesion import adhesion_number_of, work_of_adhesion
        scales = (cols["G_inf_Pa"], nu, cols["R_m"], cols["m_kg"], cols["v_z0_m_s"])
        if "lam" in p:
            cols["adhesion_J_m2"] = inputs["adhesion_J_m2"] = work_of_adhesion(p["lam"], *scales)
        else:
            cols["adhesion_J_m2"] = inputs["adhesion_J_m2"] = p["adhesion_J_m2"]
            inputs["lam"] = adhesion_number_of(p["adhesion_J_m2"], *scales)
    batches = [(np.arange(n), cols)]
    if spec.model == "standard_solid":
        # eta = 0: Material.standard_solid has no arm (a bad G2 stays in the arm batch,
        # where the engine names it)
        no_arm = (cols["tau_arm1_s"] == 0.0) & (cols["G_arm1_Pa"] > 0.0)
        if no_arm.any():
            rows = np.flatnonzero(no_arm)
            plain = {k: v[rows] for k, v in cols.items() if k not in ("G_arm1_Pa", "tau_arm1_s")}
            keep = np.flatnonzero(~no_arm)
            batches = [(keep, {k: v[keep] for k, v in cols.items()}), (rows, plain)]
    return batches, inputs


__all__ = ["REFERENCE", "chunk_generator", "chunk_parameters", "engine_columns"]
