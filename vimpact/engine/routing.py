"""Which kernel runs a scene, and why: simulate only the effects a scene calls for.

A scene names its effects (tangential problem or not, rotation, rheology);
:func:`choose_path` maps them to one of

- ``continuum``: the Kelvin-Voigt (or elastic) normal-only impact as a
  one-degree-of-freedom ODE with the closed-form continuum force
  (docs/physics.md#kelvin-voigt-continuum), adaptive Dormand-Prince 5(4) with event location;
- ``elements``: the MDR element kernel, compiled for exactly the scene's
  effects (:class:`vimpact.kernels.elements.KernelSpec`): no tangential state
  without a tangential problem, no arm variables without Maxwell arms, no
  dashpot term without a dashpot (friction and full stick share a kernel
  that skips the slip work of a row with ``mu = inf``).

``Path.reasons`` says why, in words (``vimpact simulate --explain``).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from vimpact.engine import discretization
from vimpact.engine.columns import SceneColumns
from vimpact.kernels.elements import KernelSpec
from vimpact.kernels.layout import STATUS_ASSUMPTION
from vimpact.model.numerics import INTEGRATORS, Numerics
from vimpact.model.scene import TANGENTIAL_MEMORY, Scene

CONTINUUM = "continuum"
CONTINUUM_STICK = "continuum_stick"
ELEMENTS = "elements"
#: the adhesive normal-impact kernel (vimpact.kernels.adhesion), one scene at a time
ADHESION = "adhesion"

#: Below this incidence psi = 2 (1 - nu) / (mu (2 - nu)) |v_c0| / v_z0 a finite mu is
#: full stick to rounding: friction moves beta_x by at most about psi (measured on a
#: Kelvin-Voigt scene: 1.0e-4, 3.6e-6, 7e-8 and 7e-13 at psi = 2.7e-4, 2.7e-6, 2.7e-7
#: and 2.7e-12), and mu v_z0 / |v_c0| beyond ~1e12 only feeds round-off (mu = 1e50
#: gave NaN); such rows run the stick kernels.
PSI_FULL_STICK = 1e-12


def friction_rows(cols: SceneColumns) -> np.ndarray:
    """Return the rows whose Coulomb friction the kernels must model, bool.

    Those with a tangential problem, a finite ``mu`` and an incidence ``psi`` of at
    least :data:`PSI_FULL_STICK`.
    """
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        psi = cols.kappa / cols.mu * np.abs(cols.v_c0) / cols.v_z0  # kappa = 2(1-nu)/(2-nu)
    return cols.computes_tangential & np.isfinite(cols.mu) & (psi >= PSI_FULL_STICK)


@dataclass(frozen=True)
class KernelPath:
    """The kernel chosen for a scene (``vimpact.KernelPath``; not a file path).

    Attributes
    ----------
    kind : ``"continuum"`` (Kelvin-Voigt/elastic normal impact), ``"continuum_stick"``
        (full stick, every rheology) or ``"elements"``
    spec : compile-time effects of the element kernel (``None`` for the continuum path)
    reasons : why, one sentence each
    """

    kind: str
    spec: KernelSpec | None
    reasons: tuple[str, ...]

    @functools.cached_property  # (a frozen dataclass: kept in the instance's __dict__)
    def name(self) -> str:
        """Short label, e.g. ``elements[verlet,tangential:incremental,dashpot]``."""
        if self.kind == CONTINUUM_STICK:
            return "continuum[stick]"
        if self.kind == ADHESION:
            return "adhesion[verlet,normal]"
        if self.spec is None:
            return "continuum[kelvin_voigt,normal]"
        sp = self.spec
        parts = [_INTEGRATOR_NAMES[sp.integrator]]
        if sp.tangential:
            parts.append("tangential:" + TANGENTIAL_MEMORY[sp.memory])
        if sp.arms:
            parts.append("arms")
        if sp.dashpot:
            parts.append("dashpot")
        if sp.friction:
            parts.append("friction")
        return f"elements[{','.join(parts)}]"

    def explain(self) -> str:
        """Multi-line explanation: the path and the reasons."""
        return "\n".join([f"path: {self.name}"] + [f"  - {r}" for r in self.reasons])


#: the short name inside the engine (the public name, :class:`KernelPath`, does not
#: shadow :class:`pathlib.Path`)
Path = KernelPath


_INTEGRATOR_NAMES = {code: name for name, code in INTEGRATORS.items()}

#: path of the Kelvin-Voigt/elastic normal-only continuum kernel
CONTINUUM_KV = Path(CONTINUUM, None, ())
#: path of the full-stick continuum kernel (every rheology, docs/physics.md#continuum-limit)
CONTINUUM_FULL_STICK = Path(CONTINUUM_STICK, None, ())


@dataclass(frozen=True)
class Routes:
    """Which kernel runs each row of a batch.

    Attributes
    ----------
    group : per row, the index of its path in ``paths`` (-1: invalid row, no kernel)
    paths : the distinct paths of the batch (``reasons`` left empty: see :func:`choose_path`)
    """

    group: np.ndarray
    paths: tuple[Path, ...]


def route(cols: SceneColumns, numerics: Numerics) -> Routes:
    """Return the cheapest kernel for every row of ``cols`` (vectorized; the one routing rule)."""
    if len(cols) == 1:
        return _route_row(cols, numerics)
    valid = cols.valid
    tangential = cols.computes_tangential & valid
    arms = cols.has_arms
    dashpot = cols.eta0 > 0.0
    friction = tangential & friction_rows(cols)
    memory = np.where(tangential, cols.memory, 0)
    continuum = ~arms & ~tangential & numerics.continuum
    stick = continuum_stick(cols, numerics, friction) & ~continuum
    kind = np.where(continuum, 1, np.where(stick, 2, 0))
    key = (kind.astype(np.int64) << 5 | tangential << 4 | memory << 3 | arms << 2
           | dashpot << 1 | friction)
    key = np.where(kind > 0, kind << 5, key)  # one continuum group per kernel
    key = np.where(valid, key, -1)
    paths: list[Path] = []
    group = np.full(len(cols), -1, dtype=np.int64)
    keys = key[key >= 0]
    # the distinct keys in ascending order: a key is < 2**7, so counted (np.unique sorts
    # or hashes the whole batch)
    for k in np.flatnonzero(np.bincount(keys)) if len(keys) else ():
        group[key == k] = len(paths)
        paths.append(_path_of_key(int(k), numerics.integrator_code))
    return Routes(group, tuple(paths))


#: :class:`Routes` of one row, by its path (``None``: an invalid row)
_ONE_ROW: dict = {}


def _route_row(cols: SceneColumns, numerics: Numerics) -> Routes:
    """:func:`route` of a one-row batch (:func:`vimpact.simulate`), on Python scalars.

    The same rules (:func:`friction_rows`, :func:`continuum_stick`, on the row's
    scalars) and the same key as :func:`route`, without the array arithmetic that
    costs more than the rest of the call on one row; ``tests/engine/test_routing.py``
    checks the two agree.
    """
    if cols.reasons[0] is not None:
        path = None
    else:
        tangential = bool(cols.computes_tangential[0])
        arms = bool(cols.has_arms[0])
        friction = False  # friction_rows on the row's scalars (the same operations)
        mu = cols.mu[0]
        if tangential and math.isfinite(mu):
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                psi = cols.kappa[0] / mu * abs(cols.v_c0[0]) / cols.v_z0[0]
            friction = bool(psi >= PSI_FULL_STICK)
        incremental = cols.memory[0] == TANGENTIAL_MEMORY.index("incremental")
        continuum = not arms and not tangential and numerics.continuum
        # continuum_stick of a valid row
        stick = (not continuum and numerics.continuum and not friction
                 and (incremental or not tangential))
        kind = 1 if continuum else 2 if stick else 0
        key = (kind << 5 if kind else
               tangential << 4 | (int(cols.memory[0]) if tangential else 0) << 3 | arms << 2
               | bool(cols.eta0[0] > 0.0) << 1 | friction)
        path = _path_of_key(key, numerics.integrator_code)
    routes = _ONE_ROW.get(path)
    if routes is None:  # (the group array is shared: callers read it, never write it)
        group = np.full(1, -1 if path is None else 0, dtype=np.int64)
        group.flags.writeable = False
        routes = _ONE_ROW[path] = Routes(group, () if path is None else (path,))
    return routes


def _path_of_key(key: int, integrator: int) -> Path:
    """Return the path of a routing key of :func:`route`.

    The key is ``kind << 5`` for a continuum kernel, else the effect bits of the
    element kernel.
    """
    if key >> 5 == 1:
        return CONTINUUM_KV
    if key >> 5 == 2:
        return CONTINUUM_FULL_STICK
    return _element_path(integrator, key)


@functools.cache
def _element_path(integrator: int, key: int) -> Path:
    """Return the element path of a routing key of :func:`route` (made once per key)."""
    return Path(ELEMENTS, KernelSpec(integrator, bool(key >> 4 & 1), int(key >> 3 & 1),
                                     bool(key >> 2 & 1), bool(key >> 1 & 1), bool(key & 1)), ())


def continuum_stick(cols: SceneColumns, numerics: Numerics, friction: np.ndarray) -> np.ndarray:
    """Return the rows the full-stick continuum kernel can take, bool.

    Those with the continuum allowed, no friction (``friction``: :func:`friction_rows`,
    as :func:`route` has it), incremental memory (or no tangential problem), whatever
    the arms (it updates each arm exactly over a step,
    docs/physics.md#arms-of-any-relaxation-time). Its run-time assumptions (one
    contact interval, no re-entry) are checked by the kernel, which hands a row back
    otherwise.
    """
    tangential = cols.computes_tangential
    incremental = cols.memory == TANGENTIAL_MEMORY.index("incremental")
    return numerics.continuum & cols.valid & ~friction & (incremental | ~tangential)


def handover_reason(status: int) -> str:
    """Why a row left the full-stick continuum kernel for the element path."""
    return ("the continuum kernel found its assumptions broken (the contact split or an "
            "element re-entered)" if status == STATUS_ASSUMPTION else
            "the continuum kernel reached its step limit")


def choose_path(scene: Scene, numerics: Numerics) -> Path:
    """Return the kernel :func:`route` picks for ``scene``, with the reasons in words.

    An adhesive scene gets the adhesive kernel, which :func:`vimpact.simulate` runs.
    """
    if scene.adhesion > 0.0:
        return Path(ADHESION, None, (
            f"work of adhesion {scene.adhesion:g} J/m^2: adhesive normal impact on the MDR "
            "element row with the rule of Hess (docs/physics.md#adhesion), "
            f"{numerics.steps} steps per t_H and {numerics.elements} elements per a_H "
            "(refined for a glassy modulus and a strong adhesion), verlet",))
    cols = SceneColumns.from_scenes([scene])
    routes = route(cols, numerics)
    path = routes.paths[routes.group[0]]
    mat = scene.material
    arms, dashpot = bool(cols.has_arms[0]), mat.eta0 > 0.0
    tangential = scene.computes_tangential
    reasons = []
    if scene.tangential == "none":
        reasons.append("normal impact only (tangential = 'none'): no tangential state")
    elif scene.v_c0 == 0.0:
        reasons.append("v_c0 = v_x0 + R omega0 = 0: no tangential force, tangential work skipped")
    else:
        rot = (f"with rotation (Theta/(m R^2) = {scene.theta_ratio:.4g}, contact-point mass "
               f"factor {scene.contact_mass_factor:.4g})" if scene.rotation
               else "without rotation (Theta -> inf)")
        contact = ("full stick" if path.spec is None or not path.spec.friction
                   else f"Coulomb friction mu = {scene.mu:g}")
        if np.isfinite(scene.mu) and not friction_rows(cols)[0]:
            contact = (f"full stick (mu = {scene.mu:g}, but the incidence psi is below "
                       f"{PSI_FULL_STICK:g}: friction changes beta_x by less than rounding)")
        reasons.append(f"tangential {contact}, {scene.tangential_memory} memory, {rot}")
        if mat.nu != 0.5:
            reasons.append(f"nu = {mat.nu:g}: the tangential MDR mapping is exact only at "
                           "nu = 0.5 for a rigid sphere; beta_x here is the thesis's approximation")
    what = [("Maxwell arms" if arms else "no arm variables"),
            ("a parallel dashpot" if dashpot else "no dashpot term")]
    reasons.append(f"material {mat.model}: {what[0]}, {what[1]}")
    if path.kind == CONTINUUM:
        reasons.append("Kelvin-Voigt/elastic normal impact: closed-form continuum force, 1-DOF "
                       "ODE, adaptive Dormand-Prince 5(4) with event location, "
                       f"rtol = {numerics.rtol:g}")
        return Path(CONTINUUM, None, tuple(reasons))
    if path.kind == CONTINUUM_STICK:
        reasons.append("full stick with incremental memory: the exact continuum limit of the "
                       "element row (docs/physics.md#continuum-limit), "
                       "adaptive Dormand-Prince 5(4) with event location, "
                       f"rtol = {numerics.rtol:g}; should the contact split or an element "
                       "re-enter, the element kernel takes over")
        return Path(CONTINUUM_STICK, None, tuple(reasons))
    if numerics.continuum and (arms or tangential):
        if path.spec is not None and path.spec.friction:
            reasons.append("Coulomb friction (slip) needs the element row")
        elif tangential and scene.tangential_memory != "incremental":
            reasons.append("seed tangential memory needs the element row")
    if not numerics.continuum:
        reasons.append("continuum path switched off (Numerics.continuum = False)")
    else:
        need = [n for n, on in (("the tangential problem", tangential), ("Maxwell arms", arms)) if on]
        reasons.append(f"elements needed for {' and '.join(need)}")
    glassy = float(discretization.stiffness_ratio(cols)[0])
    ft, fe = (float(x[0]) for x in discretization.refinement(
        cols, numerics, np.array([tangential]), path.spec.integrator))
    why_t = [f"glassy contact {glassy ** 0.4:.3g}x shorter"] if glassy > 1.0 else []
    why_e = [f"glassy contact {glassy ** 0.2:.3g}x narrower"] if glassy > 1.0 else []
    if fe > glassy ** 0.2 * (1.0 + 1e-12):
        why_e.append("stiff tangential mode: finer for elements entering the contact")
    if ft > glassy ** 0.4 * (1.0 + 1e-12):
        why_t.append("stiffest mode and stability of the explicit terms")
    finer = f" (refined {ft:.3g}x: {'; '.join(why_t)})" if ft > 1.0 else ""
    finer_e = f" (refined {fe:.3g}x: {'; '.join(why_e)})" if fe > 1.0 else ""
    reasons.append(f"element kernel: {numerics.integrator}, {numerics.steps} steps per "
                   f"t_H{finer}, {numerics.elements} elements per a_H{finer_e}")
    return Path(ELEMENTS, path.spec, tuple(reasons))


def refinement(scene: Scene, numerics: Numerics, spec: KernelSpec) -> tuple[float, float]:
    """Return the time-step and element-spacing factors (>= 1) of one scene on ``spec``.

    :func:`vimpact.engine.discretization.refinement` of the one-row columns of
    ``scene`` on the kernel ``spec``.
    """
    cols = SceneColumns.from_scenes([scene])
    ft, fe = discretization.refinement(cols, numerics, np.array([bool(spec.tangential)]),
                                       spec.integrator)
    return float(ft[0]), float(fe[0])


def stiffness_ratio(scene: Scene) -> float:
    """:func:`vimpact.engine.discretization.stiffness_ratio` of one scene, >= 1."""
    return float(discretization.stiffness_ratio(SceneColumns.from_scenes([scene]))[0])
