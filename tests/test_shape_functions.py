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


@pytest.mark.parametrize("dim", [2, 3])
def test_nodes_that_do_not_span_the_space_keep_a_fit(dim):
    # Active nodes in one row (2D) or one plane (3D) leave the moment matrix of Eq. 10 singular (a fragment whose
    # stencil lies mostly in a body). The fit about the weights' centroid with the pseudo-inverse of its second moment
    # (WlsShape.hpp degenerateFit) keeps Σ ψ = 1 and Σ ∇ψ = 0, reproduces x along the nodes, and is constant across.
    h = 0.1
    s = ym.make_solver(np.zeros(dim), np.ones(dim), h, margin=0)
    p = np.r_[0.53, np.full(dim - 1, 0.47)]
    idx, _, _, _ = s._shapeFunctions(p)
    xi = s._nodePositions()[idx]
    keep = np.isclose(xi[:, -1], xi[:, -1].min())          # the lowest layer along the last axis (0.3)
    for i in idx[~keep]:
        s._setNodeExcluded(int(i), True)
    idx2, psi, grad, general = s._shapeFunctions(p)
    assert general and np.array_equal(idx2, idx) and np.all(psi[~keep] == 0)
    assert abs(psi.sum() - 1) < 1e-12
    np.testing.assert_allclose(psi @ xi, np.r_[p[:-1], 0.3], atol=1e-12)     # along: x_p; across: the layer's value
    np.testing.assert_allclose(grad.sum(axis=0), 0, atol=1e-9)
    along = np.eye(dim)
    along[-1, -1] = 0
    np.testing.assert_allclose(xi.T @ grad, along, atol=1e-9)               # ∂x/∂x = 1 along the layer, 0 across
    one = idx[keep][0]                                                        # a single node left: it carries all
    for i in idx[keep][1:]:
        s._setNodeExcluded(int(i), True)
    _, psi, grad, _ = s._shapeFunctions(p)
    assert psi[idx == one] == 1 and np.all(psi[idx != one] == 0) and np.all(grad == 0)
    s._setNodeExcluded(int(one), True)                                        # none left: a clear error
    with pytest.raises(ym.MpmSimulationError, match="no active grid node"):
        s._shapeFunctions(p)


def test_a_block_whose_fits_are_degenerate_keeps_running():
    # A block with every node excluded but one row under it (each particle's fit degenerate) steps on: it moves as
    # the row's nodes let it, with no strain rate across, instead of stopping the run.
    s = ym.make_solver((0, 0), (1, 1), 0.1, margin=0)
    ym.add_region(s, ym.ElasticMat(density=2500, young=1e9, poisson=0.25), (0.4, 0.4), (0.6, 0.6), ppc=2)
    xn = s._nodePositions()
    for i in np.flatnonzero(~np.isclose(xn[:, 1], 0.4)):
        try:
            s._setNodeExcluded(int(i), True)
        except ValueError:                                   # a ghost node: excluded already
            pass
    s.view("v0")[:] = 1.0                                     # a rigid motion along the row
    s.run(5)
    assert s.steps == 5
    np.testing.assert_allclose(ym.get(s, "vel")[:, 0], 1.0, rtol=1e-9)
    assert np.abs(ym.get(s, "stress")).max() < 1e-6
