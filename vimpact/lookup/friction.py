"""Friction tables: gross slip in closed form, and ``beta_x`` over the incidence below it.

Under Coulomb friction the tangential restitution over the incidence
``psi = 2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0`` has kinks where the course of the
contact changes (docs/physics.md#coulomb-friction). Beyond the last one the contact
slips throughout: the tangential force is ``mu F_z`` at all times, so the contact
point's velocity changes by ``mu (1 + m R^2 / Theta) (1 + e_z) v_z0`` whatever the
rheology, and

    beta_x = -1 + 2 chi (1 + e_z) / psi,   chi = (1 - nu) (1 + m R^2 / Theta) / (2 - nu),

with ``e_z`` the normal restitution, which friction does not change. Since
``|F_x| <= mu F_z`` at all times, this is also an upper bound of ``beta_x`` at every
``psi``. It reaches ``beta_x = 0`` (the contact point just stops at the end) at
``psi_g = 2 chi (1 + e_z)`` (for the elastic sphere, ``e_z = 1``, Maw, Barber and
Fawcett's ``psi_1 = 4 chi``). Gross slip throughout holds at least from ``psi_g`` on;
the tangential compliance lets it begin somewhat below (measured on a Kelvin-Voigt
half-space, ``Q1 = 0.1``, ``nu = 0.3``: from about ``0.84 psi_g``, where ``beta_x``
is 0.19), so the kink where microslip meets gross slip is below ``psi_g`` and is
found by simulation, not by this closed form.

A friction table (:class:`FrictionGrid`, built by
:func:`vimpact.tablebuild.friction.build_friction`) tabulates ``beta_x`` only below
that start ``psi_s``, on nodes placed on the kinks (:func:`coordinate_nodes`), and
answers ``psi >= psi_s`` by the closed form.
"""

from __future__ import annotations

import numpy as np

from vimpact.model.validation import InputError

__all__ = ["FRICTION_FORMAT", "PSI_NEAR_STICK", "PSI_STICK", "FrictionGrid", "chi", "coordinate_nodes",
           "gross_slip_beta_x", "gross_slip_onset", "psi_of_coordinate"]


def chi(nu, theta_ratio=0.4, rotation: bool = True):
    """Mindlin ratio times the contact-point mass factor, ``(1 - nu)(1 + 1/theta_ratio)/(2 - nu)``.

    Parameters
    ----------
    nu : Poisson ratio, dimensionless, in [0, 0.5]
    theta_ratio : ``Theta / (m R^2)``, dimensionless, > 0
    rotation : the sphere may spin (without: mass factor 1)
    """
    nu = np.asarray(nu, dtype=float)
    factor = 1.0 + 1.0 / np.asarray(theta_ratio, dtype=float) if rotation else 1.0
    return (1.0 - nu) * factor / (2.0 - nu)


def gross_slip_onset(e_z, nu, theta_ratio=0.4, rotation: bool = True):
    """Return the incidence ``psi_g = 2 chi (1 + e_z)`` of the gross-slip onset.

    There the gross-slip closed form gives ``beta_x = 0``; the contact slips
    throughout at every ``psi >= psi_g``.

    Parameters
    ----------
    e_z : normal restitution, dimensionless, in [0, 1]
    nu, theta_ratio, rotation : as for :func:`chi`

    Returns
    -------
    psi_g, dimensionless (array or float)
    """
    return 2.0 * chi(nu, theta_ratio, rotation) * (1.0 + np.asarray(e_z, dtype=float))


def gross_slip_beta_x(psi, e_z, nu, theta_ratio=0.4, rotation: bool = True):
    """``beta_x = -1 + 2 chi (1 + e_z) / psi`` of gross slip throughout (``psi >= psi_g``).

    Parameters
    ----------
    psi : incidence, dimensionless, > 0
    e_z, nu, theta_ratio, rotation : as for :func:`gross_slip_onset`

    Returns
    -------
    beta_x, dimensionless; NaN where ``psi < psi_g`` (not gross slip throughout: a
    table or a simulation is needed there)
    """
    psi = np.asarray(psi, dtype=float)
    onset = gross_slip_onset(e_z, nu, theta_ratio, rotation)
    with np.errstate(divide="ignore", invalid="ignore"):
        beta = -1.0 + onset / psi
    return np.where(psi >= onset * (1.0 - 1e-12), beta, np.nan)


#: Incidence of the first kink of ``beta_x(psi)``: below it the stuck contact's
#: tangential force is below ``mu F_z`` at the first instant (the ratio of the two
#: starts at ``psi`` for every rheology whose tangential and normal elements share a
#: relaxation), so the contact starts in stick; above it, it starts slipping.
PSI_STICK = 1.0
#: Incidence of a friction table's first node: the limit ``psi -> 0`` as the
#: friction (element) path gives it, which every ``psi > 0`` is simulated on. ``psi =
#: 0`` itself is full stick on the continuum path, which differs from it by that
#: path's discretization error (measured 3e-6 ... 3e-5 in ``beta_x``); a lookup at
#: ``psi < PSI_NEAR_STICK`` gives the first node's value.
PSI_NEAR_STICK = 1e-9
#: Version of the friction entry in ``vimpact.adaptive``.
FRICTION_FORMAT = 1


def coordinate_nodes(n_stick: int, n_slip: int) -> np.ndarray:
    """Incidence coordinates of a friction table's ``psi`` nodes.

    ``u`` in ``[0, 1]`` is ``psi / PSI_STICK`` (the contact starts in stick):
    ``n_stick`` nodes at ``u = t^2``, ``t`` in equal steps, crowded towards ``psi = 0``,
    where full stick meets microslip and ``beta_x`` bends fastest (measured at ``Q1 =
    0.007``, ``nu = 0.3``: its slope falls from 0.37 to 0.23 within ``psi < 0.002``,
    then stays near 0.23 up to ``psi = 0.1``); the
    first node is :data:`PSI_NEAR_STICK` instead of 0. ``u`` in ``[1, 2]`` maps
    ``PSI_STICK .. psi_s`` linearly (microslip up to gross slip throughout): ``n_slip``
    nodes crowded towards both kinks
    (``u - 1 = 2 t^2`` for ``t <= 1/2`` and ``1 - 2 (1 - t)^2`` above, ``t`` in equal
    steps), where ``beta_x`` bends fastest: just below ``psi_s`` it meets the closed
    form like ``(psi_s - psi)^1.25`` (measured at ``Q1 = 0.1``, ``nu = 0.3``).
    """
    if n_stick < 2 or n_slip < 2:
        raise InputError(f"n_stick = {n_stick}, n_slip = {n_slip} are not allowed: at least 2 "
                         "nodes per segment")
    stick = np.linspace(0.0, 1.0, n_stick) ** 2
    stick[0] = PSI_NEAR_STICK / PSI_STICK
    t = np.linspace(0.0, 1.0, n_slip)
    graded = np.where(t < 0.5, 2.0 * t**2, 1.0 - 2.0 * (1.0 - t) ** 2)
    return np.concatenate([stick, 1.0 + graded[1:]])


def psi_of_coordinate(u, psi_s):
    """Incidence ``psi`` at coordinate ``u`` (see :func:`coordinate_nodes`)."""
    u = np.asarray(u, dtype=float)
    psi_s = np.asarray(psi_s, dtype=float)
    return np.where(u <= 1.0, u * PSI_STICK, PSI_STICK + (u - 1.0) * (psi_s - PSI_STICK))


class FrictionGrid:
    """A Kelvin-Voigt friction table: ``e_z`` and ``beta_x`` over ``Q1``, ``nu`` and ``psi``.

    An adaptive table in ``log Q1`` with the tensor axis ``nu``
    (:class:`vimpact.lookup.adaptive.AdaptiveGrid`) whose nodes carry ``e_z``, the
    ratio ``psi_s / psi_g`` of the incidence where gross slip throughout begins to the
    closed form's zero, and ``beta_x`` at the incidence coordinates ``u`` of
    :func:`coordinate_nodes` (both kinks at fixed ``u``: ``u = 1`` at
    :data:`PSI_STICK`, ``u = 2`` at ``psi_s``). A lookup interpolates them to ``Q1``,
    ``nu`` (cubic), then along ``u`` with a shape-preserving cubic Hermite interpolant
    segment by segment (:func:`vimpact.kernels.adaptive_lookup.hyman_eval`); at
    ``psi >= psi_s`` it gives the closed form :func:`gross_slip_beta_x` instead.

    Parameters
    ----------
    grid : the adaptive grid of the outputs ``e_z``, ``onset_ratio``, ``beta_x_0`` ...
    unodes : the incidence coordinates, increasing from 0 to 2
    theta_ratio : ``Theta / (m R^2)`` of the table, dimensionless
    rotation : whether the sphere may spin
    """

    #: Lookup coordinates (the reader passes these and ``tensor_axis``).
    axes = ["Q1", "psi"]
    tensor_axis = "nu"

    def __init__(self, grid, unodes, theta_ratio: float = 0.4, rotation: bool = True):
        self.grid = grid
        self.unodes = np.asarray(unodes, dtype=float)
        kinks = [0] + [int(np.flatnonzero(np.isclose(self.unodes, u, rtol=0, atol=1e-12))[0])
                       if np.isclose(self.unodes, u, rtol=0, atol=1e-12).any() else -1
                       for u in (1.0, 2.0)]
        if min(kinks) < 0 or not np.all(np.diff(self.unodes) > 0) or self.unodes[0] < 0 \
                or kinks[2] != len(self.unodes) - 1:
            raise InputError(f"friction nodes u = {self.unodes.tolist()[:6]} ... are not "
                             "allowed: increasing from >= 0, with the kink 1 among them and "
                             "the kink 2 last")
        self.kinks = np.array(kinks, dtype=np.int64)
        self.theta_ratio = float(theta_ratio)
        self.rotation = bool(rotation)
        if self.grid.names[:2] != ["e_z", "onset_ratio"] or len(self.grid.names) != \
                2 + len(self.unodes):
            raise InputError("friction table: the adaptive outputs must be e_z, onset_ratio "
                             f"and beta_x at {len(self.unodes)} incidence nodes")

    @property
    def tensor_nodes(self) -> np.ndarray:
        """The ``nu`` nodes."""
        return self.grid.tensor_nodes

    def info(self) -> dict:
        """Cells and nodes of the adaptive part, and the incidence nodes."""
        out = self.grid.info()
        out["psi_nodes"] = int(len(self.unodes))
        out["rows"] = int(out["rows"] * len(self.unodes))
        return out

    def check_range(self, coords: dict) -> None:
        """Raise :class:`InputError` for ``Q1``, ``nu`` outside the table (any ``psi >= 0``)."""
        self.grid.check_range({"Q1": coords["Q1"], "nu": coords["nu"]})
        psi = coords["psi"]
        if psi.size and (not np.all(np.isfinite(psi)) or psi.min() < 0.0):
            bad = float(psi[~(np.isfinite(psi) & (psi >= 0.0))].flat[0])
            raise InputError(f"psi = {bad!r} is not allowed: must be finite and >= 0")

    def _adaptive(self, Q1, nu) -> dict:
        """Return the adaptive outputs at ``Q1``, ``nu`` (flat arrays)."""
        return self.grid({"Q1": Q1, "nu": nu})

    def onset(self, Q1, nu) -> dict:
        """Return ``e_z``, ``psi_g`` and ``psi_s`` interpolated at ``Q1``, ``nu``.

        ``psi_s`` is where gross slip throughout begins, ``psi_g`` the closed form's zero.
        """
        Q1, nu = np.broadcast_arrays(np.asarray(Q1, float), np.asarray(nu, float))
        out = self._adaptive(Q1, nu)
        psi_g = gross_slip_onset(out["e_z"], nu, self.theta_ratio, self.rotation)
        return {"e_z": out["e_z"], "psi_g": psi_g, "psi_s": out["onset_ratio"] * psi_g}

    def __call__(self, coords: dict) -> dict:
        """Return ``e_z`` and ``beta_x`` at ``coords`` (``Q1``, ``psi``, ``nu``: one shape)."""
        import math

        from vimpact.kernels.adaptive_lookup import friction_eval

        arrays = {a: np.asarray(coords[a], dtype=float) for a in ("Q1", "psi", "nu")}
        shape = np.broadcast_shapes(*(v.shape for v in arrays.values()))
        arrays = {a: np.broadcast_to(v, shape).ravel() for a, v in arrays.items()}
        self.check_range(arrays)
        points = np.column_stack([arrays["Q1"], arrays["nu"], arrays["psi"]])
        out = np.empty((math.prod(shape), 2))
        factor = chi(arrays["nu"], self.theta_ratio, self.rotation)
        friction_eval(np.ascontiguousarray(points), *self.grid._kernel_arrays(),
                      np.ascontiguousarray(factor, dtype=float), self.unodes, self.kinks,
                      PSI_STICK, out)
        return {"e_z": out[:, 0].reshape(shape), "beta_x": out[:, 1].reshape(shape)}

    # ---- storage ------------------------------------------------------------
    def to_metadata(self) -> dict:
        """Return the ``vimpact.adaptive`` entry: the adaptive part's, with ``friction``."""
        meta = self.grid.to_metadata()
        meta["friction"] = {"format": FRICTION_FORMAT, "psi_stick": PSI_STICK,
                            "coordinates": self.unodes.tolist(),
                            "theta_ratio": self.theta_ratio, "rotation": self.rotation}
        return meta

    @classmethod
    def from_rows(cls, meta: dict, data) -> FrictionGrid:
        """Rebuild from ``vimpact.adaptive`` and the rows.

        One row per adaptive node, ``nu`` node and incidence node (column ``lattice_psi``:
        its index in the coordinates); the rows at ``u = 2`` give ``psi_s``.
        """
        from vimpact.lookup.adaptive import AdaptiveGrid

        fr = meta.get("friction")
        if not isinstance(fr, dict) or fr.get("format") != FRICTION_FORMAT \
                or fr.get("psi_stick") != PSI_STICK:
            raise InputError(f"vimpact.adaptive friction = {str(fr)[:80]!r} is not allowed: a "
                             f"friction table's entry of format {FRICTION_FORMAT} with "
                             f"psi_stick = {PSI_STICK}")
        unodes = np.asarray(fr["coordinates"], dtype=float)
        if "lattice_psi" not in data.columns:
            raise InputError("friction table: the column lattice_psi is missing")
        j = data["lattice_psi"].to_numpy(np.int64)
        if j.size and (j.min() < 0 or j.max() >= len(unodes)):
            raise InputError(f"friction table: lattice_psi must be in [0, {len(unodes) - 1}]")
        base = {k: v for k, v in meta.items() if k != "friction"}
        last = j == len(unodes) - 1  # psi = psi_s: gross slip begins (the element path)
        rows = data[last]
        nu = rows["nu"].to_numpy(float)
        theta, rotation = float(fr["theta_ratio"]), bool(fr["rotation"])
        psi_g = gross_slip_onset(rows["e_z"].to_numpy(float), nu, theta, rotation)
        ratio = rows[["lattice_Q1", "nu", "status"]].copy()
        ratio["e_z"] = rows["e_z"].to_numpy(float)
        ratio["onset_ratio"] = rows["psi"].to_numpy(float) / psi_g
        parts = AdaptiveGrid.from_rows(base, ratio, names=("e_z", "onset_ratio"))
        values = {"e_z": parts.values[..., 0], "onset_ratio": parts.values[..., 1]}
        for n in range(len(unodes)):
            sel = data[j == n]
            one = AdaptiveGrid.from_rows(base, sel, names=("beta_x",))
            if not np.array_equal(one.keys, parts.keys):
                raise InputError(f"friction table: the rows at incidence node {n} are not at "
                                 "the same adaptive nodes as the others")
            values[f"beta_x_{n}"] = one.values[..., 0]
        grid = AdaptiveGrid(parts.axes, parts.bounds, parts.leaves, parts.keys,
                            parts.tensor_axis, parts.tensor_nodes, values)
        return cls(grid, unodes, theta, rotation)
