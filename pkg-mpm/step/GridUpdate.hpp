// The grid update of a step (paper Fig. 2, Eq. 18; the MUSL remap is in MuslStep.hpp), called by every
// thread of the solver's parallel region.
#pragma once
#include "../core/Grid.hpp"

namespace mpm {

// Cundall local damping of one force component f at a node moving at v (before the step).
inline Real cundallDamped(Real f, Real v, Real alpha) { return alpha > 0 && v != 0 ? f - alpha * std::abs(f) * (v > 0 ? 1 : -1) : f; }

// Nodal momentum balance with lumped mass (Eq. 18): v_i ← p_i/m_i + Δt f_i/m_i, with Cundall local
// damping f ← f − α|f|sign(v) and the boundary planes (fixMask). Nodes lighter than massFloor carry no
// velocity. Reads nodes (m, p, f; without damping p holds p + Δt f and f = 0: GridNode.hpp); writes vel; clears mom
// (G2P collects the MUSL momentum next). keepOld: vold ← the velocity before the step (p_i/m_i), for dampAfterContact and FLIP.
template <int D>
inline void gridUpdate(Grid<D>& grid, Real dt, Real damping, Real massFloor, bool keepOld = false)
{
	auto&      nodes = grid.nodes;
	const Real alpha = damping, mf = massFloor;
#pragma omp for schedule(static)
	for (size_t i = 0; i < nodes.size(); ++i) {
		const Node<D>& nd  = nodes[i];
		const uint8_t  fix = grid.fixMask[i];
		NodeVec<D>     vn = {}, vo = {};
		if (nd.m > mf) {
			for (int a = 0; a < D; ++a) {
				const Real v = nd.p[a] / nd.m;
				const Real f = cundallDamped(nd.f[a], v, alpha);
				vn.c[a]      = (fix >> a) & 1 ? 0.0 : v + dt * f / nd.m;
				vo.c[a]      = v;
			}
		}
		grid.vel[i] = vn;
		if (keepOld) grid.vold[i] = vo;
		grid.mom[i] = NodeVec<D> {};
	}
}

// Damping of a scene with rigid bodies, after the contact step: the damped force is the node's net force
// m (v_new − v_old)/Δt, contact forces included (why: doc/developer/core_notes.md). Reads vel (after contact) and
// vold (gridUpdate keepOld); writes vel.
template <int D>
inline void dampAfterContact(Grid<D>& grid, Real dt, Real damping, Real massFloor)
{
	auto& nodes = grid.nodes;
#pragma omp for schedule(static)
	for (size_t i = 0; i < nodes.size(); ++i) {
		const Node<D>& nd  = nodes[i];
		const uint8_t  fix = grid.fixMask[i];
		if (nd.m > massFloor)
			for (int a = 0; a < D; ++a) {
				const Real v0 = grid.vold[i].c[a], f = nd.m * (grid.vel[i].c[a] - v0) / dt;
				grid.vel[i].c[a] = (fix >> a) & 1 ? 0.0 : v0 + dt * cundallDamped(f, v0, damping) / nd.m;
			}
	}
}

} // namespace mpm
