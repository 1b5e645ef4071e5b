// The kinematic contact law (ContactLaw::Kinematic, the default; doc/contact.md "Contact laws"): the Δt → 0 limit of
// Eq. 23, reached at any Δt by constraining the velocities of the touching particles (no approach, Coulomb + cohesion
// as an impulse limit, Eq. 24) with impulses found by projected Gauss–Seidel over the contacts in a fixed order (one
// thread). A layer of PtsContact (Base: ContactDetection); the derivation: doc/developer/core_notes.md.
// Under MPI every process gathers every process's contacts of a group (with the velocities of their nodes) and
// solves them all in the same order (block, then particle id): the same impulses on every process and in one
// process; each process then writes the velocities of the nodes it holds and reports its own contacts' reactions.
#pragma once
#include "ContactDetection.hpp"
#include "KinematicRecords.hpp"
#include <algorithm>
#include <array>

namespace mpm {

// Detection tolerance of the kinematic law, as a fraction of the particle's edge (ε_p above).
constexpr Real kinematicTouch = 1e-3;
// Projected Gauss–Seidel: at most this many sweeps over the contacts, fewer when the largest velocity
// correction of a sweep falls below kinematicTol × (the largest relative speed before the sweeps + 1e-12 m/s).
constexpr int  kinematicSweeps = 60;
constexpr Real kinematicTol    = 1e-6;

template <int D, class Base>
class KinematicContact : public Base {
public:
	using Vec   = typename Dim<D>::Vec;
	using IVec  = typename Dim<D>::IVec;
	using Boxes = GridBoxes<D>;
	using Base::dq;
	using Base::groups;
	using Base::nodeArr;
	using Base::parts;
	using Base::work;
	static constexpr int N = Dim<D>::nStencil;

	// Group gi with the kinematic law: its contacts, impulses and reactions; one thread (the exchange's oneThread).
	template <class X>
	void applyKinematic(size_t gi, const ContactStep<D, X>& s)
	{
		collect(gi, s);
		share(gi, s);
		const Real scale = warmStart(gi, s.dt);
		solve(gi, scale);
		store(s.grid.vel, gi);
		reactions(gi, s.dt, 1);
		keepImpulses(gi, s.dt);
	}
	// A step in which group gi had no work: its next contacts start from zero.
	void idleKinematic(size_t gi)
	{
		if (gi < warm.size()) warm[gi].clear();
	}
	// After the late damping (dampAfterContact), one thread: the damped velocities meet the constraints again; the
	// reactions are those of the total impulse.
	template <class X>
	void reprojectKinematic(size_t gi, const ContactStep<D, X>& s)
	{
		if (gi >= kcs.size()) return;
		refresh(gi, s, s.grid.vel);
		reactions(gi, s.dt, -1);
		solve(gi, 0);
		store(s.grid.vel, gi);
		reactions(gi, s.dt, 1);
		keepImpulses(gi, s.dt);
	}

	// After the MUSL remap (Eqs. 16–17), one thread: group gi's nodes' vmusl corrected (Gauss–Seidel, the per-axis
	// compliance of the solve; bodies and reactions untouched) so the tangential part of each contact's Σ_k rd_k ṽ_k is
	// that of the velocity the contact gave its particle: the strain (phase 6) does not slip where the motion stuck.
	// The normal part is left to the remap: correcting it too fed energy into an impact at C ≥ 0.8
	// (doc/reference/contact.md).
	template <class X>
	void constrainRemap(size_t gi, const ContactStep<D, X>& s)
	{
		if (gi >= kcs.size()) return;
		auto& t  = tabs[gi];
		auto& kc = kcs[gi];
		remapTarget.resize(kc.size());
		Real scale = 0;
		for (size_t j = 0; j < kc.size(); ++j) remapTarget[j] = particleVelocity(kc[j], t), scale = std::max(scale, remapTarget[j].norm());
		refresh(gi, s, s.grid.vmusl);
		for (int sweep = 0; sweep < kinematicSweeps; ++sweep) {
			Real worst = 0;
			for (size_t j = 0; j < kc.size(); ++j) {
				const auto& c  = kc[j];
				Vec         du = remapTarget[j] - particleVelocity(c, t);
				du -= du.dot(c.n) * c.n; // tangential only
				worst          = std::max(worst, du.norm());
				for (int k = 0; k < c.nn; ++k) {
					const size_t  sl  = size_t(c.slot[k]);
					const uint8_t fix = t.fix[sl];
					for (int a = 0; a < D; ++a)
						if (!((fix >> a) & 1) && c.kinvAxis[a] > 0) t.v[sl][a] += c.w[k][a] * c.invM[k] * du[a] / c.kinvAxis[a];
				}
			}
			if (worst <= kinematicTol * (scale + 1e-12)) break;
		}
		store(s.grid.vmusl, gi);
	}

	// The impulses the next step starts from (checkpoints; KinematicRecords.hpp).
	using WarmImpulse = KinematicWarmImpulse<D>;
	std::vector<KinematicWarmStart<D>> warm; // per group

private:
	std::vector<std::vector<KinematicContactRec<D>>> kcs;  // per group: its contacts this step (capacity kept between steps)
	std::vector<Vec>                                 remapTarget; // scratch of constrainRemap: each contact's particle velocity
	std::vector<KinematicNodeTable<D>>               tabs; // per group: the nodes of its contacts

	// The body's velocity change per unit impulse e at r (free part; 0 for a prescribed one): W_B J e.
	static Vec bodyCompliance(const RigidPart<D>& q, const Vec& r, const Vec& e)
	{
		if (!q.movable()) return Vec::Zero();
		return e / q.mass + crossSpin<D>(SpinOf<D>(q.inverseInertia() * momentOf<D>(r, e)), r);
	}
	// 1/k of an impulse along unit e at contact c: Σ_a e_a² kinvAxis[a] (Σ_k rd_k w_k/m_k, free components) + e·(W_B e).
	static Real compliance(const KinematicContactRec<D>& c, const RigidPart<D>& q, const Vec& e)
	{
		Real k = 0;
		for (int a = 0; a < D; ++a) k += e[a] * e[a] * c.kinvAxis[a];
		return k + e.dot(bodyCompliance(q, c.r, e));
	}

	// 1. this process's contacting particles of the blocks near group gi's body, in block order
	template <class X>
	void collect(size_t gi, const ContactStep<D, X>& s)
	{
		Grid<D>&                 grid  = s.grid;
		const Particles<D>&      P     = s.P;
		const BlockSchedule<D>&  sched = s.sched;
		const StencilOffsets<D>& offs  = s.offs;
		const GroupWork<D>&      wk    = work[gi];
		if (kcs.size() < groups.size()) kcs.resize(groups.size());
		const auto& g  = groups[gi];
		auto&       kc = kcs[gi];
		kc.clear();
		auto&        A  = nodeArr; // the nodal contact forces of the box, filled by reactions
		const size_t nb = Boxes::boxCount(wk.nlo, wk.nhi);
		for (size_t j = 0; j < nb; ++j) {
			const size_t i = Boxes::boxNode(grid, wk.nlo, wk.nhi, j);
			for (int a = 0; a < D; ++a) A.force[a][i] = 0;
		}
		IVec b;
		for (int a = 0; a < D; ++a) b[a] = wk.blo[a];
		while (true) {
			size_t bl = 0, st1 = 1;
			for (int a = 0; a < D; ++a) bl += size_t(b[a]) * st1, st1 *= sched.nBlocks[a];
			for (uint32_t p = sched.start[bl]; p < sched.start[bl + 1]; ++p) {
				Vec x;
				for (int a = 0; a < D; ++a) x[a] = P.x[a][p];
				const Real e  = ContactGroups<D>::edgeOf(P.vol[p]);
				const Real d0 = ContactDetection<D>::detectionDistance(g, P, p, e);
				if (d0 > wk.reach) continue;
				const auto h = g.query(x);
				if (!(h.d - d0 < kinematicTouch * e)) continue;
				Stencil<D> st;
				if (!computeStencil(grid, offs, x.data(), st)) {
					s.err.record(p, "is in contact with a rigid body but has too few active grid nodes for the WLS fit (penetrated the body?)");
					continue;
				}
				KinematicContactRec<D> c;
				c.nn       = 0;
				auto entry = [&](size_t i) -> int { // node i's entry (−1: too light to carry a velocity)
					if (!(grid.nodes[i].m > s.massFloor)) return -1;
					int k = 0;
					while (k < c.nn && c.node[k] != i) ++k; // a node reached twice (directly and as an image): one entry
					if (k == c.nn) {
						if (c.nn == N) return -1; // cannot happen: at most 4^D distinct nodes of the modelled region
						c.node[k] = i, c.invM[k] = 1 / grid.nodes[i].m, c.fix[k] = grid.fixMask[i], ++c.nn;
						for (int a = 0; a < D; ++a) c.rd[k][a] = c.w[k][a] = 0, c.vel[k][a] = grid.vel[i].c[a];
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
				for (int k = 0; k < c.nn; ++k) {
					for (int a = 0; a < D; ++a)
						if (!((c.fix[k] >> a) & 1)) c.kinvAxis[a] += c.rd[k][a] * c.w[k][a] * c.invM[k];
					c.node[k] += grid.offset; // global index from here on
				}
				c.block = uint32_t(bl), c.id = P.id[p], c.mine = true;
				c.g    = (d0 - h.d) / s.dt;
				c.cap0 = g.params.cohesion * (P.vol[p] / e) * s.dt;
				c.lam.setZero();
				kc.push_back(c);
			}
			int a = 0;
			for (; a < D; ++a) {
				if (b[a] < wk.bhi[a]) {
					++b[a];
					break;
				}
				b[a] = wk.blo[a];
			}
			if (a == D) break;
		}
		for (int p : g.parts) dq[p] = BodyMotion<D> {};
	}

	// 2. every process's contacts of group gi in (block, id) order, and the table of their nodes
	template <class X>
	void share(size_t gi, const ContactStep<D, X>& s)
	{
		auto&        kc   = kcs[gi];
		const size_t mine = kc.size(), at = s.exchange.gatherInOrder(kc);
		for (size_t j = 0; j < kc.size(); ++j) kc[j].mine = j >= at && j < at + mine;
		s.exchange.agree(s.err, "contact");
		auto before = [](const KinematicContactRec<D>& a, const KinematicContactRec<D>& b) { return a.block != b.block ? a.block < b.block : a.id < b.id; };
		if (!std::is_sorted(kc.begin(), kc.end(), before)) std::sort(kc.begin(), kc.end(), before); // collected in block order: often sorted
		if (tabs.size() < groups.size()) tabs.resize(groups.size());
		auto& t = tabs[gi];
		t.node.clear();
		for (const auto& c : kc) t.node.insert(t.node.end(), c.node, c.node + c.nn);
		std::sort(t.node.begin(), t.node.end());
		t.node.erase(std::unique(t.node.begin(), t.node.end()), t.node.end());
		t.v.resize(t.node.size()), t.fix.resize(t.node.size()), t.local.resize(t.node.size());
		const Grid<D>& grid = s.grid;
		for (auto& c : kc)
			for (int k = 0; k < c.nn; ++k) {
				const size_t j = size_t(std::lower_bound(t.node.begin(), t.node.end(), c.node[k]) - t.node.begin());
				c.slot[k] = int(j), t.fix[j] = c.fix[k];
				for (int a = 0; a < D; ++a) t.v[j][a] = c.vel[k][a];
			}
		for (size_t j = 0; j < t.node.size(); ++j) {
			const size_t gn = t.node[j];
			t.local[j]      = gn >= grid.offset && gn - grid.offset < grid.size() ? gn - grid.offset : SIZE_MAX;
			if (t.local[j] != SIZE_MAX)
				for (int a = 0; a < D; ++a) nodeArr.force[a][t.local[j]] = 0; // nodes of the records outside the box
		}
	}

	// The table's velocities from the grid again (of vel after the late damping, of vmusl after the remap): each process
	// sends those of the nodes it owns.
	template <class X>
	void refresh(size_t gi, const ContactStep<D, X>& s, const std::vector<NodeVec<D>>& arr)
	{
		auto& t = tabs[gi];
		t.upd.clear();
		for (size_t j = 0; j < t.node.size(); ++j)
			if (t.local[j] != SIZE_MAX && s.exchange.owns(t.local[j])) {
				typename KinematicNodeTable<D>::Update u { j, {} };
				for (int a = 0; a < D; ++a) u.v[a] = arr[t.local[j]].c[a];
				t.upd.push_back(u);
			}
		s.exchange.gatherInOrder(t.upd);
		for (const auto& u : t.upd)
			for (int a = 0; a < D; ++a) t.v[u.slot][a] = u.v[a];
	}
	// The table's velocities into arr (vel or vmusl) at the nodes this process holds.
	void store(std::vector<NodeVec<D>>& arr, size_t gi) const
	{
		const auto& t = tabs[gi];
		for (size_t j = 0; j < t.node.size(); ++j)
			if (t.local[j] != SIZE_MAX)
				for (int a = 0; a < D; ++a) arr[t.local[j]].c[a] = t.v[j][a];
	}

	// Each contact starts from the impulse its particle had in the previous step, scaled by the ratio of the steps (a
	// steady force keeps λ/Δt), applied to the node table and the free bodies as a sweep would: a light free body
	// couples every contact, and Gauss–Seidel from zero then stops short of the solution by a Δt-dependent amount.
	// Returns the largest relative speed before the start (the scale of solve's convergence test).
	Real warmStart(size_t gi, Real dt)
	{
		auto&       kc    = kcs[gi];
		const auto& t     = tabs[gi];
		Real        scale = 0;
		for (const auto& c : kc) scale = std::max(scale, relativeVelocity(c, t).norm());
		if (gi >= warm.size() || warm[gi].imp.empty() || !(warm[gi].dt > 0)) return scale;
		const auto& w  = warm[gi].imp;
		const Real  sc = dt / warm[gi].dt;
		for (auto& c : kc) {
			const auto it = std::lower_bound(w.begin(), w.end(), c.id, [](const WarmImpulse& a, int64_t id) { return a.id < id; });
			if (it != w.end() && it->id == c.id) applyImpulse(gi, c, sc * it->lam);
		}
		return scale;
	}
	void keepImpulses(size_t gi, Real dt)
	{
		if (warm.size() < groups.size()) warm.resize(groups.size());
		auto& w = warm[gi];
		w.imp.clear(), w.dt = dt;
		for (const auto& c : kcs[gi])
			if (!c.lam.isZero(0)) w.imp.push_back({ c.id, c.lam });
		std::sort(w.imp.begin(), w.imp.end(), [](const WarmImpulse& a, const WarmImpulse& b) { return a.id < b.id; });
	}
	// u_p = v_p − (v + ω × r_p) of contact c over the node table (Eqs. 6, 26).
	Vec relativeVelocity(const KinematicContactRec<D>& c, const KinematicNodeTable<D>& t) const
	{
		return particleVelocity(c, t) - parts[c.part].velocityAt(c.x) - dq[c.part].at(c.r);
	}
	// λ_c += dl: the nodes' velocities (free components) and the free body's motion (−dl at x_p).
	void applyImpulse(size_t gi, KinematicContactRec<D>& c, const Vec& dl)
	{
		auto& t = tabs[gi];
		c.lam += dl;
		for (int k = 0; k < c.nn; ++k) {
			const size_t  j   = size_t(c.slot[k]);
			const uint8_t fix = t.fix[j];
			for (int a = 0; a < D; ++a)
				if (!((fix >> a) & 1)) t.v[j][a] += c.w[k][a] * c.invM[k] * dl[a];
		}
		const auto& q = parts[c.part];
		if (q.movable()) {
			dq[c.part].v -= dl / q.mass;
			dq[c.part].w -= SpinOf<D>(q.inverseInertia() * momentOf<D>(c.r, dl));
		}
	}

	// 3. projected Gauss–Seidel on the impulses of group gi over its node table (free parts' velocity changes in dq);
	// continues from the impulses found so far, so a second call after the late damping restores the constraints.
	// scale0: a relative speed the convergence test is taken against (warmStart's), with the first sweep's.
	void solve(size_t gi, Real scale0)
	{
		if (gi >= kcs.size()) return;
		auto& t = tabs[gi];
		const auto& g     = groups[gi];
		auto&       kc    = kcs[gi];
		const Real  mu    = g.params.mu;
		Real        scale = scale0;
		for (int sweep = 0; sweep < kinematicSweeps; ++sweep) {
			Real worst = 0;
			for (auto& c : kc) {
				const auto& q = parts[c.part];
				const Vec   u = relativeVelocity(c, t); // u_p = v_p − (v + ω × r_p), Eqs. 6, 26
				if (sweep == 0) scale = std::max(scale, u.norm());
				// normal
				const Real kinvN = compliance(c, q, c.n);
				if (!(kinvN > 0)) continue; // every stencil component held by boundary planes
				const Real ln0 = c.lam.dot(c.n);
				const Real ln  = std::max(Real(0), ln0 + (c.g - u.dot(c.n)) / kinvN); // u·n ≥ g_p, λ_n ≥ 0
				// tangential: stop the slip with the effective mass of its direction
				const Vec  lt0 = c.lam - ln0 * c.n;
				const Vec  ut  = u - u.dot(c.n) * c.n;
				const Real utn = ut.norm();
				Vec        lt  = lt0;
				if (utn > 0) {
					const Real kinvT = compliance(c, q, ut / utn);
					if (kinvT > 0) lt -= ut / kinvT;
				}
				const Real cap = mu * ln + c.cap0; // ‖λ_t‖ ≤ μ λ_n + c a_p Δt
				const Real ltn = lt.norm();
				if (ltn > cap) lt *= cap / ltn; // slip at the limit (Eq. 24)
				const Vec dl = ln * c.n + lt - c.lam;
				if (dl.isZero(0)) continue;
				applyImpulse(gi, c, dl); // the free body takes −Δλ at x_p
				worst = std::max(worst, dl.norm() * kinvN);
			}
			if (worst <= kinematicTol * (scale + 1e-12)) break;
		}
	}

	// 4. reactions sign·(−λ/Δt) at x_p of this process's contacts and the nodal contact forces sign·Σ_k w_k ∘ λ/Δt of
	// the nodes it holds, in contact order (sign −1 takes back what an earlier call reported, before the
	// re-projection after the late damping).
	void reactions(size_t gi, Real dt, int sign)
	{
		if (gi >= kcs.size()) return;
		auto&       A = nodeArr;
		const auto& t = tabs[gi];
		for (const auto& c : kcs[gi]) {
			// the body takes −λ/Δt at x_p (its images' share is theirs); the nodal forces Σ_k w_k ∘ λ/Δt
			const Vec f = (sign / dt) * c.lam;
			for (int k = 0; k < c.nn; ++k) {
				const size_t i = t.local[size_t(c.slot[k])];
				if (i != SIZE_MAX)
					for (int a = 0; a < D; ++a) A.force[a][i] += c.w[k][a] * f[a];
			}
			if (!c.mine) continue;
			auto& q = parts[c.part];
			q.force -= f;
			q.torque -= momentOf<D>(c.r, f);
		}
	}
};

} // namespace mpm
