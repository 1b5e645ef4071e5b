// Node-lane arithmetic and stencil walks shared by the transfers (Transfer.hpp).
//
// Interior particles (all 4^D stencil nodes active) have ψ_i = w_i and ∇ψ_i = w_i·3/l²·(x_i − x_p)
// (WlsShape.hpp), so a transfer to or from the stencil is a tensor product: forRows visits the 4^(D−1)
// rows along x and the kernels update whole nodes as 8-lane vectors (one cache line, Grid.hpp).
// Particles with a reduced node set (grid edge, excluded nodes) go through forStencil with the full
// WLS ψ_i, ∇ψ_i of fillStencil.
#pragma once
#include "WlsShape.hpp"

namespace mpm {

// Lane vector of a node: m, mw, a…, b… (zero padding in 2D).
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
		for (int j = 0; j < 4; ++j) f(k.base + j * sy, k.w[1][j], &k.d[1][j]);
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
// expanded row by row (the x-layer is the innermost loop).
template <int D>
inline void scatterAffine(Grid<D>& g, const Kernel<D>& k, const NodeLanes& base, const NodeLanes* slope)
{
	auto& nodes = g.nodes;
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

// Interior gather of a nodal vector field u (lanes first..first+D−1): u_p = Σ w_i u_i and
// ∇u_p = Σ u_i ⊗ ∇ψ_i with ∇ψ_i = w_i 3/l² (x_i − x_p) (Eqs. 6–7).
template <int first, int D>
inline void gatherInterior(const Grid<D>& g, const Kernel<D>& k, Real (&u)[D], Real (&G)[D][D])
{
	const auto& nodes = g.nodes;
	NodeLanes   U = {}, Gb[D] = {};
	forRows(g, k, [&](size_t row, Real wr, const Real* dr) {
		NodeLanes r0 = {}, r1 = {};
		for (int i = 0; i < 4; ++i) {
			const NodeLanes& q  = lanes(nodes[row + i]);
			const Real       wx = k.w[0][i];
			r0 += wx * q;
			r1 += (wx * k.d[0][i]) * q;
		}
		U += wr * r0;
		Gb[0] += wr * r1;
		for (int b = 1; b < D; ++b) Gb[b] += (wr * dr[b - 1]) * r0;
	});
	const Real Dinv = 3.0 / (g.spacing * g.spacing);
	for (int a = 0; a < D; ++a) {
		u[a] = U[first + a];
		for (int b = 0; b < D; ++b) G[a][b] = Dinv * Gb[b][first + a];
	}
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
