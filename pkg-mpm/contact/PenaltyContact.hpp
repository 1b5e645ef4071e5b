// The penalty contact law (ContactLaw::Penalty, paper Eqs. 23–26 as printed), one group per call: 1. the particle
// pass spreads the normal penalty force of Eq. 23 to the nodes, 2. the node pass sticks or slips each contact node
// against the body (Eqs. 24–26, a free body's motion after the step included), 3. the reactions on the parts.
// Every thread of the step's region calls it; the sums have a fixed order. A layer of PtsContact (Base:
// ContactDetection); the reasoning behind N_i, A_i and the free-body stick step: doc/developer/core_notes.md.
#pragma once
#include "ContactDetection.hpp"

namespace mpm {

template <int D, class Base>
class PenaltyContact : public Base {
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

	// Per-part scratch of bodyResponse, sized before the step's parallel region.
	void preparePenalty() { Aq.resize(parts.size()), bq.resize(parts.size()); }
	// Group gi with the penalty law; every thread of the step's parallel region.
	template <class X>
	void applyPenalty(size_t gi, const ContactStep<D, X>& s)
	{
		auto&        A         = nodeArr;
		Grid<D>&     grid      = s.grid;
		const Real   dt        = s.dt;
		const Real   massFloor = s.massFloor;
		const auto&  g         = groups[gi];
		const auto&  wk        = work[gi];
		const size_t nn        = Boxes::boxCount(wk.nlo, wk.nhi);
#pragma omp for schedule(static)
		for (size_t j = 0; j < nn; ++j) {
			size_t i = Boxes::boxNode(grid, wk.nlo, wk.nhi, j);
			for (int a = 0; a < D; ++a) A.fn[a][i] = 0, A.force[a][i] = 0;
			A.area[i] = A.load[i] = 0;
		}
		particlePass(g, wk, s);
		Real* sums[D + 2]; // + the partial sums of the nodes shared with other processes
		for (int a = 0; a < D; ++a) sums[a] = A.fn[a].data();
		sums[D] = A.load.data(), sums[D + 1] = A.area.data();
		s.exchange.sumSharedArrays(grid, sums, D + 2, s.err, "contact");
		// symmetry planes: a node next to a plane also carries the contact of the particles' images
		if (grid.hasMirrors()) {
#pragma omp single
			grid.mirrors.forEachPair([&](size_t k, size_t kp, int axis) {
				for (int a = 0; a < D; ++a) A.fn[a][k] += (a == axis ? -1 : 1) * A.fn[a][kp];
				A.load[k] += A.load[kp], A.area[k] += A.area[kp];
			});
		}
		// 2. stick / slip per node, Eqs. 24–26
		const bool onePart   = g.parts.size() == 1;
		auto       stickSlip = [&](size_t j, const BodyMotion<D>* resp) {
			const size_t i = Boxes::boxNode(grid, wk.nlo, wk.nhi, j);
			ContactNode  cn;
			if (!contactNode(grid, g, i, dt, massFloor, cn)) return;
			Vec vt = cn.vt;
			if (resp) vt -= tangential(resp[cn.part].at(cn.r), cn.n); // against the body's motion after the step
			Vec        ft = (-cn.m / dt) * vt;                         // f_stick
			const Real fs = ft.norm();
			if (fs >= cn.fmax) ft *= fs > 0 ? cn.fmax / fs : 0; // Eq. 24: slip at the Coulomb limit
			const Vec     f   = cn.fn + ft;
			const uint8_t fix = grid.fixMask[i];
			for (int a = 0; a < D; ++a) {
				grid.vel[i].c[a] = (fix >> a) & 1 ? 0.0 : cn.v[a] + dt * f[a] / cn.m;
				A.force[a][i]    = f[a];
			}
		};
		if (!wk.movable) {
#pragma omp for schedule(static)
			for (size_t j = 0; j < nn; ++j) stickSlip(j, nullptr);
		} else {
			s.exchange.oneThread([&] {
				bodyResponse(grid, g, wk, dt, massFloor, s.exchange);
				for (size_t j = 0; j < nn; ++j) stickSlip(j, dq.data());
			});
		}
		// 3. reaction on the parts: minus the nodal contact forces, in node order
#pragma omp single
		{
			for (size_t j = 0; j < nn; ++j) {
				const size_t i = Boxes::boxNode(grid, wk.nlo, wk.nhi, j);
				Vec          f;
				for (int a = 0; a < D; ++a) f[a] = A.force[a][i];
				if (grid.hasMirrors()) f *= grid.mirrorShare(i); // images beyond symmetry planes are not the body's
				if (f.isZero(0) || !s.exchange.owns(i)) continue;
				const Vec xi = grid.position(i);
				auto&     q  = parts[onePart ? g.parts[0] : g.query(xi).part];
				q.force -= f;
				q.torque -= momentOf<D>(xi - q.c, f);
			}
		}
	}

private:
	static constexpr int NS = D == 2 ? 1 : 3, NQ = D + NS; // rotations, rigid-body unknowns (v, ω)
	using QVec = Eigen::Matrix<Real, NQ, 1>;
	using QMat = Eigen::Matrix<Real, NQ, NQ>;
	std::vector<QMat> Aq; // per part: A of bodyResponse
	std::vector<QVec> bq; // per part: b (+ c) of bodyResponse

	// 1. the normal penalty force of the contacted particles (Eq. 23): a block-coloured scatter over the blocks
	// near the group (same-colour blocks never share a node, each block summed by one thread in particle order).
	template <class X>
	void particlePass(const RigidGroup<D>& g, const GroupWork<D>& wk, const ContactStep<D, X>& s)
	{
		auto&                    A     = nodeArr;
		const Grid<D>&           grid  = s.grid;
		const Particles<D>&      P     = s.P;
		const BlockSchedule<D>&  sched = s.sched;
		const StencilOffsets<D>& offs  = s.offs;
		const Real               chi = g.params.chi, twoOverDt2 = 2.0 / (s.dt * s.dt);
		for (int col = 0; col < Dim<D>::nColours; ++col) {
			IVec   first, cnt;
			size_t nb = 1;
			for (int a = 0; a < D; ++a) {
				const int par = (col >> a) & 1;
				first[a]      = wk.blo[a] + ((par - wk.blo[a]) % 2 + 2) % 2;
				cnt[a]        = first[a] > wk.bhi[a] ? 0 : (wk.bhi[a] - first[a]) / 2 + 1;
				nb *= size_t(cnt[a]);
			}
#pragma omp for schedule(dynamic, 1)
			for (size_t k = 0; k < nb; ++k) {
				size_t r = k, b = 0, st1 = 1;
				for (int a = 0; a < D; ++a) {
					b += size_t(first[a] + 2 * int(r % cnt[a])) * st1;
					r /= cnt[a];
					st1 *= sched.nBlocks[a];
				}
				for (uint32_t p = sched.start[b]; p < sched.start[b + 1]; ++p) {
					Vec x;
					for (int a = 0; a < D; ++a) x[a] = P.x[a][p];
					const Real d0 = ContactDetection<D>::detectionDistance(g, P, p, ContactGroups<D>::edgeOf(P.vol[p]));
					if (d0 > wk.reach) continue; // beyond the detection margin
					const auto h = g.query(x);
					if (!(h.d - d0 < 0)) continue;
					Stencil<D> st;
					if (!computeStencil(grid, offs, x.data(), st)) {
						s.err.record(p, "is in contact with a rigid body but has too few active grid nodes for the WLS fit (penetrated the body?)");
						continue;
					}
					const Real fmag = (1 - chi) * P.mass[p] * twoOverDt2 * (d0 - h.d); // Eq. 23, κ_p = 2 m_p/Δt²
					const Vec  fp   = fmag * h.n;
					const Real ap   = P.vol[p] / ContactGroups<D>::edgeOf(P.vol[p]); // face of the particle
					Real       wsum = 0;                                            // B-spline weights over the active nodes
					for (int n = 0; n < N; ++n) wsum += st.w[n];
					const Real wn = 1 / wsum;
					for (int n = 0; n < N; ++n) {
						if (st.w[n] == 0) continue;
						const size_t i = st.base + offs.off[n];
						for (int a = 0; a < D; ++a) A.fn[a][i] += st.psi[n] * fp[a]; // Eq. 23 with ψ_i: the force acts at x_p
						A.load[i] += st.w[n] * wn * fmag;
						A.area[i] += st.w[n] * wn * ap;
					}
				}
			}
		}
	}

	static Vec tangential(const Vec& u, const Vec& n) { return u - u.dot(n) * n; }
	// J_jᵀ u = (u, r × u): the generalised force of a force u at r on (v, ω).
	static QVec jT(const Vec& r, const Vec& u)
	{
		QVec g;
		g.template head<D>()  = u;
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
	bool contactNode(const Grid<D>& grid, const RigidGroup<D>& g, size_t i, Real dt, Real massFloor, ContactNode& cn) const
	{
		const auto& A = nodeArr;
		for (int a = 0; a < D; ++a) cn.fn[a] = A.fn[a][i];
		const Real  fnorm = cn.fn.norm();
		const auto& nd    = grid.nodes[i];
		if (fnorm == 0 || !(nd.m > massFloor)) return false;
		const Vec xi  = grid.position(i);
		cn.part       = g.parts.size() == 1 ? g.parts[0] : g.query(xi).part;
		const auto& q = parts[cn.part];
		for (int a = 0; a < D; ++a) cn.v[a] = grid.vel[i].c[a];
		cn.n = cn.fn / fnorm, cn.r = xi - q.c;
		cn.vt    = tangential(cn.v + (dt / nd.m) * cn.fn - q.velocityAt(xi), cn.n); // Eqs. 26, 25
		cn.m     = nd.m;
		cn.share = grid.hasMirrors() ? grid.mirrorShare(i) : 1;
		cn.fmax  = g.params.mu * A.load[i] + A.area[i] * g.params.cohesion; // Coulomb limit of Eq. 24
		return true;
	}

	// Δq of each free part of group g (Eq. 24 with the body's mass: every contact node sticks to the body's motion
	// after the step), one thread, in node order; the sums count each node once over the processes:
	// 1. A and b over all contact nodes, (1 + W A) Δq = W b (every node sticks);
	// 2. the nodes whose f_stick against that Δq exceeds the Coulomb limit slip: their force, at the limit along
	//    f_stick, is a known impulse c on the body; A and b over the others, (1 + W A) Δq = W (b + c).
	// An immovable part gets Δq = 0. Kept out of line: the compiler's FMA contraction depends on the context.
	template <class X>
	[[gnu::noinline]] void bodyResponse(const Grid<D>& grid, const RigidGroup<D>& g, const GroupWork<D>& wk, Real dt, Real massFloor, const X& exchange)
	{
		const size_t nn = Boxes::boxCount(wk.nlo, wk.nhi);

		for (int pass = 0; pass < 2; ++pass) {
			for (int p : g.parts) Aq[p].setZero(), bq[p].setZero();
			for (size_t j = 0; j < nn; ++j) {
				ContactNode  cn;
				const size_t i = Boxes::boxNode(grid, wk.nlo, wk.nhi, j);
				if (!exchange.owns(i) || !contactNode(grid, g, i, dt, massFloor, cn)) continue;
				if (pass == 1) { // slipping against the all-stick Δq: a known force at the limit
					const Vec  ft = (-cn.m / dt) * (cn.vt - tangential(dq[cn.part].at(cn.r), cn.n));
					const Real fs = ft.norm();
					if (fs >= cn.fmax) {
						bq[cn.part] -= (cn.share * dt) * jT(cn.r, fs > 0 ? Vec(ft * (cn.fmax / fs)) : Vec(Vec::Zero()));
						continue;
					}
				}
				const Real m = cn.share * cn.m;
				bq[cn.part] += m * jT(cn.r, cn.vt);
				// J_jᵀ P_j J_j: column k of J_j is e_k (v) or e_k × r (ω)
				QMat JtJ;
				for (int k = 0; k < NQ; ++k) {
					const Vec col = k < D ? Vec(Vec::Unit(k)) : crossSpin<D>(SpinOf<D>::Unit(k - D), cn.r);
					JtJ.col(k)    = jT(cn.r, tangential(col, cn.n));
				}
				Aq[cn.part] += m * JtJ;
			}
			for (int p : g.parts) // the sums over every process's nodes (A, b: fixed-size Eigen, contiguous)
				exchange.sumInOrder(Aq[p].data(), NQ * NQ), exchange.sumInOrder(bq[p].data(), NQ);
			for (int p : g.parts) {
				const auto& q = parts[p];
				dq[p]         = BodyMotion<D> {};
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
};

} // namespace mpm
