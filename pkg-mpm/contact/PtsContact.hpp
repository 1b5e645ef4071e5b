// Particle-to-surface (PTS) frictional contact between MPM particles and rigid surfaces (paper Sec. 2.3,
// Eqs. 23–26; Wang & Chan 2014, Nakamura et al. 2021). Per step, for each contact group:
//
//   beforeTransfer   world geometry from the parts' poses; grid nodes covered by a body are marked
//                    inactive (Grid contact bit, Fig. 1b), so particles near a body use WLS shape
//                    functions fitted over the active nodes only.
//   apply            (after gridUpdate, before g2p)
//     1. particle pass: particles with d_p − d0 < 0 get the normal penalty force
//        f_p = −(1 − χ) κ_p (d_p − d0) n_p, κ_p = 2 m_p/Δt² (Eq. 23), spread to the nodes with ψ_i;
//        the node's share of the normal load N_i = Σ_p ŵ_i ‖f_p‖ and contact area A_i = Σ_p ŵ_i a_p
//        (a_p = V_p^{(D−1)/D}, the particle's face) are spread with the non-negative B-spline weights
//        normalised over the active nodes, ŵ_i = w_i / Σ_active w;
//     2. node pass: relative velocity with the rigid body at the node, ṽ_i = v_i − (v + ω × (x_i − c))
//        (Eq. 26), tangential part (Eq. 25), stick force f_stick = −m_i ṽ_tan/Δt, Coulomb limit
//        μ N_i + A_i c (Eq. 24): stick below, slip at the limit; v_i += Δt (f_nor + f_tan)/m_i;
//        for a free body ṽ_tan is taken against the body's motion after the step (bodyResponse, below);
//     3. reaction: the part owning the surface point nearest each node receives −(f_nor + f_tan) and
//        its moment about the part's centre, summed in node order (exactly the opposite of what the
//        grid received).
//
// N_i instead of ‖f_nor,i‖ in the limit: next to excluded nodes the WLS ψ_i are partly negative (a fit
// over two node rows extrapolates), so Σ_i ‖Σ_p ψ_i f_p‖ exceeds the total normal force by up to a
// factor 3 and the friction with it (measured: a block on a 30° incline with μ = 0.3 slid with 22 % too
// little acceleration). Σ_i N_i is exactly the total normal force, so the body-level limit is μ N.
// A_i: the paper takes A = l (2D) or the cell face area (3D) per contact node. With WLS over the active
// nodes the contact of one surface layer of particles spreads over two or three node rows, so a constant
// A per node would multiply the cohesive capacity by that (grid-offset dependent) row count; A_i as
// defined above sums to l (2D) / l² (3D) per node column of a flat surface, i.e. the paper's value,
// and Σ_i A_i is the contact area whatever the offset.
//
// Stick step of a free body (step 2; Eq. 24 with the body's mass). f_stick = −m_i ṽ_tan/Δt stops the node
// relative to a body that does not move. A free body receives −Σ_j f_j from its contact nodes j (f_nor,j ≠ 0):
// for a uniform slip ṽ and mass M its velocity changes by S ṽ/M (S = Σ_j m_j), so a body lighter than its
// contact nodes overshoots every step (the tunnel's flaw filler, 0.28 kg/m against ~0.8 kg/m of nodes,
// reversed its slip 199 times in 200 steps). Instead every node sticks to the body's motion after the step,
// q + Δq (q = (v, ω); the body's velocity at x_j is J_j q = v + ω × r_j, r_j = x_j − c; P_j = 1 − n_j n_jᵀ):
//     f_stick,j = −m_j P_j (ṽ_j − J_j Δq)/Δt,
// where Δq is what the reactions −Σ_j f_j do to the body, (M, I) Δq = Σ_j m_j J_jᵀ P_j (ṽ_j − J_j Δq), i.e.
//     (1 + W A) Δq = W b,   A = Σ_j m_j J_jᵀ P_j J_j,   b = Σ_j m_j J_jᵀ ṽ_tan,j,   W = diag(1/M, I⁻¹)
// (D + 1 unknowns in 2D, 6 in 3D; W = 0 along a prescribed motion, whose Δq is then 0). Every tangential slip
// is gone after the step, momentum and angular momentum of body + nodes conserved — an inelastic stick of the
// nodes to the rigid body, for any slip pattern: a uniform slip along a face with the rotation prescribed
// gives the reduced mass, f_stick = −m_j ṽ_tan M/(M + S)/Δt; the opposite slips of two faces shearing a
// flaw filler give b = 0, Δq = 0, the full stick. (A single factor α on −m_j ṽ_tan/Δt, α = M/(M + S) or
// 1/(1 + S/M + R) with the rotational compliance R, stops one mode but only a fraction α of the two faces'
// opposite slip: at true mass the tunnel filler then carried no friction, its curve that of μ = 0.)
// The Coulomb limit of Eq. 24 applies unchanged to this f_stick. Sums per part over the group's contact
// nodes, weighted with the node's share in the reaction (symmetry planes), by one thread in node order; an
// immovable part (M = I = inf: a prescribed body) keeps exactly the paper's step and its groups the parallel
// node pass.
//
// Parallel and deterministic: the particle pass is a block-coloured scatter restricted to the blocks
// near the group (same-colour blocks never share a node, each block summed by one thread in particle
// order); the node pass is independent per node (one thread in node order for a group with a free part,
// after its sums); the reaction is summed by one thread in node order.
// Results are bitwise identical for any thread count. A solver without groups never calls any of it.
// MPI (doc/scaling.md, "Rigid bodies"): every rank holds the same bodies (YADE replicated); the particle
// pass's node sums (f_nor, N_i, A_i) of the shared bands are exchanged like P2G's, the node pass runs on each
// rank's copy, and the sums over nodes (the reactions, A and b of bodyResponse) count each node on its owner
// rank only and are added over the ranks in rank order: every rank gets the same reaction bits.
#pragma once
#include "../core/BlockSchedule.hpp"
#include "ContactGroups.hpp"
#include "../mpi/ContactMpi.hpp"
#include "../core/GridBoxes.hpp"
#include "KinematicContact.hpp"
#include "../core/WlsShape.hpp"

namespace mpm {

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

template <int D>
class PtsContact : public ContactGroups<D>, private GridBoxes<D> {
public:
	using Vec  = typename Dim<D>::Vec;
	using IVec = typename Dim<D>::IVec;
	static constexpr int N = Dim<D>::nStencil;
	using ContactGroups<D>::parts;
	using ContactGroups<D>::groups;
	using ContactGroups<D>::group;
	using ContactGroups<D>::part;
	using ContactGroups<D>::active;
	using ContactGroups<D>::edgeOf;
	using GridBoxes<D>::nodeRange;
	using GridBoxes<D>::blockRange;
	using GridBoxes<D>::blockBox;
	using GridBoxes<D>::forNodes;
	using GridBoxes<D>::boxCount;
	using GridBoxes<D>::boxNode;

	ContactNodes<D>     nodeArr; // per-node contact arrays (sized to the grid by the first step with bodies)
	std::vector<size_t> marked; // nodes carrying the contact exclusion bit
	MPM_IF_MPI(Decomposition<D>* dd = nullptr;) // MPI build: the solver's decomposition (set by the Solver)

	// ---------------------------------------------------------------- before P2G (serial)
	// World geometry, reaction reset, covered nodes excluded, per-group node/block ranges.
	void beforeTransfer(Grid<D>& grid, const BlockSchedule<D>& sched)
	{
		ensureArrays(grid);
		work.resize(groups.size()); // per-group scratch, one per registered group
		dq.resize(parts.size()), Aq.resize(parts.size()), bq.resize(parts.size()); // per-part scratch of bodyResponse
		for (size_t i : marked) grid.setContactExcluded(i, false);
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
			Vec        lo, hi;
			// nodes covered by the body (within `band` of the surface)
			g.bounds(0, band, lo, hi);
			IVec nlo, nhi;
			if (nodeRange(grid, lo, hi, nlo, nhi))
				forNodes(grid, nlo, nhi, [&](size_t i) {
					if (grid.excluded[i] & Grid<D>::ExclContact) return;
					Real d = g.query(grid.position(i)).d;
					if (d < 0 && d > -band) {
						grid.setContactExcluded(i, true);
						marked.push_back(i);
					}
				});
			// particles that may touch, and the nodes their stencils reach
			g.bounds(reach, band, lo, hi);
			bool near = blockRange(grid, sched, lo, hi, wk.blo, wk.bhi); // particles near the body
			MPM_IF_MPI(if (dd && dd->distributed()) near = blockBox(grid, sched, lo, hi, wk.blo, wk.bhi);) // MPI: from the geometry
			Vec slo = lo - Vec::Constant(2 * l), shi = hi + Vec::Constant(2 * l);
			wk.skip = !near || !nodeRange(grid, slo, shi, wk.nlo, wk.nhi);
			wk.reach = reach;
		}
	}

	// ---------------------------------------------------------------- after gridUpdate (every thread of the region)
	template <class ErrorRecord>
	void apply(Grid<D>& grid, const Particles<D>& P, const BlockSchedule<D>& sched, const StencilOffsets<D>& offs, Real dt, Real massFloor,
	           ErrorRecord& err)
	{
		auto& A = nodeArr;
		for (size_t gi = 0; gi < groups.size(); ++gi) {
			const auto& g  = groups[gi];
			const auto& wk = work[gi];
			if (wk.skip) continue;
			if (g.params.law == ContactLaw::Kinematic) { // KinematicContact.hpp
				MPM_ONE_THREAD
				{
					collectKinematic(grid, P, sched, offs, gi, wk, dt, massFloor, err);
					solveKinematic(grid, gi);
					kinematicReactions(gi, dt, 1);
				}
				MPM_ONE_THREAD_END
				continue;
			}
			const size_t nn = boxCount(wk.nlo, wk.nhi);
#pragma omp for schedule(static)
			for (size_t j = 0; j < nn; ++j) {
				size_t i = boxNode(grid, wk.nlo, wk.nhi, j);
				for (int a = 0; a < D; ++a) A.fn[a][i] = 0, A.force[a][i] = 0;
				A.area[i] = A.load[i] = 0;
			}
			// 1. normal penalty force of the contacted particles, Eq. 23
			const Real chi = g.params.chi, twoOverDt2 = 2.0 / (dt * dt);
			for (int c = 0; c < Dim<D>::nColours; ++c) {
				IVec first, cnt;
				size_t nb = 1;
				for (int a = 0; a < D; ++a) {
					const int par = (c >> a) & 1;
					first[a]      = wk.blo[a] + ((par - wk.blo[a]) % 2 + 2) % 2;
					cnt[a]        = first[a] > wk.bhi[a] ? 0 : (wk.bhi[a] - first[a]) / 2 + 1;
					nb *= size_t(cnt[a]);
				}
#pragma omp for schedule(dynamic, 1)
				for (size_t k = 0; k < nb; ++k) {
					size_t r = k, b = 0, s = 1;
					for (int a = 0; a < D; ++a) {
						b += size_t(first[a] + 2 * int(r % cnt[a])) * s;
						r /= cnt[a];
						s *= sched.nBlocks[a];
					}
					for (uint32_t p = sched.start[b]; p < sched.start[b + 1]; ++p) {
						Vec x;
						for (int a = 0; a < D; ++a) x[a] = P.x[a][p];
						const Real d0 = detectionDistance(g, P, p, edgeOf(P.vol[p]));
						if (d0 > wk.reach) continue; // beyond the detection margin (documented limit)
						const auto h = g.query(x);
						if (!(h.d - d0 < 0)) continue;
						Stencil<D> st;
						if (!computeStencil(grid, offs, x.data(), st)) {
							err.record(p, "is in contact with a rigid body but has too few active grid nodes for the WLS fit (penetrated the body?)");
							continue;
						}
						const Real fmag = (1 - chi) * P.mass[p] * twoOverDt2 * (d0 - h.d); // Eq. 23, κ_p = 2 m_p/Δt²
						const Vec  fp   = fmag * h.n;
						const Real ap   = P.vol[p] / edgeOf(P.vol[p]); // face of the particle
						Real       wsum = 0;                          // B-spline weights over the active nodes
						for (int n = 0; n < N; ++n) wsum += st.w[n];
						const Real wn = 1 / wsum;
						for (int n = 0; n < N; ++n) {
							if (st.w[n] == 0) continue;
							const size_t i = st.base + offs.off[n];
							// Eq. 23 with the fit ψ_i: the force acts at x_p (Σ ψ_i x_i = x_p). Lumped like the mass
							// (η_i, WlsShape.hpp) it would act at x̄_p, inside the material: a column with three
							// contact faces measured 1.107 M/L instead of 0.97 (tests/test_contact_initial_d0.py).
							for (int a = 0; a < D; ++a) A.fn[a][i] += st.psi[n] * fp[a];
							A.load[i] += st.w[n] * wn * fmag;
							A.area[i] += st.w[n] * wn * ap;
						}
					}
				}
			}
			MPM_IF_MPI(contactMpi::sumShared(dd, grid, A.fn, A.load, A.area, err);) // + the neighbour ranks' partial sums
			// symmetry planes: a node next to a plane also carries the contact of the particles' images
			if (grid.hasMirrors()) {
#pragma omp single
				grid.forEachMirrorPair([&](size_t k, size_t kp, int axis) {
					for (int a = 0; a < D; ++a) A.fn[a][k] += (a == axis ? -1 : 1) * A.fn[a][kp];
					A.load[k] += A.load[kp], A.area[k] += A.area[kp];
				});
			}
			// 2. stick / slip per node, Eqs. 24–26
			const bool onePart   = g.parts.size() == 1;
			auto       stickSlip = [&](size_t j, const Motion* resp) {
				const size_t i = boxNode(grid, wk.nlo, wk.nhi, j);
				ContactNode  c;
				if (!contactNode(grid, g, i, dt, massFloor, c)) return;
				Vec vt = c.vt;
				if (resp) vt -= tangential(resp[c.part].at(c.r), c.n); // against the body's motion after the step
				Vec        ft = (-c.m / dt) * vt;                        // f_stick
				const Real fs = ft.norm();
				if (fs >= c.fmax) ft *= fs > 0 ? c.fmax / fs : 0; // Eq. 24: slip at the Coulomb limit
				const Vec     f   = c.fn + ft;
				const uint8_t fix = grid.fixMask[i];
				for (int a = 0; a < D; ++a) {
					grid.vel[i].c[a] = (fix >> a) & 1 ? 0.0 : c.v[a] + dt * f[a] / c.m;
					A.force[a][i]      = f[a];
				}
			};
			if (!wk.movable) {
#pragma omp for schedule(static)
				for (size_t j = 0; j < nn; ++j) stickSlip(j, nullptr);
			} else {
				MPM_ONE_THREAD // (MPI: master, bodyResponse reduces over the ranks)
				{
					bodyResponse(grid, g, wk, dt, massFloor);
					for (size_t j = 0; j < nn; ++j) stickSlip(j, dq.data());
				}
				MPM_ONE_THREAD_END
			}
			// 3. reaction on the parts: minus the nodal contact forces, in node order
#pragma omp single
			{
				for (size_t j = 0; j < nn; ++j) {
					const size_t i = boxNode(grid, wk.nlo, wk.nhi, j);
					Vec          f;
					for (int a = 0; a < D; ++a) f[a] = A.force[a][i];
					if (grid.hasMirrors()) f *= grid.mirrorShare(i); // images beyond symmetry planes are not the body's
					if (f.isZero(0) || !counted(i)) continue;
					const Vec xi = grid.position(i);
					auto&     q  = parts[onePart ? g.parts[0] : g.query(xi).part];
					q.force -= f;
					q.torque -= momentOf<D>(xi - q.c, f);
				}
			}
		}
#ifdef MPM_MPI
#pragma omp master
		contactMpi::reduceParts(dd, flags, parts); // every rank's reactions, in rank order
#pragma omp barrier
#endif
	}

private:
	struct Work {
		bool skip = true;
		bool movable = false; // a part of the group is free (finite mass or inertia): stick step with its response
		IVec blo, bhi; // block coordinate range of the particle pass
		IVec nlo, nhi; // stored node coordinate range of the node pass
		Real reach = 0;
	};
	std::vector<Work> work;
	static constexpr int NS = D == 2 ? 1 : 3, NQ = D + NS; // rotations, rigid-body unknowns (v, ω)
	using QVec = Eigen::Matrix<Real, NQ, 1>;
	using QMat = Eigen::Matrix<Real, NQ, NQ>;
	struct Motion { // the body's velocity change of the step, Δq = (Δv, Δω)
		Vec       v = Vec::Zero();
		SpinOf<D> w = SpinOf<D>::Zero();
		Vec       at(const Vec& r) const { return v + crossSpin<D>(w, r); }
	};
	std::vector<Motion> dq; // per part, set by bodyResponse
	// Sums over nodes count node i on one rank only (MPI: its owner; Decomposition::ownsNode).
	bool counted(size_t i) const
	{
		(void)i;
		MPM_IF_MPI(if (dd && !dd->ownsNode(i)) return false;)
		return true;
	}
	static Vec tangential(const Vec& u, const Vec& n) { return u - u.dot(n) * n; }
	// J_jᵀ u = (u, r × u): the generalised force of a force u at r on (v, ω).
	static QVec jT(const Vec& r, const Vec& u)
	{
		QVec g;
		g.template head<D>() = u;
		g.template tail<NS>() = momentOf<D>(r, u);
		return g;
	}

	// A contact node of a group (f_nor ≠ 0, mass above the floor): its normal force f_nor and velocity v, the
	// part owning the nearest surface point, lever arm r = x − c, normal n, tangential relative velocity ṽ_tan
	// (Eqs. 25–26), mass, share in the body's reaction (symmetry planes) and Coulomb limit μ N_i + A_i c.
	struct ContactNode {
		int  part;
		Vec  fn, v, r, n, vt;
		Real m, share, fmax;
	};
	bool contactNode(const Grid<D>& grid, const RigidGroup<D>& g, size_t i, Real dt, Real massFloor, ContactNode& c) const
	{
		const auto& A = nodeArr;
		for (int a = 0; a < D; ++a) c.fn[a] = A.fn[a][i];
		const Real  fnorm = c.fn.norm();
		const auto& nd    = grid.nodes[i];
		if (fnorm == 0 || !(nd.m > massFloor)) return false;
		const Vec xi = grid.position(i);
		c.part       = g.parts.size() == 1 ? g.parts[0] : g.query(xi).part;
		const auto& q = parts[c.part];
		for (int a = 0; a < D; ++a) c.v[a] = grid.vel[i].c[a];
		c.n  = c.fn / fnorm, c.r = xi - q.c;
		c.vt = tangential(c.v + (dt / nd.m) * c.fn - q.velocityAt(xi), c.n); // Eqs. 26, 25
		c.m    = nd.m;
		c.share = grid.hasMirrors() ? grid.mirrorShare(i) : 1;
		c.fmax = g.params.mu * A.load[i] + A.area[i] * g.params.cohesion; // Coulomb limit of Eq. 24
		return true;
	}

	// Δq of each free part of group g (see the header; Eq. 24 with a free body), serial, in node order:
	// 1. A and b over all contact nodes, (1 + W A) Δq = W b (every node sticks);
	// 2. the nodes whose f_stick against that Δq exceeds the Coulomb limit slip: their force, at the limit along
	//    f_stick, is a known impulse c on the body; A and b over the others, (1 + W A) Δq = W (b + c).
	// The node pass then sticks or slips each node against this Δq. An immovable part gets Δq = 0.
	void bodyResponse(const Grid<D>& grid, const RigidGroup<D>& g, const Work& wk, Real dt, Real massFloor)
	{
		const size_t nn = boxCount(wk.nlo, wk.nhi);
		for (int pass = 0; pass < 2; ++pass) {
			for (int p : g.parts) Aq[p].setZero(), bq[p].setZero();
			for (size_t j = 0; j < nn; ++j) {
				ContactNode  c;
				const size_t i = boxNode(grid, wk.nlo, wk.nhi, j);
				if (!counted(i) || !contactNode(grid, g, i, dt, massFloor, c)) continue;
				if (pass == 1) { // slipping against the all-stick Δq: a known force at the limit
					const Vec  ft = (-c.m / dt) * (c.vt - tangential(dq[c.part].at(c.r), c.n));
					const Real fs = ft.norm();
					if (fs >= c.fmax) {
						bq[c.part] -= (c.share * dt) * jT(c.r, fs > 0 ? Vec(ft * (c.fmax / fs)) : Vec(Vec::Zero()));
						continue;
					}
				}
				const Real m = c.share * c.m;
				bq[c.part] += m * jT(c.r, c.vt);
				// J_jᵀ P_j J_j: column k of J_j is e_k (v) or e_k × r (ω)
				QMat JtJ;
				for (int k = 0; k < NQ; ++k) {
					const Vec col = k < D ? Vec(Vec::Unit(k)) : crossSpin<D>(SpinOf<D>::Unit(k - D), c.r);
					JtJ.col(k)    = jT(c.r, tangential(col, c.n));
				}
				Aq[c.part] += m * JtJ;
			}
#ifdef MPM_MPI
			for (int p : g.parts) // the sums over every rank's nodes (A, b: fixed-size Eigen, contiguous)
				dd->sumInRankOrder(Aq[p].data(), NQ * NQ), dd->sumInRankOrder(bq[p].data(), NQ);
#endif
			for (int p : g.parts) {
				const auto& q = parts[p];
				dq[p]         = Motion {};
				if (!q.movable()) continue;
				QMat W = QMat::Zero();
				W.template topLeftCorner<D, D>().diagonal().setConstant(1 / q.mass);
				W.template bottomRightCorner<NS, NS>() = q.inverseInertia();
				const QVec x = (QMat::Identity() + W * Aq[p]).partialPivLu().solve(W * bq[p]);
				dq[p].v      = x.template head<D>();
				dq[p].w      = x.template tail<NS>();
			}
		}
	}
	// d0 of particle p (edge e_p): ½ e_p (autoD0) or the fixed d0, or for d0 = "initial" the first layer's d_p(0).
	static Real detectionDistance(const RigidGroup<D>& g, const Particles<D>& P, uint32_t p, Real e)
	{
		const size_t id = size_t(P.id[p]);
		if (id < g.d0Initial.size() && g.d0Initial[id] == g.d0Initial[id]) return g.d0Initial[id]; // d0_p = d_p(0)
		return g.params.autoD0 ? 0.5 * e : g.params.d0;
	}
	// ---------------------------------------------------------------- kinematic law (KinematicContact.hpp), one thread
	std::vector<std::vector<KinematicContactRec<D>>> kcs; // per group: its contacts this step (capacity kept between steps)
	// The body's velocity change per unit impulse e at r (free part; 0 for a prescribed one): W_B J e.
	Vec bodyCompliance(const RigidPart<D>& q, const Vec& r, const Vec& e) const
	{
		if (!q.movable()) return Vec::Zero();
		return e / q.mass + crossSpin<D>(SpinOf<D>(q.inverseInertia() * momentOf<D>(r, e)), r);
	}
	// 1. the contacting particles of the blocks near group gi's body, in block order
	void collectKinematic(Grid<D>& grid, const Particles<D>& P, const BlockSchedule<D>& sched, const StencilOffsets<D>& offs, size_t gi,
	                      const Work& wk, Real dt, Real massFloor, ErrorRecord& err)
	{
		MPM_IF_MPI(if (dd && dd->distributed()) { err.record(0, "is in a scene with a kinematic contact group, which MPI does not run yet (use law='penalty')"); return; })
		if (kcs.size() < groups.size()) kcs.resize(groups.size());
		const auto& g  = groups[gi];
		auto&       kc = kcs[gi];
		kc.clear();
		auto&        A  = nodeArr; // the nodal contact forces of the box, filled by kinematicReactions
		const size_t nb = boxCount(wk.nlo, wk.nhi);
		for (size_t j = 0; j < nb; ++j) {
			const size_t i = boxNode(grid, wk.nlo, wk.nhi, j);
			for (int a = 0; a < D; ++a) A.force[a][i] = 0;
		}
		IVec b;
		for (int a = 0; a < D; ++a) b[a] = wk.blo[a];
		while (true) {
			size_t bl = 0, s = 1;
			for (int a = 0; a < D; ++a) bl += size_t(b[a]) * s, s *= sched.nBlocks[a];
			for (uint32_t p = sched.start[bl]; p < sched.start[bl + 1]; ++p) {
				Vec x;
				for (int a = 0; a < D; ++a) x[a] = P.x[a][p];
				const Real e  = edgeOf(P.vol[p]);
				const Real d0 = detectionDistance(g, P, p, e);
				if (d0 > wk.reach) continue;
				const auto h = g.query(x);
				if (!(h.d - d0 < kinematicTouch * e)) continue;
				Stencil<D> st;
				if (!computeStencil(grid, offs, x.data(), st)) {
					err.record(p, "is in contact with a rigid body but has too few active grid nodes for the WLS fit (penetrated the body?)");
					continue;
				}
				KinematicContactRec<D> c;
				c.nn = 0;
				auto entry = [&](size_t i) -> int { // node i's entry (−1: too light to carry a velocity)
					if (!(grid.nodes[i].m > massFloor)) return -1;
					int k = 0;
					while (k < c.nn && c.node[k] != i) ++k; // a node reached twice (directly and as an image): one entry
					if (k == c.nn) {
						if (c.nn == N) return -1; // cannot happen: at most 4^D distinct nodes of the modelled region
						c.node[k] = i, c.invM[k] = 1 / grid.nodes[i].m, ++c.nn;
						for (int a = 0; a < D; ++a) c.rd[k][a] = c.w[k][a] = 0;
					}
					return k;
				};
				for (int n = 0; n < N; ++n) {
					const Real psi = st.psi[n];
					if (psi == 0) continue;
					const size_t i = st.base + offs.off[n];
					if (!grid.hasMirrors()) {
						const int k = entry(i);
						if (k >= 0)
							for (int a = 0; a < D; ++a) c.rd[k][a] += psi, c.w[k][a] += psi;
						continue;
					}
					int       sg[D];
					const int k = entry(grid.mirrorSource(i, sg));
					if (k >= 0)
						for (int a = 0; a < D; ++a) c.rd[k][a] += sg[a] * psi;
					grid.forMirrorReceivers(i, [&](size_t j, const int* sj) {
						const int kj = entry(j);
						if (kj >= 0)
							for (int a = 0; a < D; ++a) c.w[kj][a] += sj[a] * psi;
					});
				}
				if (c.nn == 0) continue;
				c.part = g.parts.size() == 1 ? g.parts[0] : h.part;
				c.x = x, c.n = h.n, c.r = x - parts[c.part].c;
				// Σ rd·w/m over the free components of the nodes, per axis (a boundary plane holds a component)
				for (int a = 0; a < D; ++a) c.kinvAxis[a] = 0;
				for (int k = 0; k < c.nn; ++k)
					for (int a = 0; a < D; ++a)
						if (!((grid.fixMask[c.node[k]] >> a) & 1)) c.kinvAxis[a] += c.rd[k][a] * c.w[k][a] * c.invM[k];
				c.g    = (d0 - h.d) / dt;
				c.cap0 = g.params.cohesion * (P.vol[p] / e) * dt;
				c.lam.setZero();
				kc.push_back(c);
			}
			int a = 0;
			for (; a < D; ++a) {
				if (b[a] < wk.bhi[a]) { ++b[a]; break; }
				b[a] = wk.blo[a];
			}
			if (a == D) break;
		}
		for (const auto& c : kc) // nodes of the records outside the box (partners of images)
			for (int k = 0; k < c.nn; ++k)
				for (int a = 0; a < D; ++a) A.force[a][c.node[k]] = 0;
		for (int p : g.parts) dq[p] = Motion {};
	}
	// 1/k of an impulse along unit e at contact c: Σ_a e_a² kinvAxis[a] (Σ_k rd_k w_k/m_k, free components) + e·(W_B e).
	Real kinematicCompliance(const KinematicContactRec<D>& c, const RigidPart<D>& q, const Vec& e) const
	{
		Real k = 0;
		for (int a = 0; a < D; ++a) k += e[a] * e[a] * c.kinvAxis[a];
		return k + e.dot(bodyCompliance(q, c.r, e));
	}
	// 2. projected Gauss–Seidel on the impulses of group gi (free parts' velocity changes in dq); continues from
	// the impulses found so far, so a second call after the late damping restores the constraints.
	void solveKinematic(Grid<D>& grid, size_t gi)
	{
		if (gi >= kcs.size()) return;
		const auto& g  = groups[gi];
		auto&       kc = kcs[gi];
		const Real  mu = g.params.mu;
		Real        scale = 0;
		for (int sweep = 0; sweep < kinematicSweeps; ++sweep) {
			Real worst = 0;
			for (auto& c : kc) {
				const auto& q  = parts[c.part];
				Vec         vp = Vec::Zero();
				for (int k = 0; k < c.nn; ++k)
					for (int a = 0; a < D; ++a) vp[a] += c.rd[k][a] * grid.vel[c.node[k]].c[a];
				const Vec u = vp - q.velocityAt(c.x) - dq[c.part].at(c.r);
				if (sweep == 0) scale = std::max(scale, u.norm());
				// normal
				const Real kinvN = kinematicCompliance(c, q, c.n);
				if (!(kinvN > 0)) continue; // every stencil component held by boundary planes
				const Real ln0 = c.lam.dot(c.n);
				const Real ln  = std::max(Real(0), ln0 + (c.g - u.dot(c.n)) / kinvN);
				// tangential: stop the slip with the effective mass of its direction
				const Vec  lt0 = c.lam - ln0 * c.n;
				const Vec  ut  = u - u.dot(c.n) * c.n;
				const Real utn = ut.norm();
				Vec        lt  = lt0;
				if (utn > 0) {
					const Real kinvT = kinematicCompliance(c, q, ut / utn);
					if (kinvT > 0) lt -= ut / kinvT;
				}
				const Real cap = mu * ln + c.cap0;
				const Real ltn = lt.norm();
				if (ltn > cap) lt *= cap / ltn; // slip at the limit (Eq. 24)
				const Vec lam = ln * c.n + lt;
				const Vec dl  = lam - c.lam;
				if (dl.isZero(0)) continue;
				c.lam = lam;
				for (int k = 0; k < c.nn; ++k) {
					const size_t  i   = c.node[k];
					const uint8_t fix = grid.fixMask[i];
					for (int a = 0; a < D; ++a)
						if (!((fix >> a) & 1)) grid.vel[i].c[a] += c.w[k][a] * c.invM[k] * dl[a];
				}
				if (q.movable()) { // the free body takes −Δλ at x_p
					dq[c.part].v -= dl / q.mass;
					dq[c.part].w -= SpinOf<D>(q.inverseInertia() * momentOf<D>(c.r, dl));
				}
				worst = std::max(worst, dl.norm() * kinvN);
			}
			if (worst <= kinematicTol * (scale + 1e-12)) break;
		}
	}
	// 3. reactions sign·(−λ/Δt) at x_p and the nodal contact forces sign·Σ_k w_k ∘ λ/Δt, in contact order
	// (sign −1 takes back what an earlier call reported, before the re-projection after the late damping).
	void kinematicReactions(size_t gi, Real dt, int sign)
	{
		if (gi >= kcs.size()) return;
		auto& A = nodeArr;
		for (const auto& c : kcs[gi]) {
			// the body takes −λ/Δt at x_p (its images' share is theirs); the nodal forces Σ_k w_k ∘ λ/Δt
			const Vec f = (sign / dt) * c.lam;
			for (int k = 0; k < c.nn; ++k)
				for (int a = 0; a < D; ++a) A.force[a][c.node[k]] += c.w[k][a] * f[a];
			auto& q = parts[c.part];
			q.force -= f;
			q.torque -= momentOf<D>(c.r, f);
		}
	}

public:
	// Some kinematic group has work this step (set by beforeTransfer).
	bool hasKinematic() const
	{
		for (size_t gi = 0; gi < groups.size(); ++gi)
			if (groups[gi].params.law == ContactLaw::Kinematic && gi < work.size() && !work[gi].skip) return true;
		return false;
	}
	// After the late damping (dampAfterContact), serial: the kinematic groups project again, so the damped velocities
	// still meet the constraints, and report the total impulse.
	void reprojectKinematic(Grid<D>& grid, Real dt)
	{
		for (size_t gi = 0; gi < groups.size(); ++gi) {
			if (groups[gi].params.law != ContactLaw::Kinematic || work[gi].skip) continue;
			kinematicReactions(gi, dt, -1);
			solveKinematic(grid, gi);
			kinematicReactions(gi, dt, 1);
		}
	}

private:

	std::vector<QMat> Aq; // per part: A of bodyResponse
	std::vector<QVec> bq; // per part: b (+ c) of bodyResponse
	MPM_IF_MPI(std::vector<double> flags;) // MPI scratch of reduceParts

	void ensureArrays(const Grid<D>& grid)
	{
		const size_t n = grid.size();
		if (nodeArr.size() == n) return;
		nodeArr.resize(n);
		marked.reserve(4096);
	}
};

} // namespace mpm
