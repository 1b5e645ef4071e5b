"""WLS shape functions (paper Eqs. 10–15): partition of unity and exact linear reproduction in the
interior, at the grid edge and with excluded nodes; the interior closed form equals the cubic B-spline."""
import numpy as np
import pytest
import yade_mpm as ym


def _check(s, point, expect_general):
    idx, psi, grad, general = s._shapeFunctions(point)
    xi = s._nodePositions()[idx]
    assert general == expect_general
    assert abs(psi.sum() - 1) < 1e-12                           # Σ ψ_i = 1
    np.testing.assert_allclose(psi @ xi, point, atol=1e-12)     # Σ ψ_i x_i = x_p
    np.testing.assert_allclose(grad.sum(axis=0), 0, atol=1e-9)  # Σ ∇ψ_i = 0
    np.testing.assert_allclose(xi.T @ grad, np.eye(len(point)), atol=1e-9)  # Σ x_i ⊗ ∇ψ_i = I
    return idx, psi, grad


@pytest.mark.parametrize("dim", [2, 3])
def test_interior_is_cubic_bspline(dim):
    h = 0.1
    s = ym.make_solver(np.zeros(dim), np.ones(dim), h, margin=0)
    rng = np.random.default_rng(1)
    for _ in range(20):
        p = 0.3 + 0.4 * rng.random(dim)
        idx, psi, grad = _check(s, p, expect_general=False)
        xi = s._nodePositions()[idx]

        def w1(t):
            t = abs(t)
            return 0.5 * t**3 - t**2 + 2 / 3 if t < 1 else ((2 - t) ** 3 / 6 if t < 2 else 0.0)

        w = np.array([np.prod([w1((x[a] - p[a]) / h) for a in range(dim)]) for x in xi])   # Eqs. 12–13
        np.testing.assert_allclose(psi, w, atol=1e-14)
        np.testing.assert_allclose(grad, w[:, None] * 3 / h**2 * (xi - p), atol=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_grid_edge_and_corner(dim):
    s = ym.make_solver(np.zeros(dim), np.ones(dim), 0.1, margin=0)
    for p in [np.full(dim, 0.0), np.full(dim, 0.02), np.r_[0.999, np.full(dim - 1, 0.5)], np.full(dim, 0.97)]:
        idx, psi, _ = _check(s, p, expect_general=True)
        # ghost nodes (outside the grid) carry nothing
        lo, hi = -1e-12, 1 + 1e-12
        xi = s._nodePositions()[idx]
        outside = np.any((xi < lo) | (xi > hi), axis=1)
        assert outside.any() and np.all(psi[outside] == 0)


def test_excluded_nodes():
    s = ym.make_solver((0, 0), (1, 1), 0.1, margin=0)
    p = np.array([0.43, 0.57])
    idx, psi0, _ = _check(s, p, expect_general=False)
    for k in [0, 5, 6, 15]:                  # corner, two inner, far corner of the stencil
        s._setNodeExcluded(int(idx[k]), True)
    _, psi, _ = _check(s, p, expect_general=True)
    assert np.all(psi[[0, 5, 6, 15]] == 0)
    assert not np.allclose(psi, psi0)
