"""Scene files: the shipped examples, parity with a sweep's fixed values, errors."""

import dataclasses
import math
from pathlib import Path

import pytest

import vimpact as v
from vimpact.model.scene_file import load_scene, scene_from_toml
from vimpact.sweep.spec import load_spec

SCENES = Path(__file__).resolve().parents[2] / "sweeps" / "scenes"

KV = """
model = "kelvin_voigt"
[scene]
E_Pa = 1e7
eta_Pa_s = 10.0
nu = 0.3
R_m = 0.01
m_kg = 0.001
v_z0_m_s = 1.0
"""


def write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


# ---- the shipped examples -----------------------------------------------------

def test_rubber_ball_example():
    scene, numerics = load_scene(SCENES / "rubber_ball.toml")
    material = v.Material.standard_solid(nu=0.49, G1=1e7, G2=3e7, eta=600.0)
    assert scene == v.Scene(material, R=0.01, m=0.004, v_z0=1.0, v_x0=0.8, omega0=-40.0,
                            Theta=0.4 * 0.004 * 0.01**2)
    assert scene.tangential == "auto" and scene.rotation and not scene.allow_large_contact
    assert scene.computes_tangential and scene.v_c0 == pytest.approx(0.4)
    assert numerics == v.Numerics.preset("default")


def test_normal_kelvin_voigt_example():
    scene, numerics = load_scene(SCENES / "normal_kelvin_voigt.toml")
    material = v.Material.kelvin_voigt(nu=0.5, E=5e10, eta=1e5)
    assert scene == v.Scene(material, R=0.2, m=10.0, v_z0=10.0, tangential="none")
    assert not scene.computes_tangential and not scene.allow_large_contact
    assert numerics is None


def test_every_shipped_scene_loads():
    names = sorted(p.stem for p in SCENES.glob("*.toml"))
    assert {"rubber_ball", "normal_kelvin_voigt"} <= set(names)
    for name in names:
        scene, _ = load_scene(SCENES / f"{name}.toml")
        assert isinstance(scene, v.Scene)


# ---- the same values as a sweep's [random] table --------------------------------

# Bodies shared verbatim by a sweep's [random] table and a scene's [scene] table.
BODIES = {
    "elastic_E": ("elastic", "E_Pa = 2e9\nnu = 0.25\nR_m = 0.02\nm_kg = 0.05\nv_z0_m_s = 3.0\n"),
    "elastic_G": ("elastic", "G_Pa = 8e8\nnu = 0.5\nR_m = 0.02\nm_kg = 0.05\nv_z0_m_s = 3.0\n"
                             "v_x0_m_s = -1.5\n"),
    "kelvin_voigt_E": ("kelvin_voigt", "E_Pa = 1e7\neta_Pa_s = 10.0\nnu = 0.3\nR_m = 0.01\n"
                                       "m_kg = 0.001\nv_z0_m_s = 1.0\nv_x0_m_s = 0.5\n"
                                       "omega0_rad_s = 20\ntheta_ratio = 0.25\n"),
    "kelvin_voigt_G": ("kelvin_voigt", "G_Pa = 4e6\neta_Pa_s = 0\nnu = 0.0\nR_m = 1\n"
                                       "m_kg = 2\nv_z0_m_s = 0.1\nomega0_rad_s = -3.5\n"),
    "standard_solid": ("standard_solid", "G1_Pa = 1e7\nG2_Pa = 3e7\neta_Pa_s = 600\nnu = 0.49\n"
                                         "R_m = 0.01\nm_kg = 0.004\nv_z0_m_s = 1.0\n"
                                         "v_x0_m_s = 0.8\nomega0_rad_s = -40\n"),
    "prony": ("prony", "G_Pa = 1e6\neta_Pa_s = 5.0\nnu = 0.45\nR_m = 0.01\nm_kg = 0.001\n"
                       "v_z0_m_s = 2.0\nv_x0_m_s = 1.0\n"
                       "arms = [{G_Pa = 2e6, tau_s = 1e-3}, {G_Pa = 5e6, tau_s = 1e-5}]\n"),
    "prony_no_dashpot": ("prony", "G_Pa = 1e6\nnu = 0.45\nR_m = 0.01\nm_kg = 0.001\n"
                                  "v_z0_m_s = 2.0\narms = [{G_Pa = 2e6, tau_s = 1e-3}]\n"),
    "kelvin_voigt_friction_angle": ("kelvin_voigt", "E_Pa = 2.5e9\neta_Pa_s = 2e3\nnu = 0.4\n"
                                                    "R_m = 0.005\nm_kg = 0.0041\nv_z0_m_s = 1.3\n"
                                                    "angle_deg = 37.5\nmu = 0.2\n"
                                                    "omega0_rad_s = 12\n"),
    "standard_solid_mu_inf": ("standard_solid", "G1_Pa = 1e7\nG2_Pa = 3e7\neta_Pa_s = 600\n"
                                                "nu = 0.49\nR_m = 0.01\nm_kg = 0.004\n"
                                                'v_z0_m_s = 1.0\nv_x0_m_s = 0.8\nmu = "inf"\n'),
    "elastic_frictionless": ("elastic", "G_Pa = 8e8\nnu = 0.5\nR_m = 0.02\nm_kg = 0.05\n"
                                        "v_z0_m_s = 3.0\nangle_deg = 0\nmu = 0\n"),
}
TOP = 'tangential_memory = "{memory}"\n[numerics]\npreset = "fast"\nsteps = 500\n'
#: Bodies with a finite friction coefficient: the seed memory refuses them.
FRICTION = ("kelvin_voigt_friction_angle", "elastic_frictionless")


@pytest.mark.parametrize("name", sorted(BODIES))
def test_scene_file_equals_sweep_row_with_the_same_values(tmp_path, name):
    model, body = BODIES[name]
    memory = "incremental" if name in FRICTION else "seed"
    head = f'model = "{model}"\n' + TOP.format(memory=memory)
    spec = load_spec(write(tmp_path, head.replace("[numerics]", "seed = 1\n[numerics]")
                           + "[random]\nrows = 1\n" + body, "sweep.toml"))
    scene, numerics = load_scene(write(tmp_path, head + "[scene]\n" + body))
    expected = spec.scene(spec.parameters(), 0)
    # a sweep row always allows a large contact; a scene file only when it says so
    assert scene == dataclasses.replace(expected, allow_large_contact=False)
    assert (scene.tangential_memory, scene.Theta) == (memory, expected.Theta)
    assert numerics == spec.numerics == v.Numerics.preset("fast").with_(steps=500)


@pytest.mark.parametrize("name", FRICTION)
def test_seed_memory_with_finite_friction_is_refused_in_both(tmp_path, name):
    """Coulomb friction needs the incremental memory: a scene file and a sweep spec
    with the seed memory and a finite mu are refused, naming the file and mu."""
    model, body = BODIES[name]
    head = f'model = "{model}"\n' + TOP.format(memory="seed")
    with pytest.raises(ValueError, match=r"scene\.toml: scene: mu = 0\.[02] is not allowed: .*seed"):
        load_scene(write(tmp_path, head + "[scene]\n" + body, "scene.toml"))
    with pytest.raises(ValueError, match=r"sweep\.toml: random\.mu.*seed"):
        load_spec(write(tmp_path, head.replace("[numerics]", "seed = 1\n[numerics]")
                        + "[random]\nrows = 1\n" + body, "sweep.toml"))


def test_defaults_and_options():
    scene, numerics = scene_from_toml(KV)
    assert (scene.v_x0, scene.omega0, scene.theta_ratio) == (0.0, 0.0, pytest.approx(0.4))
    assert (scene.tangential, scene.rotation, scene.allow_large_contact) == ("auto", True, False)
    assert scene.tangential_memory == "incremental" and numerics is None
    options = ('tangential = "stick"\nrotation = false\nallow_large_contact = true\n'
               'description = "x"\nnumerics = "thesis"\n')
    scene, numerics = scene_from_toml(options + KV)
    assert (scene.tangential, scene.rotation, scene.allow_large_contact) == ("stick", False, True)
    assert numerics == v.Numerics.preset("thesis")
    scene, numerics = scene_from_toml(KV.replace("[scene]", "[numerics]\n[scene]"))
    assert numerics == v.Numerics.preset("default")


def test_friction_coefficient_and_impact_angle():
    scene, _ = scene_from_toml(KV)
    assert scene.mu == math.inf  # default: full stick
    for text, mu in (("mu = 0.3", 0.3), ("mu = 0", 0.0), ('mu = "inf"', math.inf),
                     ("mu = inf", math.inf), ("mu = 2", 2.0)):
        assert scene_from_toml(KV + text + "\n")[0].mu == mu
    # 30 degrees from the normal at v_z0 = 1 m/s: v_x0 = tan(30 deg) = 1/sqrt(3) m/s
    scene, _ = scene_from_toml(KV + "angle_deg = 30\nmu = 0.5\n")
    assert scene.v_x0 == pytest.approx(1.0 / math.sqrt(3.0), rel=1e-15)
    assert (scene.v_z0, scene.mu) == (1.0, 0.5)
    assert scene_from_toml(KV + "angle_deg = 0\n")[0].v_x0 == 0.0


def test_friction_example():
    scene, _ = load_scene(SCENES / "steel_on_polymer_friction.toml")
    assert 0.0 < scene.mu < math.inf and scene.computes_tangential
    # incidence (Maw, Barber and Fawcett; docs/physics.md#coulomb-friction): gross slip
    # from the start
    nu = scene.material.nu
    psi = 2 * (1 - nu) / (scene.mu * (2 - nu)) * scene.v_c0 / scene.v_z0
    assert psi > 4 * (1 - nu) * scene.contact_mass_factor / (2 - nu)  # psi > 4 chi


def test_prony_arms_as_tables():
    scene, _ = scene_from_toml('model = "prony"\n[scene]\nG_Pa = 1e6\nnu = 0.5\nR_m = 0.01\n'
                               'm_kg = 0.001\nv_z0_m_s = 1.0\n'
                               '[[scene.arms]]\nG_Pa = 2e6\ntau_s = 1e-3\n'
                               '[[scene.arms]]\nG_Pa = 3e6\ntau_s = 1e-4\n')
    assert scene.material == v.Material.prony(nu=0.5, G_inf=1e6,
                                              arms=[(2e6, 1e-3), (3e6, 1e-4)])


# ---- errors --------------------------------------------------------------------

@pytest.mark.parametrize("text, keys", [
    ('colour = 1\n' + KV, ["colour", "tangential", "allow_large_contact"]),
    (KV + "E = 1e7\n", ["scene.E", "E_Pa", "eta_Pa_s", "theta_ratio"]),
    (KV + "rows = 1\n", ["scene.rows"]),
    (KV.replace("nu = 0.3", "nu = [0.3, 0.5]"), ["scene.nu", "one number"]),
    (KV.replace("R_m = 0.01", "R_m = { range = [0.01, 0.1] }"), ["scene.R_m", "one number"]),
    (KV.replace("m_kg = 0.001", "m_kg = { choice = [1e-3, 1e-2] }"), ["scene.m_kg"]),
    (KV.replace("R_m = 0.01\n", "").replace("v_z0_m_s = 1.0\n", ""),
     ["scene.R_m", "scene.v_z0_m_s", "missing"]),
    (KV.replace("eta_Pa_s = 10.0\n", ""), ["scene.eta_Pa_s", "missing"]),
    (KV.replace("E_Pa = 1e7", "G_Pa = 1e7\nE_Pa = 1e7"), ["E_Pa/G_Pa"]),
    (KV.replace("E_Pa = 1e7\n", ""), ["E_Pa/G_Pa"]),
    (KV.replace('"kelvin_voigt"', '"maxwell"'), ["model", "maxwell", "kelvin_voigt"]),
    (KV.replace('model = "kelvin_voigt"\n', ""), ["model", "missing"]),
    ('tangential = "slip"\n' + KV, ["tangential", "slip", "'stick'"]),
    ('tangential_memory = "total"\n' + KV, ["tangential_memory", "total"]),
    ("rotation = 1\n" + KV, ["rotation", "true or false"]),
    ('allow_large_contact = "yes"\n' + KV, ["allow_large_contact"]),
    ("description = 3\n" + KV, ["description"]),
    (KV.replace("nu = 0.3", "nu = 0.7"), ["scene.nu", "[0, 0.5]"]),
    (KV.replace("v_z0_m_s = 1.0", "v_z0_m_s = -1.0"), ["scene.v_z0_m_s", "> 0"]),
    (KV.replace("E_Pa = 1e7", 'E_Pa = "stiff"'), ["scene.E_Pa", "finite number"]),
    (KV.replace("m_kg = 0.001", "m_kg = true"), ["scene.m_kg"]),
    (KV.replace("[scene]", "[numerics]\nsteps = 3\n[scene]"), ["numerics.steps"]),
    (KV.replace("[scene]", "[numerics]\npreset = \"slow\"\n[scene]"), ["numerics.preset"]),
    (KV.replace("[scene]", "[numerics]\ndt = 1e-3\n[scene]"), ["numerics.dt"]),
    (KV.replace("[scene]", "[random]"), ["random", "[scene]"]),
    ("seed = 1\n" + KV, ["seed", "sweep key"]),
    ('model = "kelvin_voigt"\n', ["scene", "missing"]),
    ('model = "kelvin_voigt"\nscene = 1\n', ["scene"]),
    (KV + "arms = []\n", ["scene.arms"]),
    ('model = "prony"\n[scene]\nG_Pa = 1e6\nnu = 0.5\nR_m = 0.01\nm_kg = 0.001\n'
     'v_z0_m_s = 1.0\narms = [{G_Pa = 2e6}]\n', ["scene.arms[1].tau_s", "missing"]),
    ('model = "prony"\n[scene]\nG_Pa = 1e6\nnu = 0.5\nR_m = 0.01\nm_kg = 0.001\n'
     'v_z0_m_s = 1.0\narms = [{G_Pa = 2e6, tau_s = [1e-3, 1e-2]}]\n', ["scene.arms[1].tau_s"]),
    ('model = "prony"\n[scene]\nG_Pa = 1e6\nnu = 0.5\nR_m = 0.01\nm_kg = 0.001\n'
     'v_z0_m_s = 1.0\narms = [{G_Pa = 2e6, tau_s = 1e-3, eta = 1}]\n', ["scene.arms[1].eta"]),
    ('model = "kelvin_voigt"\n[scene\n', ["TOML"]),
    (KV + "mu = -0.1\n", ["scene.mu", ">= 0"]),
    (KV + "mu = nan\n", ["scene.mu", ">= 0"]),
    (KV + 'mu = "stick"\n', ["scene.mu", "inf"]),
    (KV + "mu = [0.1, 0.2]\n", ["scene.mu", "one number"]),
    (KV + "angle_deg = 90\n", ["scene.angle_deg", "[0, 90)"]),
    (KV + "angle_deg = -5\n", ["scene.angle_deg", "[0, 90)"]),
    (KV + "angle_deg = 30\nv_x0_m_s = 0.5\n", ["scene.angle_deg/v_x0_m_s"]),
])
def test_bad_scene_file_names_file_and_key(tmp_path, text, keys):
    path = write(tmp_path, text, "bad_scene.toml")
    with pytest.raises(ValueError) as info:
        load_scene(path)
    message = str(info.value)
    assert "bad_scene.toml" in message
    for key in keys:
        assert key in message
    assert "\n" not in message.strip() or keys == ["TOML"]


def test_missing_scene_file(tmp_path):
    with pytest.raises(ValueError, match="nowhere.toml.*not found"):
        load_scene(tmp_path / "nowhere.toml")


def test_source_names_a_string_scene():
    with pytest.raises(ValueError, match="^my-scene: scene.R_m"):
        scene_from_toml(KV.replace("R_m = 0.01", "R_m = 0"), source="my-scene")
