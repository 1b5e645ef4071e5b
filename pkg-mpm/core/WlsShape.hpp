// WLS shape functions with a linear basis and cubic B-spline weights (paper Sec. 2.2, Eqs. 8–15).
//
// For a particle whose 4^D stencil nodes are all active, the moment matrix of the cubic B-spline is
// exactly M = diag(1, l²/3, …) (partition of unity, zero first moment, second moment 1/3 cell²), so
// ψ_i = w_i and ∇ψ_i = w_i·3/l²·(x_i − x_p). When some stencil node is excluded (ghost, beyond a one-sided
// plane, thin gap, contact: Grid.hpp), M is built from the active nodes only and inverted: the fit stays
// exact for linear fields. Images of symmetry planes are active nodes (closed form).
#pragma once
#include "Grid.hpp"
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace mpm {

template <int D>
struct Stencil {
	static constexpr int N = Dim<D>::nStencil;
	size_t base;       // linear index of stencil node (0,0[,0])
	Real   d[D][4];    // x_i − x_p per axis for the 4 stencil layers [m]
	Real   w[N];       // B-spline weight w_i(x_p), Eq. 12
	Real   psi[N];     // ψ_i(x_p), Eq. 15
	Real   grad[N][D]; // ∇ψ_i(x_p)
	Real   eta[N];     // η_i: non-negative lumping weights of a cut stencil (below; = ψ_i = w_i in the interior)
	Real   dbar[D];    // x̄_p − x_p, x̄_p = Σ η_i x_i the centroid of the lumping weights (0 in the interior)
	bool   general;    // true when M was assembled from a reduced node set

	// Offset of stencil node n from the base along each axis.
	static int along(int n, int a) { return (n >> (2 * a)) & 3; }
};

// Linear-index offsets of the 4^D stencil nodes for a given grid (computed once per grid).
template <int D>
struct StencilOffsets {
	size_t off[Dim<D>::nStencil];
	explicit StencilOffsets(const Grid<D>& g)
	{
		for (int n = 0; n < Dim<D>::nStencil; ++n) {
			size_t k = 0;
			for (int a = 0; a < D; ++a) k += size_t(Stencil<D>::along(n, a)) * g.stride[a];
			off[n] = k;
		}
	}
};

// Per-particle, per-step tensor-product data: the 4 one-dimensional B-spline weights and node offsets
// x_i − x_p along each axis. For an interior particle (all 4^D nodes active) this is all a transfer needs,
// because there ψ_i = w_i = Π_a w1[a][i_a] and ∇ψ_i = w_i·3/l²·(x_i − x_p): the kernels expand the
// products row by row instead of storing 4^D values. `general` marks particles that need the full
// WLS stencil (reduced node set, Eqs. 10–15).
typedef Real Lane4 __attribute__((vector_size(32))); // the 4 stencil layers of one axis
template <int D>
struct Kernel {
	size_t base; // linear index of stencil node (0,0[,0])
	Lane4  w[D]; // one-dimensional cubic B-spline weights, Eq. 13 (vectors: kept in registers)
	Lane4  d[D]; // x_i − x_p per axis for the 4 stencil layers [m]
	bool   general; // some stencil node is excluded (any bit of Grid::excluded): use fillStencil's general path
	bool   inside;  // x is finite and inside the physical grid (false: nothing else is valid)
};

// The grid constants a kernel evaluation reads, copied once per pass into a local (so that stores to the particle
// arrays do not force them to be reloaded and the divisions redone per particle).
template <int D>
struct KernelGeom {
	Real           origin[D], cells[D]; // [m], physical cells per axis
	Real           h, invH, gradFactor;  // l [m], 1/l, 3/l² (interior M⁻¹ gradient factor, ∇ψ_i = w_i 3/l² (x_i − x_p))
	size_t         stride[D];
	size_t         offset; // global index of the grid's first held node (Grid::setWindow)
	const uint8_t* stencilExcl;
	explicit KernelGeom(const Grid<D>& g)
	    : h(g.spacing), invH(1.0 / g.spacing), gradFactor(3.0 / (g.spacing * g.spacing)), offset(g.offset), stencilExcl(g.stencilExcl.data())
	{
		for (int a = 0; a < D; ++a) origin[a] = g.origin[a], cells[a] = g.cells[a], stride[a] = g.stride[a];
	}
};

// checked: x may lie anywhere (k.inside tells); unchecked (G2P and the stress pass of a step whose P2G
// accepted every position, which do not move before the step ends): x lies inside the physical grid.
template <int D, bool checked = true>
inline void computeKernel(const KernelGeom<D>& g, const Real* x, Kernel<D>& k)
{
	const Real h = g.h, invH = g.invH;
	size_t     base     = 0;
	k.inside            = true;
	for (int a = 0; a < D; ++a) {
		Real f = (x[a] - g.origin[a]) * invH;
		if constexpr (checked)
			if (!(f >= 0 && f < g.cells[a])) { // also catches NaN: positions edited through views
				k.inside = false;
				return;
			}
		const int  c = int(f); // f ≥ 0: truncation is the floor
		const Real t = f - c; // in [0,1): distances to the 4 nodes c-1..c+2 are t+1, t, 1-t, 2-t
		// the 4 weights as cubics in t (Horner, one vector): w0 = (1−t)³/6, w1 = t³/2 − t² + 2/3,
		// w2 = −t³/2 + t²/2 + t/2 + 1/6, w3 = t³/6 (Eq. 13); offsets x_i − x_p = (j − 1 − t) l
		typedef Lane4 L4;
		const L4 c3 = { -1.0 / 6, 0.5, -0.5, 1.0 / 6 }, c2 = { 0.5, -1.0, 0.5, 0.0 }, c1 = { -0.5, 0.0, 0.5, 0.0 };
		const L4 c0 = { 1.0 / 6, 2.0 / 3, 1.0 / 6, 0.0 }, jm = { -1.0, 0.0, 1.0, 2.0 };
		k.w[a] = ((c3 * t + c2) * t + c1) * t + c0;
		k.d[a] = (jm - t) * h;
		base += size_t(c - 1 + Grid<D>::ghost) * g.stride[a];
	}
	k.base    = base - g.offset; // local index: a rank's particles reach only its window
	k.general = g.stencilExcl[k.base] != 0; // one load: ghosts near the grid edge, planes, gaps, contact
}

// The fit of a cut stencil whose active nodes do not span a D-simplex (M of Eq. 10 singular: e.g. one row of nodes
// left beside a body, a fragment with most of its stencil excluded). The same weighted least squares written about
// the weights' centroid x̄ = Σ w_i x_i / Σ w_i, with the pseudo-inverse of the centred second moment
// S = Σ w_i (x_i − x̄)(x_i − x̄)ᵀ / Σ w_i (directions with S's eigenvalue below `degenerateSpread` cell² dropped):
//   ψ_i = w_i/Σw (1 + (x_i − x̄)ᵀ S⁺ (x_p − x̄)),   ∇ψ_i = w_i/Σw S⁺ (x_i − x̄).
// It keeps Σ ψ_i = 1 and Σ ∇ψ_i = 0 (a rigid motion gives no strain rate), is exact for fields linear along the
// directions the nodes span and constant across the others, and equals Eq. 15 where M is regular (not used there:
// the bits of regular fits stay those of M⁻¹). False only when no stencil node is active (Σ w = 0).
constexpr Real degenerateSpread = 1e-3; // [cell²] smallest kept eigenvalue of S (a full stencil has 1/3)
template <int D>
inline bool degenerateFit(Stencil<D>& st, Real invH)
{
	constexpr int N = Dim<D>::nStencil;
	using MatD      = Eigen::Matrix<Real, D, D>;
	using VecD      = Eigen::Matrix<Real, D, 1>;
	Real wsum       = 0;
	VecD c          = VecD::Zero(); // x̄ − x_p [cells]
	auto dn         = [&](int n) {
                VecD v;
                for (int a = 0; a < D; ++a) v[a] = st.d[a][Stencil<D>::along(n, a)] * invH;
                return v;
	};
	for (int n = 0; n < N; ++n) wsum += st.w[n], c += st.w[n] * dn(n);
	if (!(wsum > 0)) return false;
	c /= wsum;
	MatD S = MatD::Zero();
	for (int n = 0; n < N; ++n) {
		const VecD r = dn(n) - c;
		S += (st.w[n] / wsum) * r * r.transpose();
	}
	Eigen::SelfAdjointEigenSolver<MatD> es(S);
	MatD Sp = MatD::Zero(); // S⁺ over the kept directions
	for (int k = 0; k < D; ++k)
		if (es.eigenvalues()[k] > degenerateSpread) Sp += es.eigenvectors().col(k) * es.eigenvectors().col(k).transpose() / es.eigenvalues()[k];
	const VecD g0 = Sp * (-c); // S⁺ (x_p − x̄)
	for (int n = 0; n < N; ++n) {
		const VecD r  = dn(n) - c;
		const Real wn = st.w[n] / wsum;
		st.psi[n]     = wn * (1 + r.dot(g0));
		const VecD gr = wn * (Sp * r) * invH;
		for (int a = 0; a < D; ++a) st.grad[n][a] = gr[a];
	}
	return true;
}

// What a pass reports of a particle whose fit fillStencil refused (after "particle id N ").
constexpr const char* noActiveNodeMessage = "has no active grid node in its WLS stencil (every node excluded)";

// Fills st from the kernel data. Returns false only when no stencil node is active (noActiveNodeMessage); a singular
// moment matrix takes degenerateFit.
template <int D>
inline bool fillStencil(const Grid<D>& g, const StencilOffsets<D>& so, const Kernel<D>& k, Stencil<D>& st)
{
	constexpr int N = Dim<D>::nStencil;
	const Real    invH = 1.0 / g.spacing;
	const size_t  base = k.base;
	st.base            = base;
	for (int a = 0; a < D; ++a)
		for (int j = 0; j < 4; ++j) st.d[a][j] = k.d[a][j];
	for (int n = 0; n < N; ++n) {
		Real w = 1;
		for (int a = 0; a < D; ++a) w *= k.w[a][Stencil<D>::along(n, a)];
		st.w[n] = w;
	}
	const bool general = k.general;
	st.general         = general;

	if (!general) { // interior closed form: M⁻¹ = diag(1, 3/l², …)
		const Real s = 3.0 * invH * invH;
		for (int a = 0; a < D; ++a) st.dbar[a] = 0; // Σ w_i (x_i − x_p) = 0 for the full B-spline stencil
		for (int n = 0; n < N; ++n) {
			st.psi[n] = st.eta[n] = st.w[n];
			for (int a = 0; a < D; ++a) st.grad[n][a] = st.w[n] * s * st.d[a][Stencil<D>::along(n, a)];
		}
		return true;
	}

	// General case: moment matrix over active nodes (Eq. 10), basis p = [1, (x_i − x_p)/l] for conditioning.
	using MatP = Eigen::Matrix<Real, D + 1, D + 1>;
	// Scalar code, p_n rebuilt from st.d where needed (faster than a stored basis vector); an excluded node adds w = 0.
	auto basis = [&](int n, Real (&pn)[D + 1]) {
		pn[0] = 1;
		for (int a = 0; a < D; ++a) pn[a + 1] = st.d[a][Stencil<D>::along(n, a)] * invH;
	};
	Real Ms[D + 1][D + 1] = {};
	for (int n = 0; n < N; ++n) {
		const Real w = g.excluded[base + so.off[n]] ? 0.0 : st.w[n];
		st.w[n]      = w;
		Real pn[D + 1];
		basis(n, pn);
		for (int i = 0; i <= D; ++i)
			for (int j = 0; j <= D; ++j) Ms[i][j] += (w * pn[i]) * pn[j]; // Eq. 10; + 0 for an excluded node
	}
	MatP M;
	for (int i = 0; i <= D; ++i)
		for (int j = 0; j <= D; ++j) M(i, j) = Ms[i][j];
	// M is SPD when the active nodes span a D-simplex; its smallest scale is ~1e-2 in cell units.
	Real det = M.determinant();
	if (std::abs(det) > 1e-12) {
		const MatP Minv = M.inverse();
		for (int n = 0; n < N; ++n) { // Eq. 15 at x = x_p and its gradient: q = M⁻¹ p_n
			Real pn[D + 1], q[D + 1];
			basis(n, pn);
			for (int i = 0; i <= D; ++i) {
				q[i] = Minv(i, 0) * pn[0];
				for (int j = 1; j <= D; ++j) q[i] += Minv(i, j) * pn[j];
			}
			st.psi[n] = st.w[n] * q[0];
			for (int a = 0; a < D; ++a) st.grad[n][a] = st.w[n] * q[a + 1] * invH;
		}
	} else if (!degenerateFit(st, invH)) { // no active node at all
		for (int n = 0; n < N; ++n) {
			st.psi[n] = 0;
			for (int a = 0; a < D; ++a) st.grad[n][a] = 0;
		}
		return false;
	}
	// Lumping weights of a cut stencil (mass, momentum, external force; Eq. 20 with positive weights):
	// η_i = ½ (w_i/Σ_active w + ψ⁺_i/Σ_j ψ⁺_j) ≥ 0, ψ⁺ = max(ψ, 0), Σ η = 1; ψ_i, ∇ψ_i keep the fit (Eqs. 15, 21, 7).
	// Why not ψ_i itself (a negative lumped mass next to excluded nodes): doc/developer/core_notes.md.
	Real wsum = 0, psum = 0;
	for (int n = 0; n < N; ++n) wsum += st.w[n], psum += std::max(st.psi[n], Real(0));
	for (int a = 0; a < D; ++a) st.dbar[a] = 0;
	for (int n = 0; n < N; ++n) {
		st.eta[n] = 0.5 * (std::max(st.psi[n], Real(0)) / psum + st.w[n] / wsum);
		for (int a = 0; a < D; ++a) st.dbar[a] += st.eta[n] * st.d[a][Stencil<D>::along(n, a)];
	}
	return true;
}

// Fills st for a particle at x (the caller has checked that x lies inside the physical grid).
template <int D>
inline bool computeStencil(const Grid<D>& g, const StencilOffsets<D>& so, const Real* x, Stencil<D>& st)
{
	Kernel<D> k;
	computeKernel(KernelGeom<D>(g), x, k);
	return k.inside && fillStencil(g, so, k, st);
}

} // namespace mpm
