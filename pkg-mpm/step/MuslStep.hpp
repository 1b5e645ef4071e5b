// One explicit WLS-MPM step with MUSL (paper Sec. 2.5, Fig. 2), the whole step in order: gridPhases (1 P2G,
// 2 grid update, 3 contact, 4 G2P, 5 MUSL remap and the kinematic contact's correction of it, in one parallel region)
// and particlePhases (6 stress update, 7 positions, in one loop over blocks); the loops live in the headers they call.
// A table of the phases, their equations and the node arrays each writes: doc/developer/core_notes.md.
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
	bool                 flip;                              // velocityUpdate 'flip': G2P needs the velocities before the step
};

// Wall clock of the phase ends (master thread), for Solver::phase.
inline void stampTime(double& t)
{
#pragma omp master
	t = omp_get_wtime();
}

// Phases 1–5 in one parallel region: every thread calls each phase (worksharing loops, each ending with a barrier)
// and takes the same branches. A phase that recorded a failure (errP2G, cs.err, errG2P) ends the region; the
// caller throws. t[1..4]: wall clock after P2G, grid update, contact, G2P + MUSL remap.
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
		xfer.p2g(mat, in.gravity, in.loadScale, in.viewWrites, in.dt, in.damping == 0 && !in.flip, errP2G); // 1: Eqs. 20–22 (no damping, PIC: p + Δt f fused)
		ex.sumShared(grid, grid.nodes, errP2G, "P2G");                   // + the other processes' partial sums
		if (in.mirrors) grid.mirrors.fold(grid.nodes);                   // symmetry planes: add the reflected images
		stampTime(t[1]);
		if (errP2G.none()) {
			const bool dampLate = in.withContact && in.damping > 0; // damp the net force, contact included
			gridUpdate(grid, in.dt, dampLate ? 0 : in.damping, in.massFloor, dampLate || in.flip); // 2: Eq. 18
			stampTime(t[2]);
			if (in.withContact) {
				contact.apply(cs); // 3: Eqs. 23–26
#pragma omp barrier
				if (dampLate) {
					dampAfterContact(grid, in.dt, in.damping, in.massFloor);
					contact.reproject(cs); // kinematic law: the damped velocities meet the constraints again
				}
			}
			if (in.mirrors) { // nodes beyond a symmetry plane take their partner's reflection
				grid.mirrors.unfold(grid.nodes), grid.mirrors.unfold(grid.vel);
				if (in.flip) grid.mirrors.unfold(grid.vold);
			}
			stampTime(t[3]);
			if (errContact.none()) {
				xfer.g2p(errG2P, in.flip); // 4: Eqs. 6–7 (or FLIP), MUSL momentum (Eq. 16)
				ex.sumShared(grid, grid.mom, errG2P, "G2P"); // + the other processes' partial sums
				if (errG2P.none()) {
					if (in.mirrors) grid.mirrors.fold(grid.mom);
					gridMusl(grid, in.massFloor); // 5: Eq. 17
					if (in.withContact) contact.afterRemap(cs); // kinematic law: the remap keeps the constraints
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
inline ParticleStepStats particlePhases(const Transfer<D>& xfer, const Mat& mat, Real dt, bool flip, ErrorRecord& errStress, ErrorRecord& errMove)
{
	return updateStress(xfer, mat, dt, errStress, [&](uint32_t b, Real& v2max, int& drift) { // 6: Eqs. 7, 27–40
		moveParticles(xfer, dt, b, flip, v2max, drift, errMove);                            // 7
	});
}

} // namespace mpm
