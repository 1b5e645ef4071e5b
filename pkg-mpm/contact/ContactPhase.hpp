// Contact with rigid bodies (paper Sec. 2.3, Eqs. 23–26; node exclusion of Fig. 1b) as a phase of the
// step. The solver owns one ContactPhase<D> and calls it only when active():
//
//   Solver<D>::advance(dt)
//     sort particles by block (if due)
//     contact.beforeTransfer(step)   serial, before P2G: mark the grid nodes covered by bodies as excluded
//                                    from the WLS fits (Fig. 1b), e.g. through Grid::setExcluded
//     ┌ parallel region (every thread runs each phase; worksharing loops inside) ─────────────────────┐
//     │ p2g → gridUpdate → contact.apply(step) → g2p → gridMusl            (MuslStep.hpp: gridPhases)   │
//     └───────────────────────────────────────────────────────────────────────────────────────────────────┘
//     updateStress → moveParticles                                           (MuslStep.hpp: particlePhases)
//
// apply() runs between gridUpdate and g2p: Grid::vel holds the updated nodal velocities (Eq. 18),
// Grid::nodes the lumped masses m (and momentum p, force f of P2G); a contact correction of the nodal
// velocity (Eqs. 23–26) is written into vel and the force applied into ContactNodes::force, from which
// the body reactions are summed.
// apply() is called by EVERY thread of the step's parallel region: use orphaned `#pragma omp for` loops
// (their implicit barrier ends the phase), write each node from one thread only, and keep sums
// deterministic (fixed order, e.g. per-thread partials combined in thread order, or the block colouring
// of Transfer::scatterPass for particle → node scatters). Never throw inside: record failures in
// step.err (the solver throws a SimulationError naming step, particle and quantity after the region).
// Without bodies the step does no contact work at all (active() is false: no call, no allocation).
#pragma once
#include "PtsContact.hpp"
#include "../step/Transfer.hpp"

namespace mpm {

// Everything a contact phase may use during one step.
template <int D>
struct ContactStep {
	Transfer<D>& tr;        // tr.grid (nodes, masks), tr.P (particles), tr.sched (blocks, colours),
	                        // tr.offs + tr.kernelOf / fillStencil (kernels and stencils), tr.scatterPass
	Real         dt;        // Δt of this step [s]
	Real         time;      // simulated time at the start of the step [s]
	Real         massFloor; // nodes lighter than this carry no velocity [kg]
	ErrorRecord& err;       // failures inside the parallel region
};

// The PTS contact (PtsContact.hpp: rigid parts, contact groups, per-node arrays ContactNodes) as the
// solver's contact phase.
template <int D>
class ContactPhase : public PtsContact<D> {
public:
	// Before P2G, serial: world geometry of the bodies, nodes covered by them excluded (Fig. 1b).
	void beforeTransfer(ContactStep<D>& s) { PtsContact<D>::beforeTransfer(s.tr.grid, s.tr.sched); }
	// Between gridUpdate and g2p, inside the parallel region: Eqs. 23–26 and the body reactions.
	void apply(ContactStep<D>& s) { PtsContact<D>::apply(s.tr.grid, s.tr.P, s.tr.sched, s.tr.offs, s.dt, s.massFloor, s.err); }
	// After the late damping (dampAfterContact), inside the region: kinematic groups restore their constraints.
	void reproject(ContactStep<D>& s)
	{
		if (!PtsContact<D>::hasKinematic()) return;
		MPM_ONE_THREAD
		PtsContact<D>::reprojectKinematic(s.tr.grid, s.dt);
		MPM_ONE_THREAD_END
	}
};

} // namespace mpm
