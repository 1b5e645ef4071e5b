// The per-step geometry of the PTS contact (paper Sec. 2.3, Fig. 1b), shared by both contact laws: before P2G
// each enabled group's surface is placed from its parts' poses, the grid nodes a body covers are excluded from
// the WLS fits, and the particle blocks and the node box near the body are found; detectionDistance is the d0
// of Eq. 23 of each particle.
#pragma once
#include "../core/GridBoxes.hpp"
#include "../core/WlsShape.hpp"
#include "ContactGroups.hpp"

namespace mpm {

// What the contact phase reads during one step. X: the exchange policy of the step (core/Exchange.hpp).
template <int D, class X>
struct ContactStep {
	Grid<D>&                 grid;      // nodes, masks, velocities after the grid update (Eq. 18)
	const Particles<D>&      P;
	const BlockSchedule<D>&  sched;     // blocks and colours of the particle pass
	const StencilOffsets<D>& offs;
	Real                     dt;        // Δt of this step [s]
	Real                     massFloor; // nodes lighter than this carry no velocity [kg]
	ErrorRecord&             err;       // failures inside the parallel region (the solver throws after it)
	const X&                 exchange;
};

// Per-node contact arrays in structure-of-arrays storage, kept outside Node<D> (one cache line of transfer
// lanes). Allocated only when a scene has rigid bodies.
template <int D>
struct ContactNodes {
	std::vector<Real> fn[D];    // normal force f_nor (Eq. 23) of the group being processed [N]
	std::vector<Real> force[D]; // total contact force applied to the node by that group in the last step [N]
	std::vector<Real> load;     // normal load share N_i = Σ_p ŵ_i ‖f_p‖ for the Coulomb limit [N]
	std::vector<Real> area;     // contact area A_i = Σ_p ŵ_i a_p [m²] (2D: m per m)
	size_t            size() const { return area.size(); }
	void              resize(size_t n)
	{
		for (int a = 0; a < D; ++a) fn[a].assign(n, 0), force[a].assign(n, 0);
		load.assign(n, 0), area.assign(n, 0);
	}
};

// A body's velocity change of the step, Δq = (Δv, Δω).
template <int D>
struct BodyMotion {
	using Vec   = typename Dim<D>::Vec;
	Vec       v = Vec::Zero();
	SpinOf<D> w = SpinOf<D>::Zero();
	Vec       at(const Vec& r) const { return v + crossSpin<D>(w, r); }
};

// One group's share of the step (beforeTransfer).
template <int D>
struct GroupWork {
	using IVec   = typename Dim<D>::IVec;
	bool skip    = true;
	bool movable = false; // a part of the group is free (finite mass or inertia)
	IVec blo, bhi;        // block coordinate range of the particle pass
	IVec nlo, nhi;        // stored node coordinate range of the node pass
	Real reach = 0;       // detection margin outside the surface [m]
};

template <int D>
class ContactDetection : public ContactGroups<D> {
public:
	using Vec   = typename Dim<D>::Vec;
	using IVec  = typename Dim<D>::IVec;
	using Boxes = GridBoxes<D>;
	using ContactGroups<D>::parts;
	using ContactGroups<D>::groups;

	ContactNodes<D>            nodeArr; // per-node contact arrays (sized to the grid by the first step with bodies)
	std::vector<GroupWork<D>>  work;    // per group: its share of this step
	std::vector<BodyMotion<D>> dq;      // per part: the body's velocity change of the step (set by the laws)

	// Before P2G, serial: world geometry, reactions reset, covered nodes excluded (Fig. 1b), per-group ranges.
	template <class X>
	void beforeTransfer(const ContactStep<D, X>& s)
	{
		Grid<D>& grid = s.grid;
		if (nodeArr.size() != grid.size()) nodeArr.resize(grid.size()), marked.reserve(4096);
		work.resize(groups.size());
		dq.resize(parts.size());
		for (size_t gi : marked) // global indices: the grid's window may have moved since (MPI, Grid::setWindow)
			if (gi >= grid.offset && gi - grid.offset < grid.size()) grid.setBits(gi - grid.offset, ExContact, false);
		marked.clear();
		for (auto& q : parts) q.force.setZero(), q.torque.setZero();
		const Real l    = grid.spacing;
		const Real band = (2 * std::sqrt(Real(D)) + 0.5) * l; // deepest node a particle outside the body can reach
		for (size_t gi = 0; gi < groups.size(); ++gi) {
			auto& g  = groups[gi];
			auto& wk = work[gi];
			if (!g.enabled) {
				wk.skip = true;
				continue;
			}
			wk.movable = false;
			for (int p : g.parts) wk.movable = wk.movable || parts[p].movable();
			if (g.params.initialD0 && !g.d0Captured)
				throw InputError("contact group " + std::to_string(gi) + ": d0 = 'initial' needs captureInitialD0 at registration, before the first step");
			g.update(parts);
			Real reach = (g.params.autoD0 ? 1.5 * l : g.params.d0 + l); // detection margin outside the surface
			if (!g.d0Initial.empty()) reach = std::max(reach, g.d0InitialMax + l);
			Vec lo, hi;
			g.bounds(0, band, lo, hi); // nodes covered by the body (within `band` of the surface)
			IVec nlo, nhi;
			if (Boxes::nodeRange(grid, lo, hi, nlo, nhi))
				Boxes::forNodes(grid, nlo, nhi, [&](size_t i) {
					if (grid.excluded[i] & ExContact) return;
					Real d = g.query(grid.position(i)).d;
					if (d < 0 && d > -band) {
						grid.setBits(i, ExContact, true);
						marked.push_back(i + grid.offset);
					}
				});
			// particles that may touch, and the nodes their stencils reach; a distributed run decides from the
			// geometry alone (every process takes part in the group's sums, with or without particles near it)
			g.bounds(reach, band, lo, hi);
			const bool near = s.exchange.distributed() ? Boxes::blockBox(grid, s.sched, lo, hi, wk.blo, wk.bhi)
			                                           : Boxes::blockRange(grid, s.sched, lo, hi, wk.blo, wk.bhi);
			Vec slo = lo - Vec::Constant(2 * l), shi = hi + Vec::Constant(2 * l);
			wk.skip  = !near || !Boxes::nodeRange(grid, slo, shi, wk.nlo, wk.nhi);
			wk.reach = reach;
		}
	}

	// d0 of particle p (edge e_p): ½ e_p (autoD0) or the fixed d0, or for d0 = "initial" the first layer's d_p(0).
	static Real detectionDistance(const RigidGroup<D>& g, const Particles<D>& P, uint32_t p, Real e)
	{
		const size_t id = size_t(P.id[p]);
		if (id < g.d0Initial.size() && g.d0Initial[id] == g.d0Initial[id]) return g.d0Initial[id]; // d0_p = d_p(0)
		return g.params.autoD0 ? 0.5 * e : g.params.d0;
	}

private:
	std::vector<size_t> marked; // nodes carrying the contact exclusion bit (global indices)
};

} // namespace mpm
