// Node-lane arithmetic and stencil walks shared by the transfers (Transfer.hpp). An interior particle (ψ_i = w_i,
// ∇ψ_i = w_i·3/l²·(x_i − x_p), WlsShape.hpp) is a tensor product: forRows visits the 4^(D−1) rows along x and the
// kernels update whole nodes as lane vectors; a particle with a reduced node set goes through forStencil.
#pragma once
#include "WlsShape.hpp"
#include <immintrin.h>

namespace mpm {

typedef Real Lane4Mem __attribute__((vector_size(32))); // 4 lanes of a node in memory

// Lane vector of a node: m, mw, momentum…, force… (zero padding in 2D).
template <int D>
inline NodeLanes nodeLanes(Real m, Real mw, const Real (&a)[D], const Real (&b)[D])
{
	if constexpr (D == 2) return NodeLanes { m, mw, a[0], a[1], b[0], b[1], 0, 0 };
	else return NodeLanes { m, mw, a[0], a[1], a[2], b[0], b[1], b[2] };
}

// Visits the 4^(D−1) stencil rows along x of an interior kernel: f(linear index of the row's first
// node, product of the row's weights along y[, z], its offsets (x_i − x_p) along y[, z]).
template <int D, class F>
inline void forRows(const Grid<D>& g, const Kernel<D>& k, F&& f)
{
	const size_t sy = g.stride[1];
	if constexpr (D == 2) {
		for (int j = 0; j < 4; ++j) {
			const Real dr[1] = { k.d[1][j] };
			f(k.base + j * sy, k.w[1][j], dr);
		}
	} else {
		const size_t sz = g.stride[2];
		for (int l = 0; l < 4; ++l)
			for (int j = 0; j < 4; ++j) {
				const Real dr[2] = { k.d[1][j], k.d[2][l] };
				f(k.base + l * sz + j * sy, k.w[1][j] * k.w[2][l], dr);
			}
	}
}

// Interior scatter of an affine field: node i of the stencil receives w_i (base + Σ_b slope_b (x_i − x_p)_b),
// expanded row by row (the x-layer is the innermost loop). low4 (2D, fused P2G): only lanes 0–3 (m, mw,
// p + Δt f) are non-zero, so the row is updated as 4-lane vectors.
template <int D, bool low4 = false>
inline void scatterAffine(Grid<D>& g, const Kernel<D>& k, const NodeLanes& base, const NodeLanes* slope)
{
	auto& nodes = g.nodes;
	if constexpr (low4 && D == 2) {
		const Lane4 b0 = __builtin_shufflevector(base, base, 0, 1, 2, 3), s0 = __builtin_shufflevector(slope[0], slope[0], 0, 1, 2, 3),
		            s1 = __builtin_shufflevector(slope[1], slope[1], 0, 1, 2, 3);
		const Lane4 wd = k.w[0] * k.d[0];
		forRows(g, k, [&](size_t row, Real wr, const Real* dr) {
			const Lane4 R = (b0 + s1 * dr[0]) * wr, S = s0 * wr;
			for (int i = 0; i < 4; ++i) *reinterpret_cast<Lane4Mem*>(&nodes[row + i]) += k.w[0][i] * R + wd[i] * S;
		});
		return;
	}
	forRows(g, k, [&](size_t row, Real wr, const Real* dr) {
		NodeLanes R = base;
		for (int b = 1; b < D; ++b) R += slope[b] * dr[b - 1];
		R *= wr;
		const NodeLanes S = slope[0] * wr;
		for (int i = 0; i < 4; ++i) {
			const Real wx = k.w[0][i];
			lanes(nodes[row + i]) += wx * R + (wx * k.d[0][i]) * S;
		}
	});
}

// ---- packed nodal vector fields (NodeVec: velocity, MUSL momentum, MUSL velocity) ----
// The 4 nodes of a stencil row along x hold 4·S contiguous values (S = 2 in 2D, 4 in 3D): one or two
// 8-lane vectors. A gather sums the rows first (weights along y[, z]) and the 4 nodes along x last (lanes);
// a scatter adds a precomputed per-node pattern to each row: a few vector operations per row, not per node.
typedef Real RowLanes __attribute__((vector_size(64), aligned(8))); // unaligned 8-lane view (aliases doubles only)
template <int D>
struct PackedRow {
	static constexpr int S = NodeVec<D>::S, R = 4 * S / 8; // values per node, lane vectors per row
	RowLanes             wx[R], wxd[R];                    // w_i and w_i (x_i − x_p) of node i = lane / S
	typedef Real L4 __attribute__((vector_size(32)));
	typedef Real L2 __attribute__((vector_size(16)));
	explicit PackedRow(const Kernel<D>& k)
	{
		const L4 w = k.w[0], wd = w * k.d[0];
		if constexpr (S == 2) {
			wx[0] = __builtin_shufflevector(w, w, 0, 0, 1, 1, 2, 2, 3, 3), wxd[0] = __builtin_shufflevector(wd, wd, 0, 0, 1, 1, 2, 2, 3, 3);
		} else {
			wx[0] = __builtin_shufflevector(w, w, 0, 0, 0, 0, 1, 1, 1, 1), wxd[0] = __builtin_shufflevector(wd, wd, 0, 0, 0, 0, 1, 1, 1, 1);
			wx[1] = __builtin_shufflevector(w, w, 2, 2, 2, 2, 3, 3, 3, 3), wxd[1] = __builtin_shufflevector(wd, wd, 2, 2, 2, 2, 3, 3, 3, 3);
		}
	}
	// A node vector repeated in every node slot of a row (padding lanes 0).
	static RowLanes spread(const Real* v)
	{
#ifdef __AVX512F__ // one broadcast from registers
		if constexpr (S == 2) return RowLanes(_mm512_broadcast_f64x2(_mm_set_pd(v[1], v[0])));
		else return RowLanes(_mm512_broadcast_f64x4(_mm256_set_pd(0.0, v[2], v[1], v[0])));
#endif
		if constexpr (S == 2) {
			const L2 q = { v[0], v[1] };
			return __builtin_shufflevector(q, q, 0, 1, 0, 1, 0, 1, 0, 1);
		} else {
			const L4 q = { v[0], v[1], v[2], 0.0 };
			return __builtin_shufflevector(q, q, 0, 1, 2, 3, 0, 1, 2, 3);
		}
	}
	// Σ over the node slots of R lane vectors: out[a] = Σ_r Σ_i x[r][i S + a].
	static void sumNodes(const RowLanes (&x)[R], Real* out)
	{
		RowLanes t = x[0];
		if constexpr (R == 2) t += x[1];
		const L4 h = __builtin_shufflevector(t, t, 0, 1, 2, 3) + __builtin_shufflevector(t, t, 4, 5, 6, 7);
		if constexpr (S == 2) {
			const L2 q = __builtin_shufflevector(h, h, 0, 1) + __builtin_shufflevector(h, h, 2, 3);
			out[0] = q[0], out[1] = q[1];
		} else {
			for (int a = 0; a < D; ++a) out[a] = h[a];
		}
	}
};

// Interior gather of a packed nodal vector field u: u_p = Σ w_i u_i and ∇u_p = Σ u_i ⊗ ∇ψ_i with
// ∇ψ_i = w_i 3/l² (x_i − x_p) (Eqs. 6–7); gradFactor = 3/l² (KernelGeom).
template <int D>
inline void gatherPacked(const Grid<D>& g, const std::vector<NodeVec<D>>& field, const Kernel<D>& k, Real gradFactor, Real (&u)[D], Real (&G)[D][D])
{
	using PR          = PackedRow<D>;
	constexpr int R   = PR::R;
	const Real*   f   = field[0].c;
	RowLanes      T[R] = {}, U[D - 1][R] = {}; // Σ_rows w_r row, Σ_rows w_r (x − x_p)_b row
	forRows(g, k, [&](size_t row, Real wr, const Real* dr) {
		const RowLanes* q = reinterpret_cast<const RowLanes*>(f + row * PR::S);
		for (int r = 0; r < R; ++r) {
			const RowLanes x = q[r];
			T[r] += wr * x;
			for (int b = 0; b < D - 1; ++b) U[b][r] += (wr * dr[b]) * x;
		}
	});
	const PR   pr(k);
	RowLanes   V[R], GX[R], GY[D - 1][R];
	for (int r = 0; r < R; ++r) {
		V[r] = pr.wx[r] * T[r], GX[r] = pr.wxd[r] * T[r];
		for (int b = 0; b < D - 1; ++b) GY[b][r] = pr.wx[r] * U[b][r];
	}
	Real gb[D][D];
	PR::sumNodes(V, u);
	PR::sumNodes(GX, gb[0]);
	for (int b = 0; b < D - 1; ++b) PR::sumNodes(GY[b], gb[b + 1]);
	for (int a = 0; a < D; ++a)
		for (int b = 0; b < D; ++b) G[a][b] = gradFactor * gb[b][a];
}

// Interior scatter of an affine nodal vector field into a packed array: node i of the stencil receives
// w_i (base + Σ_b slope_b (x_i − x_p)_b), slope_b = column b.
template <int D>
inline void scatterPacked(const Grid<D>& g, std::vector<NodeVec<D>>& field, const Kernel<D>& k, const Real (&base)[D], const Real (&slope)[D][D])
{
	using PR        = PackedRow<D>;
	constexpr int R = PR::R;
	const PR      pr(k);
	Real          col[D];
	RowLanes      A[R], B[D - 1][R];
	for (int a = 0; a < D; ++a) col[a] = slope[a][0];
	const RowLanes b0 = PR::spread(base), s0 = PR::spread(col);
	for (int r = 0; r < R; ++r) A[r] = pr.wx[r] * b0 + pr.wxd[r] * s0;
	for (int b = 1; b < D; ++b) {
		for (int a = 0; a < D; ++a) col[a] = slope[a][b];
		const RowLanes sb = PR::spread(col);
		for (int r = 0; r < R; ++r) B[b - 1][r] = pr.wx[r] * sb;
	}
	Real* f = field[0].c;
	forRows(g, k, [&](size_t row, Real wr, const Real* dr) {
		RowLanes* q = reinterpret_cast<RowLanes*>(f + row * PR::S);
		for (int r = 0; r < R; ++r) {
			RowLanes x = wr * A[r];
			for (int b = 0; b < D - 1; ++b) x += (wr * dr[b]) * B[b][r];
			q[r] += x;
		}
	});
}

// Visits the 4^D nodes of a general WLS stencil: f(node, n, dx) with dx = x_i − x_p [m];
// st.psi[n], st.grad[n], st.w[n] are the node's ψ_i, ∇ψ_i, w_i.
template <int D, class NodeT, class F>
inline void forStencil(NodeT* nodes, const StencilOffsets<D>& offs, const Stencil<D>& st, F&& f)
{
	for (int n = 0; n < Dim<D>::nStencil; ++n) {
		Real dx[D];
		for (int a = 0; a < D; ++a) dx[a] = st.d[a][Stencil<D>::along(n, a)];
		f(nodes[st.base + offs.off[n]], n, dx);
	}
}

} // namespace mpm
