// The two grid phases of a step (paper Fig. 2), called by every thread of the solver's parallel region.
#pragma once
#include "Grid.hpp"

namespace mpm {

// Nodal momentum balance with lumped mass (Eq. 18): v_i ← p_i/m_i + Δt f_i/m_i, with Cundall local
// damping f ← f − α|f|sign(v) and the boundary planes (fixMask). Nodes lighter than massFloor carry no
// velocity. Lanes on entry: a = momentum, b = force; on exit: a = updated velocity, b = 0 (collects
// the MUSL momentum next).
template <int D>
inline void gridUpdate(Grid<D>& grid, Real dt, Real damping, Real massFloor)
{
	auto&      nodes = grid.nodes;
	const Real alpha = damping, mf = massFloor;
#pragma omp for schedule(static)
	for (size_t i = 0; i < nodes.size(); ++i) {
		Node<D>&      nd  = nodes[i];
		const uint8_t fix = grid.fixMask[i];
		if (nd.m > mf) {
			for (int a = 0; a < D; ++a) {
				const Real v = nd.a[a] / nd.m;
				Real       f = nd.b[a];
				if (alpha > 0 && v != 0) f -= alpha * std::abs(f) * (v > 0 ? 1 : -1);
				nd.a[a] = (fix >> a) & 1 ? 0.0 : v + dt * f / nd.m;
			}
		} else {
			for (int a = 0; a < D; ++a) nd.a[a] = 0;
		}
		for (int a = 0; a < D; ++a) nd.b[a] = 0;
	}
}

// MUSL nodal velocities (Eqs. 16–17): lanes b ← Σ w m h_p(x_i) / Σ w m, boundary planes again.
template <int D>
inline void gridMusl(Grid<D>& grid, Real massFloor)
{
	auto&      nodes = grid.nodes;
	const Real mf    = massFloor;
#pragma omp for schedule(static)
	for (size_t i = 0; i < nodes.size(); ++i) {
		Node<D>&      nd  = nodes[i];
		const uint8_t fix = grid.fixMask[i];
		const Real    inv = nd.mw > mf ? 1.0 / nd.mw : 0.0; // Eq. 17 denominator
		for (int a = 0; a < D; ++a) nd.b[a] = (fix >> a) & 1 ? 0.0 : nd.b[a] * inv;
	}
}

} // namespace mpm
