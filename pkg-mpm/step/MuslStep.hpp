// One explicit WLS-MPM step with MUSL (paper Sec. 2.5, Fig. 2), the whole step in order. Solver::advance
// checks Δt, re-sorts the particles when due, marks the nodes covered by rigid bodies (Fig. 1b) and
// calls gridPhases, then particlePhases; the loops live in the headers named on the right.
//
//   phase          what it computes                                             paper          where
//   1 P2G          m_i = Σ η m_p, Σ w m_p, p_i = Σ η m_p h_p(x_i),              Eqs. 16, 20–22 Transfer::p2g
//                  f_i = −Σ V_p σ_p ∇ψ_i + Σ η m_p g + traction
//   2 grid update  v_i = (p_i + Δt f_i)/m_i, local damping, boundary planes     Eq. 18         gridUpdate
//   3 contact      PTS correction of v_i by the rigid bodies, body reactions    Eqs. 23–26     ContactPhase::apply
//   4 G2P          v_p = Σ η_i v_i, C_p = Σ v_i ⊗ ∇ψ_i;                         Eqs. 6–7       Transfer::g2p
//                  MUSL momentum mom_i = Σ_p w m_p h_p(x_i)                     Eq. 16
//   5 MUSL remap   ṽ_i = mom_i / Σ_p w m_p, boundary planes                     Eq. 17         gridMusl (below)
//   6 stress       ∇ṽ_p = Σ ṽ_i ⊗ ∇ψ_i, Δε = sym(∇ṽ_p) Δt, Jaumann rotation,    Eqs. 7, 29,    updateStress,
//                  material update, V_p ← det(I + Δt ∇ṽ_p) V_p                  27–40          Transfer::velocityGradient
//   7 move         x_p ← x_p + Δt v_p, stability and re-sort checks                            moveParticles
//
// Each node array holds one quantity, written by one phase (Grid.hpp, GridNode.hpp):
//   nodes {m, mw, p, f}  P2G (no damping: p + Δt f, f = 0)
//       vel  grid update (+ contact)      mom  G2P      vmusl  MUSL remap
// (gridUpdate also clears mom for G2P: one pass over the nodes.) With symmetry planes, nodal sums are
// folded onto the physical nodes after each scatter and the nodes beyond the planes are filled again
// after each nodal update (MirrorPlanes.hpp). h_p(x) = v_p + C_p (x − x_p): the particle's linear
// velocity field (x̄_p for a cut stencil, WlsShape.hpp).
#pragma once
#include "../contact/PtsContact.hpp"
#include "GridUpdate.hpp"
#include "ParticleUpdate.hpp"
#include <omp.h>

namespace mpm {

// Phase 5, MUSL nodal velocities (Eqs. 16–17): vmusl ← mom / Σ w m, boundary planes again.
template <int D>
inline void gridMusl(Grid<D>& grid, Real massFloor)
{
	auto&      nodes = grid.nodes;
	const Real mf    = massFloor;
#pragma omp for schedule(static)
	for (size_t i = 0; i < nodes.size(); ++i) {
		const uint8_t fix = grid.fixMask[i];
		const Real    inv = nodes[i].mw > mf ? 1.0 / nodes[i].mw : 0.0; // Eq. 17 denominator
		NodeVec<D>    vn  = {};
		for (int a = 0; a < D; ++a) vn.c[a] = (fix >> a) & 1 ? 0.0 : grid.mom[i].c[a] * inv;
		grid.vmusl[i] = vn;
	}
}

// What the phases of one step read besides the state.
template <int D>
struct StepInputs {
	Real                 dt, loadScale, damping, massFloor; // [s], traction ramp factor [-], Cundall α [-], [kg]
	typename Dim<D>::Vec gravity;                           // [m/s²]
	bool                 withContact, mirrors, viewWrites;  // rigid bodies, symmetry planes, state written through views
};

// Wall clock of the phase ends (master thread), for Solver::phase.
inline void stampTime(double& t)
{
#pragma omp master
	t = omp_get_wtime();
}

// Phases 1–5 in one parallel region (the thread team is woken once per step, which matters on shared
// cores): every thread calls each phase, whose worksharing loops end with a barrier, and every thread
// takes the same branches. A phase that recorded a failure (errP2G, errContact, errG2P) ends the region;
// the caller throws. t[1..4]: wall clock after P2G, grid update, contact, G2P + MUSL remap.
// cs.exchange (core/Exchange.hpp) adds the other processes' partial sums of the shared nodes after each scatter.
template <int D, class Contact, class Mat, class X>
inline void gridPhases(Transfer<D>& xfer, Contact& contact, const ContactStep<D, X>& cs, const Mat& mat, const StepInputs<D>& in,
                       ErrorRecord& errP2G, ErrorRecord& errG2P, double (&t)[6])
{
	const X&     ex         = cs.exchange;
	ErrorRecord& errContact = cs.err;
	Grid<D>& grid = xfer.grid;
#pragma omp parallel
	{
		xfer.p2g(mat, in.gravity, in.loadScale, in.viewWrites, in.dt, in.damping == 0, errP2G); // 1: Eqs. 20–22 (no damping: p + Δt f fused)
		ex.sumShared(grid, grid.nodes, errP2G, "P2G");                   // + the other processes' partial sums
		if (in.mirrors) grid.mirrors.fold(grid.nodes);                   // symmetry planes: add the reflected images
		stampTime(t[1]);
		if (errP2G.none()) {
			const bool dampLate = in.withContact && in.damping > 0; // damp the net force, contact included
			gridUpdate(grid, in.dt, dampLate ? 0 : in.damping, in.massFloor, dampLate); // 2: Eq. 18
			stampTime(t[2]);
			if (in.withContact) {
				contact.apply(cs); // 3: Eqs. 23–26
#pragma omp barrier
				if (dampLate) {
					dampAfterContact(grid, in.dt, in.damping, in.massFloor);
					contact.reproject(cs); // kinematic law: the damped velocities meet the constraints again
				}
			}
			if (in.mirrors) grid.mirrors.unfold(grid.nodes), grid.mirrors.unfold(grid.vel); // nodes beyond a symmetry plane take their partner's reflection
			stampTime(t[3]);
			if (errContact.none()) {
				xfer.g2p(errG2P); // 4: Eqs. 6–7, MUSL momentum (Eq. 16)
				ex.sumShared(grid, grid.mom, errG2P, "G2P"); // + the other processes' partial sums
				if (errG2P.none()) {
					if (in.mirrors) grid.mirrors.fold(grid.mom);
					gridMusl(grid, in.massFloor); // 5: Eq. 17
					if (in.mirrors) grid.mirrors.unfold(grid.vmusl);
				}
			}
		}
		stampTime(t[4]);
	}
}

// Phases 6–7 in one parallel loop over blocks: a block's particles move right after its stress update,
// while they are in cache. Failures are recorded in errStress, errMove; the caller throws.
template <int D, class Mat>
inline ParticleStepStats particlePhases(const Transfer<D>& xfer, const Mat& mat, Real dt, ErrorRecord& errStress, ErrorRecord& errMove)
{
	return updateStress(xfer, mat, dt, errStress, [&](uint32_t b, Real& v2max, int& drift) { // 6: Eqs. 7, 27–40
		moveParticles(xfer, dt, b, v2max, drift, errMove);                                  // 7
	});
}

} // namespace mpm
