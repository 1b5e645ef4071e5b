// Contact with rigid bodies (paper Sec. 2.3, Eqs. 23–26; node exclusion of Fig. 1b) as a phase of the
// step. The solver owns one ContactPhase<D> and calls it only when active():
//
//   Solver<D>::advance(dt)
//     sort particles by block (if due)
//     contact.beforeTransfer(step)   serial, before P2G: mark the grid nodes covered by bodies as excluded
//                                    from the WLS fits (Fig. 1b), e.g. through Grid::setExcluded
//     ┌ parallel region (every thread runs each phase; worksharing loops inside) ─────────────────────┐
//     │ p2g → gridUpdate → contact.apply(step) → g2p → gridMusl                                          │
//     └───────────────────────────────────────────────────────────────────────────────────────────────────┘
//     updateStress → moveParticles
//
// apply() runs between gridUpdate and g2p: node lanes `a` hold the updated nodal velocities (Eq. 18),
// `m` the lumped masses; a contact correction of the nodal velocity (Eqs. 23–26) is written into `a`
// and the force it implies (m Δv/Δt) into ContactNodes::force, from which the body reactions are summed.
// apply() is called by EVERY thread of the step's parallel region: use orphaned `#pragma omp for` loops
// (their implicit barrier ends the phase), write each node from one thread only, and keep sums
// deterministic (fixed order, e.g. per-thread partials combined in thread order, or the block colouring
// of Transfer::scatterPass for particle → node scatters). Never throw inside: record failures in
// step.err (the solver throws a SimulationError naming step, particle and quantity after the region).
// Without bodies the step does no contact work at all (active() is false: no call, no allocation).
#pragma once
#include "Transfer.hpp"

namespace mpm {

// Per-node contact state in structure-of-arrays storage, kept outside Node<D> (which is one cache line
// of transfer lanes). Full vectors in 3D. Allocated (resize) only when a scene has rigid bodies.
template <int D>
struct ContactNodes {
	std::vector<Real>    normal[D]; // unit outward normal of the body surface seen by the node [-]
	std::vector<Real>    gap;       // signed distance of the node from that surface (< 0 inside) [m]
	std::vector<Real>    force[D];  // contact force applied to the node in the last step [N]
	std::vector<int32_t> body;      // index of the body in contact, −1 none

	size_t size() const { return gap.size(); }
	void   resize(size_t nNodes)
	{
		for (int a = 0; a < D; ++a) normal[a].assign(nNodes, 0.0), force[a].assign(nNodes, 0.0);
		gap.assign(nNodes, INFINITY);
		body.assign(nNodes, -1);
	}
};

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

template <int D>
class ContactPhase {
public:
	ContactNodes<D> nodes; // per-node contact arrays (sized to the grid by the first body)

	// True when the scene has rigid bodies; false → the solver skips every contact call.
	bool   active() const { return nBodies > 0; }
	size_t bodyCount() const { return nBodies; }

	// Before P2G, serial: exclude the nodes covered by bodies (Fig. 1b) and clear last step's marks.
	void beforeTransfer(ContactStep<D>&) { }
	// Between gridUpdate and g2p, inside the parallel region (see the header comment).
	void apply(ContactStep<D>&) { }

private:
	size_t nBodies = 0; // rigid surfaces registered (RigidSurface.hpp / PtsContact.hpp plug in here)
};

} // namespace mpm
