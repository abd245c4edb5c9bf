"""Cubic Hermite tensor-product interpolation (vimpact.lookup.interpolate).

Checked against things the interpolant does not produce: polynomials it must
reproduce exactly, the convergence order on a smooth function, and
monotonicity of monotone data.
"""

import numpy as np
import pytest

from vimpact.lookup.interpolate import HermiteGrid, derivative_matrix, hermite_slopes
from vimpact.model.validation import InputError


def cubic(x, y, z):
    """A cubic in each variable, with mixed terms."""
    return 0.3 + x**3 - 2.0 * x * y**2 + y**3 * z + z**3 * x**2 - 0.5 * x * y * z


def test_derivative_matrix_is_exact_for_quartics():
    x = np.array([0.0, 0.1, 0.35, 0.4, 0.7, 0.75, 1.0])  # uneven spacing
    f = 1 + 2 * x - x**2 + 3 * x**3 - 4 * x**4
    df = 2 - 2 * x + 9 * x**2 - 16 * x**3
    np.testing.assert_allclose(derivative_matrix(x) @ f, df, rtol=0, atol=1e-11)


def test_reproduces_cubics_exactly_on_an_uneven_3d_grid():
    nu = np.array([0.0, 0.05, 0.2, 0.3, 0.45, 0.5])
    th = np.array([0.2, 0.4, 0.5, 0.9, 1.0])
    q1 = np.array([1e-3, 3e-3, 1e-2, 0.1, 0.2, 1.0, 10.0])
    X, Y, Z = np.meshgrid(nu, th, np.log(q1), indexing="ij")
    # theta_ratio linear here (a table interpolates it in log: LOG_AXES)
    grid = HermiteGrid(["nu", "theta_ratio", "Q1"], [nu, th, q1], {"f": cubic(X, Y, Z)},
                       monotone=False, log_axes=("Q1",))
    rng = np.random.default_rng(3)
    p = [rng.uniform(0, 0.5, 2000), rng.uniform(0.2, 1.0, 2000),
         np.exp(rng.uniform(np.log(1e-3), np.log(10.0), 2000))]
    got = grid(p)["f"]
    np.testing.assert_allclose(got, cubic(p[0], p[1], np.log(p[2])), rtol=0, atol=1e-11)


def test_returns_node_values_at_nodes():
    q1, nu = np.geomspace(0.01, 10, 7), np.linspace(0, 0.5, 4)
    f = np.random.default_rng(0).normal(size=(7, 4))
    grid = HermiteGrid(["Q1", "nu"], [q1, nu], {"f": f})
    Q, N = np.meshgrid(q1, nu, indexing="ij")
    np.testing.assert_allclose(grid([Q, N])["f"], f, rtol=0, atol=1e-14)


def test_converges_at_order_four_on_a_smooth_function():
    """Max error on a fine sample falls by >= 2**3 per halving of the spacing (order >= 3;
    fourth-order slopes give about 2**4), with the monotonicity limiter on."""
    f = lambda u, v: np.sin(1.3 * u) * np.exp(-v) + np.cos(2 * v) * u  # noqa: E731
    rng = np.random.default_rng(1)
    pu, pv = np.exp(rng.uniform(np.log(0.1), np.log(10), 20000)), rng.uniform(0, 0.5, 20000)
    errors = []
    for n in (6, 11, 21, 41):
        q1, nu = np.geomspace(0.1, 10, n), np.linspace(0, 0.5, n)
        U, V = np.meshgrid(np.log(q1), nu, indexing="ij")
        grid = HermiteGrid(["Q1", "nu"], [q1, nu], {"f": f(U, V)})
        errors.append(np.max(np.abs(grid([pu, pv])["f"] - f(np.log(pu), pv))))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all(ratios > 2**3), (errors, ratios)


def test_monotone_data_gives_a_monotone_interpolant_without_overshoot():
    x = np.linspace(0, 1, 12)
    data = np.where(x < 0.45, 0.0, 1.0) + 0.01 * x  # a step: monotone, steep
    x_fine = np.linspace(0, 1, 5001)
    shaped = HermiteGrid(["nu"], [x], {"f": data})([x_fine])["f"]
    assert np.all(np.diff(shaped) >= -1e-15)
    assert shaped.min() >= data.min() - 1e-15 and shaped.max() <= data.max() + 1e-15
    # the check means something: the unlimited interpolant overshoots this data
    free = HermiteGrid(["nu"], [x], {"f": data}, monotone=False)([x_fine])["f"]
    assert free.max() > data.max() + 1e-3 and np.any(np.diff(free) < 0)


def test_limiter_spares_a_smooth_maximum():
    """Slopes beside a smooth interior maximum keep their accuracy (order as without
    limiter): the filter acts only where the data is monotone around a node."""
    x = np.linspace(0, 1, 15)
    f = np.sin(np.pi * x * 0.93)
    limited = hermite_slopes(x, f, monotone=True)
    free = hermite_slopes(x, f, monotone=False)
    exact = 0.93 * np.pi * np.cos(0.93 * np.pi * x)
    peak = np.argmax(f)
    near = slice(peak - 1, peak + 2)
    np.testing.assert_allclose(limited[near], free[near], rtol=0, atol=0)
    # and nowhere does it make a slope worse than the unlimited fourth-order one here
    assert np.max(np.abs(limited - exact)) <= np.max(np.abs(free - exact))


def test_failed_node_spoils_only_its_cells():
    q1, nu = np.geomspace(0.01, 10, 7), np.linspace(0, 0.5, 5)
    f = np.add.outer(np.log(q1), nu)
    f[3, 2] = np.nan
    grid = HermiteGrid(["Q1", "nu"], [q1, nu], {"f": f})
    assert np.isnan(grid([np.array([0.2]), np.array([0.3])])["f"][0])  # a touching cell
    far = grid([np.array([0.012, 9.0, q1[3], 0.05]), np.array([0.1, 0.45, 0.0, 0.25])])["f"]
    assert np.all(np.isfinite(far))


def test_extrapolates_linearly_with_the_end_slope():
    q1 = np.geomspace(0.01, 10, 7)
    f = 2.0 * np.log(q1) + 1.0  # linear in log Q1: the slope is exact
    grid = HermiteGrid(["Q1"], [q1], {"f": f})
    got = grid([np.array([1e-3, 100.0])], extrapolate=True)["f"]
    np.testing.assert_allclose(got, 2.0 * np.log([1e-3, 100.0]) + 1.0, rtol=1e-12)
    with pytest.raises(InputError, match=r"Q1 = 100 is outside .*Q1 in \[0\.01, 10\]"):
        grid([np.array([100.0])])


def test_log_axis_refuses_zero_nodes():
    with pytest.raises(InputError, match="Q2 nodes .* log Q2 axis"):
        HermiteGrid(["Q2"], [np.array([0.0, 1.0, 2.0])], {"f": np.ones(3)})


@pytest.mark.parametrize("d", [1, 2, 3, 4])
def test_numba_kernel_equals_the_numpy_reference(d):
    """The numba kernel (default backend) and the NumPy evaluation are two codes for one
    interpolant: equal to 1e-12 at random points, at nodes, beyond the ends (extrapolated),
    with NaN at the same points around a failed node."""
    rng = np.random.default_rng(10 + d)
    names = ["Q1", "nu", "Q2", "theta_ratio"][:d]
    nodes = [np.geomspace(1e-3, 10.0, 9), np.linspace(0.0, 0.5, 6), np.geomspace(0.01, 100, 5),
             np.array([0.2, 0.3, 0.4, 0.55, 0.6667])][:d]
    mesh = np.meshgrid(*[np.log(n) if a in ("Q1", "Q2") else n for a, n in zip(names, nodes)],
                       indexing="ij")
    smooth = sum(np.sin(0.7 * (k + 1) * m + k) for k, m in enumerate(mesh))
    values = {"e_z": 0.5 + 0.1 * smooth, "beta_x": np.tanh(smooth) * np.exp(-mesh[0] ** 2 / 20)}
    values["beta_x"][(2,) * d] = np.nan  # a failed node
    grid = HermiteGrid(names, nodes, values)
    n = 3000
    inside = [np.exp(rng.uniform(np.log(x[0]), np.log(x[-1]), n)) if a in ("Q1", "Q2")
              else rng.uniform(x[0], x[-1], n) for a, x in zip(names, nodes)]
    for k, x in enumerate(nodes):  # some points on nodes of each axis
        inside[k][k * 50:(k + 1) * 50] = rng.choice(x, 50)
    beyond = [np.where(rng.random(n) < 0.5, p, np.where(rng.random(n) < 0.5, x[0] * 0.7,
                                                        x[-1] * 1.3 + 0.1))
              for p, x in zip(inside, nodes)]
    for pts, extrapolate in ((inside, False), (inside, True), (beyond, True)):
        fast = grid(pts, extrapolate, backend="numba")
        ref = grid(pts, extrapolate, backend="numpy")
        for name in values:
            assert np.array_equal(np.isnan(fast[name]), np.isnan(ref[name]))
            np.testing.assert_allclose(fast[name], ref[name], rtol=0, atol=1e-12, equal_nan=True)
        assert np.isnan(ref["e_z"]).any() and np.isfinite(ref["e_z"]).sum() > n // 2


def test_unknown_backend_is_refused():
    grid = HermiteGrid(["nu"], [np.linspace(0, 0.5, 3)], {"f": np.ones(3)})
    with pytest.raises(InputError, match="backend = 'c' is not allowed.*numba, numpy"):
        grid([np.array([0.1])], backend="c")
