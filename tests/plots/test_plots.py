"""Every thesis figure renders (PNG, and SVG/PDF by extension) from small runs and tables."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from tests.lookup.test_table import make_table, results_frame, run, vimpact_main, write_table  # noqa: F401
from vimpact import Material, Scene
from vimpact.lookup.table import RestitutionTable
from vimpact.plots.figures import FIGURE_NAMES, FIGURES, figure_name, plot_figure


def random_draws_table(path, n=40, seed=3):
    """Random physical Kelvin-Voigt impacts, as the fig. 5.1 sweep draws them."""
    rng = np.random.default_rng(seed)
    E = 10 ** rng.uniform(7, 10, n)         # Pa
    nu = rng.uniform(0.0, 0.5, n)
    eta = 10 ** rng.uniform(1, 5, n)        # Pa s
    R = 10 ** rng.uniform(-3, -1, n)        # m
    m = 2500.0 * 4.0 / 3.0 * np.pi * R**3   # kg
    v = 10 ** rng.uniform(-1, 1, n)         # m/s
    scenes = [Scene(Material.kelvin_voigt(nu=nu[i], E=E[i], eta=eta[i]), R=R[i], m=m[i],
                    v_z0=v[i], v_x0=0.5 * v[i], allow_large_contact=True) for i in range(n)]
    df = results_frame(scenes)
    df = pd.concat([df, pd.DataFrame({"E_Pa": E, "eta_Pa_s": eta, "R_m": R, "m_kg": m,
                                      "v_z0_m_s": v})], axis=1)
    write_table(path, df, "kelvin_voigt", spec="random draws")
    return path


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    d = tmp_path_factory.mktemp("plot_tables")
    make_table(d / "kv.parquet", Q1=np.logspace(-2, 1, 9), fail=(2,))
    make_table(d / "ss.parquet", Q1=np.logspace(-2, 1, 7), nu=(0.0, 0.5), Q2=(0.1, 1.0, 10.0))
    random_draws_table(d / "random.parquet")
    return {"fig5_1": d / "random.parquet", "fig5_2": d / "kv.parquet", "fig5_3": d / "kv.parquet",
            "fig5_4": d / "ss.parquet", "fig5_5": d / "ss.parquet"}


#: the friction figures simulate ~100 oblique impacts each: drawn in
#: tests/plots/test_friction_figures.py (slow), their data checked there
FRICTION = ("fig_mbf", "fig_beta_psi", "fig_chung_ooi")
#: e_z(v) of the example polymer at five temperatures (45 impacts on the element path):
#: drawn in tests/plots/test_temperature_figure.py (slow)
TEMPERATURE = ("fig_temperature",)
#: e_z(v) and sticking velocities of the adhesive example: drawn in tests/adhesion
ADHESION = ("fig_adhesion",)


@pytest.mark.parametrize("name", [n for n in FIGURE_NAMES if n not in FRICTION + TEMPERATURE + ADHESION])
def test_every_figure_renders_png(name, tables, tmp_path):
    out = tmp_path / f"{name}.png"
    path = plot_figure(name, out, table=tables.get(name))
    assert path == out and out.stat().st_size > 10_000
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_svg_and_pdf_by_extension(tmp_path):
    # the quickest SVG (fig. 4.2: 0.27 s) and the quickest PDF (fig. 4.4: 0.53 s; a PDF
    # embeds subsets of its fonts, the more text the costlier)
    svg = plot_figure("4.2", tmp_path / "f.svg")
    assert svg.stat().st_size > 0 and b"<svg" in svg.read_bytes()[:2000]
    pdf = plot_figure("4.4", tmp_path / "f.pdf")
    assert pdf.read_bytes()[:5] == b"%PDF-"


@pytest.fixture
def drawn(monkeypatch):
    """Figures drawn but not rendered: each ``savefig`` records the curves of the figure
    (``[[(label, x, y), ...] per axes]``, appended to the list this fixture returns) and
    writes nothing. For the tests of what is drawn from which input; the rendering of every
    figure function is checked by :func:`test_every_figure_renders_png` and
    :func:`test_svg_and_pdf_by_extension` (rendering is matplotlib's text layout, the slow
    part of a figure)."""
    from matplotlib.figure import Figure

    figures: list = []

    def record(fig, *args, **kwargs):
        figures.append([[(line.get_label(), np.asarray(line.get_xdata(), float),
                          np.asarray(line.get_ydata(), float)) for line in ax.get_lines()]
                        for ax in fig.axes])

    monkeypatch.setattr(Figure, "savefig", record)
    return figures


def curve(recorded, label: str) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) of the one curve labelled ``label`` in a recorded one-axes figure."""
    (axes,) = recorded
    found = [(x, y) for name, x, y in axes if name == label]
    assert len(found) == 1, [name for name, _, _ in axes]
    return found[0]


def kelvin_voigt_e_x(kv: pd.DataFrame, nu: float) -> tuple[np.ndarray, np.ndarray]:
    """The table's (Q1, e_x) at ``nu``, rows with a result, by increasing Q1."""
    rows = kv[np.isclose(kv.nu, nu) & np.isfinite(kv.e_x)].sort_values("Q1")
    assert len(rows) >= 5
    return rows.Q1.to_numpy(float), rows.e_x.to_numpy(float)


def test_table_as_dataframe_and_kelvin_voigt_rows_in_a_standard_solid_table(tables, tmp_path,
                                                                               drawn):
    """What is drawn from each form of the input (the curves, not the pixels: ``drawn``)."""
    kv = RestitutionTable.open(tables["fig5_2"]).data
    plot_figure("fig5_3", tmp_path / "a.png", table=kv)  # a DataFrame of rows works too
    for nu in (0.0, 0.25, 0.5):  # one curve per nu: the table's e_x over Q1
        assert np.array_equal(curve(drawn[-1], f"$\\nu$ = {nu:g}"), kelvin_voigt_e_x(kv, nu))
    # a fig 5.4/5.5 table that carries its own Kelvin-Voigt rows (Q2 = 0, the sweep's
    # convention for the limit G2 -> inf) draws those as the black curve
    ss = RestitutionTable.open(tables["fig5_4"])
    mixed = pd.concat([ss.data, kv[np.isclose(kv.nu, 0.5)].assign(Q2=0.0)], ignore_index=True)
    plot_figure("fig5_5", tmp_path / "b.png", table=RestitutionTable(mixed, {"model": "standard_solid"}))
    assert np.array_equal(curve(drawn[-1], "Kelvin-Voigt"), kelvin_voigt_e_x(kv, 0.5))
    # or a separate Kelvin-Voigt table, in either order
    plot_figure("5.5", tmp_path / "c.svg", table=[tables["fig5_2"], tables["fig5_4"]])
    assert np.array_equal(curve(drawn[-1], "Kelvin-Voigt"), kelvin_voigt_e_x(kv, 0.5))
    assert len(drawn) == 3
    with pytest.raises(ValueError, match="one standard_solid table and optionally one"):
        plot_figure("5.5", tmp_path / "d.png", table=[tables["fig5_4"], tables["fig5_4"]])
    with pytest.raises(ValueError, match="takes one table, got 2"):
        plot_figure("5.2", tmp_path / "d.png", table=[tables["fig5_2"], tables["fig5_2"]])


def test_kelvin_voigt_curve_is_the_closed_form(tables, tmp_path, drawn):
    """The continuum curve of fig. 5.2 (drawn at rtol 1e-8) is the closed form at its
    default rtol 1e-12 to 1e-7, at every eighth point and the ends of the table's range
    (rtol 1e-6 would be 1e-6 off there)."""
    from vimpact.reference.closed_forms import kelvin_voigt_continuum

    plot_figure("fig5_2", tmp_path / "a.png", table=tables["fig5_2"])
    q1, e_z = curve(drawn[-1], "Kelvin-Voigt continuum (1-DOF ODE)")
    kv = RestitutionTable.open(tables["fig5_2"]).data
    assert q1[0] == kv.Q1.min() and q1[-1] == kv.Q1.max()
    at = [*range(0, len(q1), 8), len(q1) - 1]
    exact = kelvin_voigt_continuum(q1[at]).e_z
    assert np.abs(e_z[at] - exact).max() < 1e-7


def test_figure_errors(tables, tmp_path):
    with pytest.raises(ValueError, match="sweeps/fig5_2_3_kelvin_voigt_nu.toml"):
        plot_figure("fig5_2", tmp_path / "x.png")
    with pytest.raises(ValueError, match="needs a kelvin_voigt table"):
        plot_figure("fig5_2", tmp_path / "x.png", table=tables["fig5_4"])
    with pytest.raises(ValueError, match="needs a standard_solid table.*fig5_4_5_standard_solid_q2.toml"):
        plot_figure("fig5_4", tmp_path / "x.png", table=tables["fig5_2"])
    with pytest.raises(ValueError, match="must end in .png, .svg, .pdf"):
        plot_figure("fig3_2", tmp_path / "x.jpg")
    with pytest.raises(ValueError, match="must be one of fig3_2"):
        plot_figure("fig9_9", tmp_path / "x.png")
    with pytest.raises(ValueError, match="takes no table"):
        plot_figure("fig3_2", tmp_path / "x.png", table=tables["fig5_2"])
    assert not list(tmp_path.iterdir())


def test_figure_names():
    assert set(FIGURE_NAMES) == {"fig3_2", "fig4_2", "fig4_4", "fig5_1", "fig5_2", "fig5_3",
                                 "fig5_4", "fig5_5", *FRICTION, *TEMPERATURE, *ADHESION}
    assert figure_name("5.2") == figure_name("Fig 5.2") == figure_name("fig5_2") == "fig5_2"
    assert all(FIGURES[n].spec for n in FIGURE_NAMES if n.startswith("fig5"))


def test_cli_plot(vimpact_main, tables, tmp_path, capsys, drawn):  # noqa: F811 (the imported fixture)
    out = tmp_path / "f.png"
    code, text, err = run(vimpact_main, ["plot", "fig5_5", "--out", str(out), "--table",
                                         str(tables["fig5_4"]), "--table", str(tables["fig5_2"])],
                          capsys)
    assert code == 0 and out.exists() and str(out) in text, err
    # both tables reached the figure: the black curve is the Kelvin-Voigt table's (drawn,
    # not rendered: the rendering of fig. 5.5 is test_every_figure_renders_png's)
    kv = RestitutionTable.open(tables["fig5_2"]).data
    assert np.array_equal(curve(drawn[-1], "Kelvin-Voigt"), kelvin_voigt_e_x(kv, 0.5))
    code, text, err = run(vimpact_main, ["plot", "fig5_1", "--out", str(out)], capsys)
    assert (code == 2 and "sweeps/fig5_1_kelvin_voigt_random.toml" in err
            and len(err.strip().splitlines()) == 1)
    code, _, err = run(vimpact_main, ["plot", "nope", "--out", str(out)], capsys)
    assert code == 2 and "fig3_2" in err
