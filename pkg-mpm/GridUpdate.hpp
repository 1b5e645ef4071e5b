// The two grid phases of a step (paper Fig. 2), called by every thread of the solver's parallel region.
#pragma once
#include "Grid.hpp"

namespace mpm {

// Nodal momentum balance with lumped mass (Eq. 18): v_i ← p_i/m_i + Δt f_i/m_i, with Cundall local
// damping f ← f − α|f|sign(v) and the boundary planes (fixMask). Nodes lighter than massFloor carry no
// velocity. Lanes on entry: a = momentum, b = force; on exit: a = updated velocity, b = 0 (collects
// the MUSL momentum next).
// Cundall local damping of one force component f at a node moving at v (before the step).
inline Real cundallDamped(Real f, Real v, Real alpha) { return alpha > 0 && v != 0 ? f - alpha * std::abs(f) * (v > 0 ? 1 : -1) : f; }

// keepOld: lanes b keep the velocity before the step (p_i/m_i) instead of 0, for dampAfterContact.
template <int D>
inline void gridUpdate(Grid<D>& grid, Real dt, Real damping, Real massFloor, bool keepOld = false)
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
				const Real f = cundallDamped(nd.b[a], v, alpha);
				nd.a[a]      = (fix >> a) & 1 ? 0.0 : v + dt * f / nd.m;
				nd.b[a]      = keepOld ? v : 0.0;
			}
		} else {
			for (int a = 0; a < D; ++a) nd.a[a] = nd.b[a] = 0;
		}
	}
}

// Damping of a scene with rigid bodies, after the contact step: the damped force is the node's net force
// m (v_new − v_old)/Δt, contact forces included. Damping the force before contact (gridUpdate) takes
// α|f| off a node whose internal force the contact then balances: next to a held platen the node is at
// rest, sign(v) flips from step to step and the reaction (−Σ contact forces) swung to 0.79–1.41 of the
// section force at α = 0.5. Lanes on entry: a = velocity after contact, b = velocity before the step
// (gridUpdate keepOld); on exit a = damped velocity, b = 0.
template <int D>
inline void dampAfterContact(Grid<D>& grid, Real dt, Real damping, Real massFloor)
{
	auto& nodes = grid.nodes;
#pragma omp for schedule(static)
	for (size_t i = 0; i < nodes.size(); ++i) {
		Node<D>&      nd  = nodes[i];
		const uint8_t fix = grid.fixMask[i];
		if (nd.m > massFloor)
			for (int a = 0; a < D; ++a) {
				const Real v0 = nd.b[a], f = nd.m * (nd.a[a] - v0) / dt;
				nd.a[a]       = (fix >> a) & 1 ? 0.0 : v0 + dt * cundallDamped(f, v0, damping) / nd.m;
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
