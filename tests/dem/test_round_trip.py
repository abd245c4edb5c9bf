"""Round trips: the DEM code itself, fed the exported constants, restitutes what the
report predicted for it (LAMMPS; REBOUND with the exported callback module)."""

import importlib.util

import numpy as np
import pytest

from tests.dem.codes import need
from tests.dem.conftest import one_lammps_process_in
from vimpact.dem import lammps
from vimpact.dem.export import export
from vimpact.dem.laws import hertz_contact_time
from vimpact.dem.problem import problem_from_toml

TOML = """
[speeds]
min = 0.05
max = 1.0
n = 8
[types.a]
density = 1150.0
radius = 0.005
[types.a.material]
model = "kelvin_voigt"
nu = 0.45
G = 3e7
eta = 600.0
[types.b]
density = 1250.0
radius = 0.004
[types.b.material]
model = "kelvin_voigt"
nu = 0.45
G = 6e7
eta = 1200.0
[walls.floor]
material = "rigid"
[friction]
default = 0.5
"""


@pytest.fixture(scope="module")
def problem():
    return problem_from_toml(TOML, "round-trip")


_NO_LAMMPS = lammps.lammps_available()


@pytest.fixture(scope="module")
def lammps_export(code_run):
    """The LAMMPS export of :data:`TOML` that ``vimpact dem --for lammps`` made (the CLI
    test's run)."""
    run = code_run("lammps")
    assert run.status == 0
    return run.export


#: the contacts, speeds (m/s) and steps per contact of the head-on LAMMPS collisions against
#: the report's law
COLLISIONS = [(key, v, steps) for key in ("a-floor", "a-b") for v in (0.1, 1.0)
              for steps in (1000, 4000)]


@pytest.fixture(scope="module")
def lammps_collisions(lammps_export, _lammps_worker):
    """LAMMPS' e of each of :data:`COLLISIONS` (one LAMMPS run each, in the session's LAMMPS
    worker process: tests/dem/conftest.py)."""
    need(_NO_LAMMPS, "LAMMPS")
    fits = {f.contact.key: f for f in lammps_export.fits}
    runs = []
    for key, v, steps in COLLISIONS:
        f = fits[key]
        R, m = f.contact.nominal()
        runs.append((f, v, float(hertz_contact_time(f.params["E_star_Pa"], R, m, v)), steps))
    with pytest.MonkeyPatch.context() as mp:
        one_lammps_process_in(mp, _lammps_worker)
        return dict(zip(COLLISIONS, lammps.lammps_restitutions(runs)))


@pytest.mark.parametrize("key", ["a-floor", "a-b"])
def test_lammps_restitutes_what_the_report_predicts(lammps_export, lammps_collisions, key):
    fits = {f.contact.key: f for f in lammps_export.fits}
    f = fits[key]
    for v in (0.1, 1.0):
        predicted = float(lammps.predicted_restitution(f, v))
        coarse = lammps_collisions[key, v, 1000]
        fine = lammps_collisions[key, v, 4000]
        # LAMMPS' velocity-Verlet error shrinks with the time step towards the prediction
        assert abs(fine - predicted) < abs(coarse - predicted) or abs(fine - predicted) < 1e-6
        assert fine == pytest.approx(predicted, abs=5e-5)


def test_rebound_round_trip_with_the_exported_callback(code_run):
    """The callback module ``vimpact dem --for rebound`` wrote for :data:`TOML` (the CLI
    test's run)."""
    rebound = pytest.importorskip("rebound", reason="REBOUND round trip: pip install rebound")
    run = code_run("rebound")
    assert run.status == 0
    ex = run.export
    spec = importlib.util.spec_from_file_location("vimpact_restitution_rt",
                                                  run.folder / "vimpact_restitution.py")
    cor = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cor)
    fit = next(f for f in ex.fits if f.contact.key == cor.CONTACT)
    b1, b2 = fit.contact.levels()[0]
    for v in (0.07, 0.3, 0.9):
        sim = rebound.Simulation()
        sim.G = 0.0
        sim.integrator = "leapfrog"
        sim.dt = 1e-5
        sim.collision = "direct"
        sim.collision_resolve = "hardsphere"
        sim.coefficient_of_restitution = cor.coefficient_of_restitution
        sim.add(m=b1.m, r=b1.R, x=-(b1.R + 1e-4), vx=v * b2.m / (b1.m + b2.m))
        sim.add(m=b2.m, r=b2.R, x=b2.R + 1e-4, vx=-v * b1.m / (b1.m + b2.m))
        sim.integrate(0.01)
        e = (sim.particles[1].vx - sim.particles[0].vx) / v
        # what the report says REBOUND will produce: vimpact's curve, interpolated in log v
        expected = float(np.interp(np.log(v), np.log(fit.params["v_m_s"]), fit.params["e_z"]))
        assert e == pytest.approx(expected, rel=1e-9)
    # and that is vimpact's e_z at the table speeds
    assert fit.params["e_z"] == pytest.approx(list(ex.targets[fit.contact.key].e_z), rel=1e-12)


def test_lammps_hertz_material_wall_is_a_body_of_the_particles_material():
    """What docs/dem.md says about LAMMPS (why the export uses `hertz` with k_n per
    contact): with `hertz/material E eta nu` a `fix wall/gran` wall behaves as a body of
    the same E and nu, E* = E / (2 (1 - nu^2)), not as a rigid wall (E / (1 - nu^2)).
    Measured through the elastic contact time against the Hertz closed form."""
    import math

    need(_NO_LAMMPS, "LAMMPS")
    R, rho, v, E, nu = 0.005, 1150.0, 0.5, 1e8, 0.3
    m = rho * 4.0 / 3.0 * math.pi * R**3

    def t_hertz(E_star):
        return float(hertz_contact_time(E_star, R, m, v))

    dt = t_hertz(E / (1 - nu**2)) / 4000
    n = int(3 * t_hertz(E / (1 - nu**2)) / dt)
    coeff = f"hertz/material {E} 0.0 {nu} damping viscoelastic tangential linear_nohistory 0 0"
    script = "\n".join([
        "units si", "atom_style sphere", "atom_modify map array", "boundary f f f",
        "comm_modify vel yes", "region box block -0.05 0.05 -0.05 0.05 -0.05 0.05",
        "create_box 1 box", "pair_style granular", f"pair_coeff * * {coeff}",
        f"create_atoms 1 single 0 0 {R}", f"set atom 1 diameter {2 * R} density {rho}",
        f"velocity all set 0 0 {-v}", f"fix w all wall/gran granular {coeff} zplane 0.0 NULL",
        f"variable inside equal z[1]<{R}", "fix nve all nve/sphere", f"timestep {dt}",
        f"fix a all ave/time 1 {n} {n} v_inside", "variable frac equal f_a", f"run {n}", ""])
    frac, = lammps.run_lammps(script, ["frac"])
    t_contact = frac * n * dt
    assert t_contact == pytest.approx(t_hertz(E / (2 * (1 - nu**2))), rel=1e-3)
    assert t_contact / t_hertz(E / (1 - nu**2)) == pytest.approx(2**0.4, rel=1e-3)


def test_lammps_runs_the_exported_files_at_every_size_level(one_lammps_process):
    """What users paste: the settings, the per-type pair_coeff lines and the wall groups and
    fixes, included unchanged in the documented order, with particles of every type at every
    size level (a size range, so LAMMPS' mass scaling of the damping enters)."""
    need(_NO_LAMMPS, "LAMMPS")
    problem = problem_from_toml(TOML.replace("radius = 0.004", "radius = [0.003, 0.005]"), "rt")
    fits = export(problem, "lammps", tangential=False).fits  # the normal law is checked here
    speeds = np.geomspace(problem.speeds.min(), problem.speeds.max(), 5)
    diff = {}
    steps_list = (lammps.STEPS_PER_CONTACT, 4 * lammps.STEPS_PER_CONTACT)
    for steps, rows in lammps.round_trips_files(problem, speeds, steps_list, fits=fits).items():
        assert {(r["contact"], r["level"]) for r in rows} == {
            (f.contact.key, k) for f in fits for k in range(len(f.contact.levels()))}
        diff[steps] = max(abs(r["e"] - r["predicted"]) for r in rows)
    assert diff[lammps.STEPS_PER_CONTACT] < 1e-3
    assert diff[4 * lammps.STEPS_PER_CONTACT] < diff[lammps.STEPS_PER_CONTACT] / 2


def oblique_rows_against_vimpact(rows, ob):
    """Pair each round-trip row with vimpact's beta_x at the same (speed, angle)."""
    key = {(round(v, 12), a): b for v, a, b in zip(ob.v, ob.angle_deg, ob.beta_x)}
    return [(r, key[(round(r["v"], 12), r["angle"])]) for r in rows]


def test_lammps_oblique_wall_impacts_give_the_reported_beta(problem, lammps_export,
                                                          one_lammps_process):
    """The exported LAMMPS files, run on oblique wall impacts with the set-up's friction at
    the report's speeds and impact angles: LAMMPS' beta (from its velocities) is the
    report's prediction to its time-step error, shrinking with the step, and it lies
    within the report's stated beta_x residual (plus that error) of vimpact's."""
    need(_NO_LAMMPS, "LAMMPS")
    ex = lammps_export
    f = next(x for x in ex.fits if x.contact.key == "a-floor")
    ob = ex.targets["a-floor"].oblique
    assert ob is not None and f.beta_oblique is not None and ob.mu == 0.5
    speeds, angles = sorted(set(ob.v.tolist())), sorted(set(ob.angle_deg.tolist()))
    diff = {}
    fine = 4 * lammps.STEPS_PER_CONTACT
    runs = lammps.round_trips_files(problem, speeds, (lammps.STEPS_PER_CONTACT, fine),
                                    fits=ex.fits, angles_deg=angles, contacts={"a-floor"})
    for steps, rows in runs.items():
        assert len(rows) == len(speeds) * len(angles)
        diff[steps] = max(abs(r["beta"] - r["predicted_beta"]) for r in rows)
    rows = runs[fine]
    assert diff[fine] < 3e-3
    assert diff[fine] < diff[lammps.STEPS_PER_CONTACT] / 2  # first order in the step
    for r, beta_vimpact in oblique_rows_against_vimpact(rows, ob):
        assert abs(r["beta"] - beta_vimpact) <= f.res_beta_x.max_abs + diff[fine]
        assert r["e"] == pytest.approx(r["predicted"], abs=2e-4)


def test_full_stick_beta_of_a_contact_with_friction_is_lammps_law_in_stick(lammps_export):
    """A contact with friction is fitted and reported over its oblique impacts, so its
    full-stick ``beta_x`` (the Hertz-Mindlin ODE with the fitted ``k_t``, ``x_gamma_t``) is
    only worked out when read; read, it is the limit of the stepped LAMMPS law with no
    Coulomb cap (an independent integration): the largest difference falls about as the
    time step (6e-4 at 2000 steps per contact, about 4x less per 4x steps), to below 1e-4."""
    import math

    from vimpact.dem import laws, linear

    for key in ("a-floor", "a-b"):
        f = next(f for f in lammps_export.fits if f.contact.key == key)
        t, p = lammps_export.targets[key], f.params
        assert f.has_beta_x and f.beta_oblique is not None
        assert f.beta_x.shape == t.v.shape
        alpha = p["A_s"] * t.v / laws.hertz_overlap(p["E_star_Pa"], t.R, t.m, t.v)
        gaps = []
        for steps in (2000, 8000, 32000):
            _, stick = laws.hertz_mindlin_coulomb(
                alpha, p["k_t"] / (2.0 * p["E_star_Pa"]), p["x_gamma_t"],
                linear.mass_factor(f.contact), math.inf, np.ones_like(alpha), steps)
            gaps.append(float(np.max(np.abs(f.beta_x - stick))))
        assert gaps[0] < 1e-3 and gaps[2] < 1e-4, gaps
        assert gaps[1] < gaps[0] / 3.0 and gaps[2] < gaps[1] / 3.0, gaps
