"""The batch unpack (status codes) and the scalar unpack of one row agree; the code
tables follow the status table."""

import numpy as np

from vimpact.engine.result import FINISHED, STATUS_CODE, STATUS_NAMES, STATUSES, Coded
from vimpact.engine.unpack import finished_codes


def test_finished_codes_are_the_finished_names():
    """The finished mask of status codes is ``name in FINISHED`` of their names, for
    every status of the table (the sweep's ``failed`` too)."""
    codes = np.arange(len(STATUS_NAMES))
    names = np.array(STATUS_NAMES, dtype=object)[codes]
    assert np.array_equal(finished_codes(codes), np.isin(names, list(FINISHED)))
    assert set(STATUSES) < set(STATUS_NAMES) and "failed" in STATUS_NAMES
    assert all(STATUS_NAMES[STATUS_CODE[name]] == name for name in STATUS_NAMES)


def test_coded_round_trip():
    """Codes and names give back the object column, ``None`` (code -1) included."""
    values = np.array(["b", None, "a", "b", None], dtype=object)
    coded = Coded.encode(values)
    assert coded.names == ("b", "a") and list(coded.codes) == [0, -1, 1, 0, -1]
    assert list(coded.decode()) == list(values)
    assert list(Coded.encode(values, ("a", "b")).codes) == [1, -1, 0, 1, -1]


def test_guard_marks_the_rows_it_turns_non_finite_as_not_finished():
    """guard's answer (the rows not finished) takes non_finite rows as not finished
    without a second look at the statuses: the status table must say so."""
    from vimpact.engine.unpack import guard

    assert "non_finite" not in FINISHED
    names = ["ok", "ok", "time_limit", "normal_only"]
    status = np.array([STATUS_CODE[s] for s in names], dtype=np.int8)
    values = {"e_z": np.array([0.5, np.nan, np.nan, 0.7]),
              "e_x": np.array([0.1, 0.2, np.nan, np.nan])}  # NaN e_x: normal only
    dead = guard(values, status, np.array([True, True, True, False]))
    assert [STATUS_NAMES[c] for c in status] == ["ok", "non_finite", "time_limit",
                                                 "normal_only"]
    assert list(dead) == [False, True, True, False]
    assert np.array_equal(dead, ~finished_codes(status))
    assert np.isnan(values["e_x"][1]) and values["e_z"][3] == 0.7


def _scenes():
    """Scenes that take every branch of unpack: tangential or not, rotation held,
    seed memory, v_c0 = 0, arms."""
    import vimpact as v

    kv = v.Material.kelvin_voigt(nu=0.3, E=5e10, eta=1e5)
    sls = v.Material.standard_solid(nu=0.5, G1=1e9, G2=3e9, eta=4e6)
    return [
        v.Scene(kv, R=0.2, m=10.0, v_z0=10.0, v_x0=5.0),
        v.Scene(kv, R=0.2, m=10.0, v_z0=10.0, tangential="none"),
        v.Scene(kv, R=0.2, m=10.0, v_z0=10.0, v_x0=5.0, omega0=-3.0, rotation=False),
        v.Scene(sls, R=0.01, m=0.03, v_z0=1.0, v_x0=-0.5, tangential_memory="seed"),
        v.Scene(sls, R=0.01, m=0.03, v_z0=1.0, v_x0=0.5, omega0=-50.0),  # v_c0 = 0
        v.Scene(sls, R=0.01, m=0.03, v_z0=1.0, v_x0=2.0, omega0=10.0, mu=0.3),
    ]


def _kernel_rows(rng, n):
    """Kernel rows of every status, many with energy gain, NaN, a short contact, a
    contact wider than the half-space limit or outputs just above 1."""
    from vimpact.kernels import layout
    from vimpact.kernels import status as status_table

    out = np.zeros((n, layout.N_OUT))
    out[:, layout.OUT_VZ_END] = -rng.uniform(0.0, 1.0 + 2e-6, n)
    out[:, layout.OUT_VC_END] = rng.uniform(-1.0, 1.0, n)
    # a gain beyond the passivity slack, or a round-off excess within it
    for col in (layout.OUT_VZ_END, layout.OUT_VC_END):
        above = rng.random(n) < 0.15
        out[above, col] = -(1.0 + rng.choice([1e-5, 5e-7], above.sum()))
    out[:, layout.OUT_T_CONTACT] = 10.0 ** rng.uniform(-1.0, 1.0, n)
    out[:, layout.OUT_U_MAX] = rng.uniform(0.0, 1.0, n)
    out[:, layout.OUT_B_MAX] = 10.0 ** rng.uniform(-1.0, 4.0, n)
    codes = list(status_table.BY_CODE) + [layout.STATUS_ASSUMPTION, 99]
    out[:, layout.OUT_STATUS] = rng.choice(codes, n, p=None)
    out[rng.random(n) < 0.7, layout.OUT_STATUS] = layout.STATUS_OK
    out[:, layout.OUT_STEPS] = rng.integers(0, 10_000, n)
    out[:, layout.OUT_T_GROSS_SLIP] = rng.uniform(0.0, 1.0, n) * out[:, layout.OUT_T_CONTACT]
    out[:, layout.OUT_W_FRICTION] = rng.uniform(0.0, 0.1, n)
    nan = rng.random(n) < 0.05
    out[nan, rng.integers(0, 5, n)[nan]] = np.nan
    return out


def test_unpack_row_is_unpack_of_one_row():
    """simulate()'s scalar unpack gives exactly what the batch unpack gives for the
    same row (every field, every status, refused rows too).

    The batch unpack takes the 400 rows of a scene at once (each row's outputs are its
    own: a batch of one row is one of these rows)."""
    from vimpact.engine.columns import SceneColumns
    from vimpact.engine.result import RESULT_FIELDS
    from vimpact.engine.unpack import unpack, unpack_row

    rng = np.random.default_rng(7)
    statuses = set()
    n = 400
    for scene in _scenes():
        cols = SceneColumns.from_scenes([scene])
        assert cols.valid[0]
        out = _kernel_rows(rng, n)
        euler, steps = np.zeros(n, dtype=bool), np.zeros(n)
        refused_col = np.full(n, None, dtype=object)
        for i in range(n):
            euler[i] = rng.random() < 0.2
            steps[i] = rng.choice([0.0, 0.5, 50.0])
            refused_col[i] = (("too_costly", "a reason") if rng.random() < 0.03 else None)
        want = unpack(SceneColumns.from_scenes([scene] * n), out,
                      Coded.encode(np.full(n, "p", dtype=object)), euler, steps, refused_col)
        for i in range(n):
            got = unpack_row(cols, out[i], "p", bool(euler[i]), float(steps[i]),
                             refused_col[i])
            assert list(got) == list(RESULT_FIELDS)
            for name in RESULT_FIELDS:
                w = want[name][i]
                w = w.item() if hasattr(w, "item") else w
                g = got[name]
                assert type(g) is type(w), (name, g, w)
                assert g == w or (g != g and w != w), (name, g, w, want["status"][0])
            statuses.add(got["status"])
    # the rows above reach the statuses unpack decides itself
    assert {"ok", "unstable", "energy_gain", "not_passive", "unresolved", "half_space",
            "normal_only", "vc0_zero", "non_finite", "too_costly"} <= statuses


def test_unpack_row_where_python_floats_raise():
    """Rows whose arithmetic divides by zero or overflows (Python floats raise where
    NumPy gives inf or NaN): unpack_row still gives exactly what unpack gives."""
    from vimpact.engine.columns import SceneColumns
    from vimpact.engine.result import RESULT_FIELDS
    from vimpact.engine.unpack import unpack, unpack_row
    from vimpact.kernels import layout

    rows = []
    for vz_end, vc_end, t_contact in ((1.0, 0.5, 0.0), (-0.5, 1e200, 2.0), (0.0, 0.0, 0.0),
                                      (1.0, 1.0, 1.0)):
        row = np.zeros(layout.N_OUT)
        row[layout.OUT_VZ_END], row[layout.OUT_VC_END] = vz_end, vc_end
        row[layout.OUT_T_CONTACT], row[layout.OUT_T_GROSS_SLIP] = t_contact, 0.5
        rows.append(row)
    for scene in _scenes():
        cols = SceneColumns.from_scenes([scene])
        for row in rows:
            want = unpack(cols, row[None, :], Coded.encode(np.array(["p"], dtype=object)),
                          np.array([False]), np.array([50.0]), np.full(1, None, dtype=object))
            got = unpack_row(cols, row, "p", False, 50.0, None)
            for name in RESULT_FIELDS:
                w = want[name][0]
                w = w.item() if hasattr(w, "item") else w
                assert type(got[name]) is type(w), (name, got[name], w)
                assert got[name] == w or (got[name] != got[name] and w != w), (name, got, w)


def test_a_whole_batch_dealt_to_the_threads_comes_back_in_row_order():
    """A batch of one path in row order is dealt to the threads (every other row on
    two) and its kernel rows stored back by strides: on an odd number of rows, with
    one and with all threads, each row equals its own impact through ``simulate()``
    (the serial one-row kernel and the scalar unpack), and the invalid rows of a batch
    (not dealt: a scatter) keep their places too."""
    import numba

    import vimpact as v

    rng = np.random.default_rng(11)
    n = 41
    cols = {"nu": rng.uniform(0.0, 0.5, n), "G_inf_Pa": 10 ** rng.uniform(6, 9, n),
            "eta0_Pa_s": 10 ** rng.uniform(0, 4, n), "R_m": rng.uniform(0.01, 0.1, n),
            "m_kg": rng.uniform(1e-3, 1e-2, n), "v_z0_m_s": rng.uniform(0.5, 5.0, n),
            "tangential": np.full(n, "none")}
    broken = {**cols, "nu": np.where(np.arange(n) % 5 == 3, 0.7, cols["nu"])}
    before = numba.get_num_threads()
    frames = []
    try:
        for threads in sorted({1, before}):
            numba.set_num_threads(threads)
            frames += [v.simulate_batch(cols), v.simulate_batch(broken)]
    finally:
        numba.set_num_threads(before)
    for i in range(n):
        scene = v.Scene(v.Material.kelvin_voigt(cols["nu"][i], cols["eta0_Pa_s"][i],
                                                G=cols["G_inf_Pa"][i]),
                        R=cols["R_m"][i], m=cols["m_kg"][i], v_z0=cols["v_z0_m_s"][i],
                        tangential="none", allow_large_contact=True)
        one = v.simulate(scene)
        for k, df in enumerate(frames):
            if k % 2 and i % 5 == 3:
                assert df.status[i] == "invalid"
                continue
            assert (df.e_z[i], df.t_contact[i], df.u_max[i]) == (one.e_z, one.t_contact,
                                                                 one.u_max)
