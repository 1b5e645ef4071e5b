// Particle ↔ grid transfers of one step (paper Sec. 2.5, Fig. 2): P2G (Eqs. 20–22), G2P with the MUSL remap
// (Eqs. 6–7, 16–17) and the particle velocity gradient from the MUSL nodal velocities (Eq. 7). Scatters run colour
// by colour over the blocks of BlockSchedule (the same bits for any thread count); p2g and g2p are called by every
// thread of the solver's parallel region and record failures in an ErrorRecord.
#pragma once
#include "../core/BlockSchedule.hpp"
#include "CutStencilCache.hpp"
#include "Kinematics.hpp"
#include "../core/Lanes.hpp"
#include <atomic>
#include <omp.h>

namespace mpm {

template <int D>
class Transfer {
public:
	using Vec           = typename Dim<D>::Vec;
	Grid<D>&                grid;
	Particles<D>&           P;
	const BlockSchedule<D>& sched;
	const StencilOffsets<D> offs; // linear-index offsets of the 4^D stencil nodes

	CutStencilCache<D>      cuts; // the step's cut-stencil fits (P2G makes them, G2P and the stress pass read them)

	Transfer(Grid<D>& g, Particles<D>& p, const BlockSchedule<D>& s) : grid(g), P(p), sched(s), offs(g) { }

	// Scatter pass: colours in sequence, blocks of one colour in parallel (deterministic sums); fb(b) handles
	// block b. Thread t takes its own share of each colour first (BlockSchedule::colourShare), then helps with the
	// others' (blocks claimed through per-share counters; which thread sums a block changes no result).
	template <class FB>
	void scatterBlocks(FB&& fb) const
	{
		const int T = omp_get_num_threads(), t = omp_get_thread_num();
		if (T > maxShares) { // more threads than counters: plain dynamic scheduling
			for (int c = 0; c < Dim<D>::nColours; ++c) {
				const auto& blocks = sched.colour[c];
#pragma omp for schedule(dynamic, 1)
				for (size_t k = 0; k < blocks.size(); ++k) fb(blocks[k]);
			}
			return;
		}
		for (int c = 0; c < Dim<D>::nColours; ++c) {
			const auto& blocks = sched.colour[c];
			for (int j = 0; j < T; ++j) {
				const int u = (t + j) % T; // own share first, then the others'
				size_t    k0, k1;
				sched.colourShare(c, u, T, k0, k1);
				auto& next = claimed[c][u].n;
				for (size_t k = k0 + next.fetch_add(1, std::memory_order_relaxed); k < k1; k = k0 + next.fetch_add(1, std::memory_order_relaxed))
					fb(blocks[k]);
			}
#pragma omp barrier
			claimed[c][t].n.store(0, std::memory_order_relaxed); // unused until this pass's next call: barriers lie between
		}
	}
	// checked = false: inside the grid for sure (G2P and the stress pass, after P2G accepted the positions).
	template <bool checked = true>
	void kernelOf(size_t p, Kernel<D>& k) const
	{
		Real x[D];
		for (int a = 0; a < D; ++a) x[a] = P.x[a][p];
		computeKernel<D, checked>(KernelGeom<D>(grid), x, k);
	}

	// ------------------------------------------------------------ P2G: Eqs. 20–22
	// Every node receives w·(P0 + Σ_b A_b (x_i − x_p)_b) with the per-particle affine coefficients
	// P0 = [m, m, m v, f_ext] and A_b = [0, 0, m C_·b, −V σ_·b 3/l²] (interior particles, where
	// ∇ψ_i = w_i 3/l² (x_i − x_p)); particles with a general WLS stencil go through the full ψ, ∇ψ.
	// Sign of Eq. 21 in code: stress is tension-positive and f_int,i = −Σ_p V_p σ_p ∇ψ_i(x_p).
	// fused (no damping, which needs the force alone): the momentum lanes receive p + Δt f (Eq. 18's
	// numerator) and the force lanes stay 0, so in 2D P2G updates 4 lanes per node (m, mw, p + Δt f)
	// instead of 8: P0 = [m, m, m v + Δt f_ext], A_b = [0, 0, m C_·b − Δt V σ_·b 3/l²]. gridUpdate then
	// reads v = (p + Δt f)/m + Δt·0/m.
	// loadScale multiplies the particle surface forces (traction ramp). viewWrites: state may have been
	// written through NumPy views since the last step, so positions are checked against their block's
	// reach and mass and volume against (0, inf) (compile-time: a step without views pays nothing).
	template <class Mat>
	void p2g(const Mat& mat, const Vec& gravity, Real loadScale, bool viewWrites, Real dt, bool fused, ErrorRecord& err)
	{
		if (fused) {
			if (viewWrites) p2g<true, true>(mat, gravity, loadScale, dt, err);
			else p2g<false, true>(mat, gravity, loadScale, dt, err);
		} else {
			if (viewWrites) p2g<true, false>(mat, gravity, loadScale, dt, err);
			else p2g<false, false>(mat, gravity, loadScale, dt, err);
		}
	}
	template <bool checkViews, bool fused, class Mat>
	void p2g(const Mat& mat, const Vec& gravity, Real loadScale, Real dt, ErrorRecord& err)
	{
		auto& nodes = grid.nodes;
#pragma omp for schedule(static)
		for (size_t i = 0; i < nodes.size(); ++i) lanes(nodes[i]) = NodeLanes {}; // padding lanes too
		const KernelGeom<D> geo(grid);
		scatterBlocks([&](uint32_t blk) {
			const KernelGeom<D> g    = geo; // a local: not reloaded after the node stores
			const Real          s    = loadScale;
			const Real          Dinv = g.gradFactor; // interior M⁻¹ gradient factor 3/l²
			Real cellLo[D], cellHi[D]; // cells a particle of this block may reach: beyond, the colouring breaks
			if constexpr (checkViews) sched.reach(blk, cellLo, cellHi);
			const int t         = omp_get_thread_num(); // this block's cut-stencil fits go to thread t's store
			auto&     cutStore  = cuts.store[size_t(t)];
			uint32_t  cutUsed   = cuts.used[size_t(t)], cutMet = 0; // counted here, stored after the block (no shared line per particle)
			bool      cutCached = true;
			cuts.owner[blk] = uint32_t(t), cuts.start[blk] = cutUsed;
			// The interior path runs inline in the particle loop; cut stencils (p2gCut) and messages are out of line.
			for (uint32_t pp = sched.start[blk]; pp < sched.start[blk + 1]; ++pp) {
				const size_t p = pp;
				Kernel<D>    k;
				Real         x[D];
				for (int a = 0; a < D; ++a) x[a] = P.x[a][p];
				computeKernel<D, true>(g, x, k);
				if (!k.inside) {
					recordOutside(p, err);
					continue;
				}
				const Real m = P.mass[p], V = P.vol[p];
				if constexpr (checkViews) { // state written through the views without requestSort() is refused before it is used
					bool ok = m > 0 && m < INFINITY && V > 0 && V < INFINITY;
					for (int a = 0; a < D; ++a) {
						const Real f = (x[a] - g.origin[a]) * g.invH;
						ok &= f >= cellLo[a] && f < cellHi[a];
					}
					if (!ok) {
						recordViewWrite(p, cellLo, cellHi, err);
						continue;
					}
				}
				const Sym<D> sg = mat.forceStress(P, p);
				Real         mv[D], mC[D][D], fe[D];
				for (int a = 0; a < D; ++a) {
					mv[a] = m * P.v[a][p];
					for (int b = 0; b < D; ++b) mC[a][b] = m * P.C[a * D + b][p];
					fe[a] = m * gravity[a] + (P.hasTraction() ? s * P.trac[a][p] : 0.0); // Eq. 22
				}
				if (k.general) {
					++cutMet;
					cutCached = cutCached && cutUsed < cutStore.size();
					p2gCut<fused>(p, k, cutCached ? &cutStore[cutUsed++] : nullptr, m, V, sg, mv, mC, fe, dt, err);
					continue;
				}
				Real sgm[D][D];
				sym2full(sg, sgm);
				if constexpr (fused) {
					Real q[D], zero[D] = {};
					for (int a = 0; a < D; ++a) q[a] = mv[a] + dt * fe[a]; // p + Δt f_ext
					const NodeLanes P0 = nodeLanes<D>(m, m, q, zero);
					NodeLanes       A[D];
					for (int b = 0; b < D; ++b) {
						Real ca[D];
						for (int a = 0; a < D; ++a) ca[a] = mC[a][b] - dt * V * Dinv * sgm[a][b]; // Eq. 21 × Δt, fused
						A[b] = nodeLanes<D>(0, 0, ca, zero);
					}
					scatterAffine<D, true>(grid, k, P0, A);
				} else {
					const NodeLanes P0 = nodeLanes<D>(m, m, mv, fe); // lanes: m, mw, momentum…, force…
					NodeLanes       A[D];
					for (int b = 0; b < D; ++b) {
						Real ca[D], fa[D];
						for (int a = 0; a < D; ++a) {
							ca[a] = mC[a][b];
							fa[a] = -V * Dinv * sgm[a][b]; // Eq. 21, f_int = −Σ V σ ∇ψ
						}
						A[b] = nodeLanes<D>(0, 0, ca, fa);
					}
					scatterAffine(grid, k, P0, A); // Eqs. 20–22 with ψ = w: w (P0 + Σ_b A_b (x_i − x_p)_b)
				}
			}
			if (!cutCached) cuts.start[blk] = CutStencilCache<D>::none; // some fit did not fit: the later passes fit again
			cuts.used[size_t(t)] = cutUsed, cuts.need[size_t(t)] += cutMet;
		});
	}

	// ------------------------------------------------------------ G2P + MUSL remap: Eqs. 6–7, 16–17
	// Particle velocity and its WLS gradient from the updated nodal velocities (vel), then the particle's
	// local linear velocity field is spread back with Shepard weights ξ = w m / Σ w m (into mom).
	// flip (Solver.velocityUpdate): v_p ← v_p + Σ ψ_i (v_i − vold_i) instead of Eq. 6, and vg ← Σ ψ_i v_i, the
	// velocity the particle moves with (moveParticles). The MUSL remap spreads Σ ψ_i v_i either way, so the strain
	// (from the remap) and the motion come from one field, the one the contact and the boundary planes constrained.
	void g2p(ErrorRecord& err, bool flip)
	{
		if (flip) g2pPass<true>(err);
		else g2pPass<false>(err);
	}
	std::vector<Real> vg[D]; // flip only: Σ ψ_i v_i of the last G2P, the velocity of the position update [m/s]

	template <bool flip>
	void g2pPass(ErrorRecord& err)
	{
		const KernelGeom<D> geo(grid);
		scatterBlocks([&](uint32_t blk) {
			const KernelGeom<D> g   = geo; // a local: not reloaded after the stores
			const Stencil<D>*   cut = cuts.block(blk); // P2G's fits of this block's cut stencils, in order (or none)
			for (uint32_t pp = sched.start[blk]; pp < sched.start[blk + 1]; ++pp) {
				const size_t p = pp;
				Kernel<D>    k;
				Real         x[D];
				for (int a = 0; a < D; ++a) x[a] = P.x[a][p];
				computeKernel<D, false>(g, x, k);
				if (k.general) {
					g2pCut<flip>(p, k, cut ? cut++ : nullptr, err);
					continue;
				}
				const Real m = P.mass[p];
				Real       v[D], C[D][D];
				gatherPacked(grid, grid.vel, k, g.gradFactor, v, C); // Eqs. 6–7 from the updated velocities
				if constexpr (flip) {
					Real vo[D], Co[D][D];
					gatherPacked(grid, grid.vold, k, g.gradFactor, vo, Co); // the same fit of the velocities before the step
					flipVelocity(p, v, vo, C);
				} else storeVelocity(p, v, C);
				Real mvv[D], mc[D][D]; // m h_p(x_i) = m (v + ∇v (x_i − x_p))
				for (int a = 0; a < D; ++a) {
					mvv[a] = m * v[a];
					for (int b = 0; b < D; ++b) mc[a][b] = m * C[a][b];
				}
				scatterPacked(grid, grid.mom, k, mvv, mc); // Eq. 16 numerator, Σ w m h_p(x_i)
			}
		});
	}

	// ∇v_p = Σ v_i ⊗ ∇ψ_i over the MUSL nodal velocities (vmusl, Eq. 7). False if no stencil node is active.
	// general: a cut stencil, whose v_p stands at x̄_p = x_p + dbar (g2p); dbar is left untouched otherwise.
	// g: KernelGeom of the grid, made once per pass; cut: the block's next cached fit (cuts.block), advanced when used.
	bool velocityGradient(const KernelGeom<D>& g, size_t p, Real (&L)[D][D], bool& general, Real (&dbar)[D], const Stencil<D>*& cut) const
	{
		Kernel<D> k;
		Real      x[D];
		for (int a = 0; a < D; ++a) x[a] = P.x[a][p];
		computeKernel<D, false>(g, x, k);
		general = k.general;
		if (!k.general) {
			Real v[D];
			gatherPacked(grid, grid.vmusl, k, g.gradFactor, v, L);
			return true;
		}
		return velocityGradientCut(k, cut ? cut++ : nullptr, L, dbar);
	}

	// Velocity of the material point x_p: v_p + C_p (x_p − x̄_p). A cut stencil's v_p is the velocity at x̄_p (g2p:
	// Σ_p m_p v_p is the grid's momentum), so the material point moves with this one (updateStress); x̄_p from the
	// current positions and node exclusions (those of the last step until the next one starts). False: no stencil node active.
	bool materialVelocity(size_t p, Real (&v)[D]) const
	{
		Kernel<D> k;
		kernelOf(p, k);
		for (int a = 0; a < D; ++a) v[a] = P.v[a][p];
		if (!k.inside || !k.general) return true; // interior: x̄_p = x_p; outside the grid: v_p as stored
		Stencil<D> st;
		if (!fillStencil(grid, offs, k, st)) return false;
		for (int a = 0; a < D; ++a)
			for (int b = 0; b < D; ++b) v[a] -= P.C[a * D + b][p] * st.dbar[b];
		return true;
	}

	std::string positionText(size_t p) const
	{
		std::string t = "(";
		for (int a = 0; a < D; ++a) t += (a ? ", " : "") + fmtNum(P.x[a][p]);
		return t + ") m";
	}

private:
	// Blocks claimed so far of colour c's share u in the running scatter pass (scatterBlocks), one cache line each.
	static constexpr int maxShares = 64;
	struct alignas(64) Counter {
		std::atomic<size_t> n { 0 };
	};
	mutable Counter claimed[Dim<D>::nColours][maxShares];

	// P2G of a particle with a cut stencil (some node excluded): mass, momentum and external force lumped with η ≥ 0
	// (WlsShape.hpp), the particle's velocity v_p standing at the centroid x̄_p = x_p + dbar of its weights
	// (Σ η (x_i − x̄_p) = 0: momentum conserved); internal force with the fitted ∇ψ (Σ_i ∇ψ_i = 0). Out of line:
	// the interior loop stays small.
	// slot: where the fit is kept for G2P and the stress pass (nullptr: not kept).
	template <bool fused>
	[[gnu::noinline]] void p2gCut(size_t p, const Kernel<D>& k, Stencil<D>* slot, Real m, Real V, const Sym<D>& sg, const Real (&mv)[D], const Real (&mC)[D][D],
	                              const Real (&fe)[D], Real dt, ErrorRecord& err)
	{
		Stencil<D>  local;
		Stencil<D>& st = slot ? *slot : local;
		if (!fillStencil(grid, offs, k, st)) return err.record(p, noActiveNodeMessage);
		forStencil(grid.nodes.data(), offs, st, [&](Node<D>& nd, int n, const Real(&dx)[D]) {
			const Real eta = st.eta[n];
			nd.m += eta * m;       // Eq. 20, positive lumping
			nd.mw += st.w[n] * m; // Σ w m, denominator of Eq. 17
			Real sg_g[D];
			stressTimesVector(sg, st.grad[n], sg_g);
			for (int a = 0; a < D; ++a) {
				Real mom = mv[a];
				for (int b = 0; b < D; ++b) mom += mC[a][b] * (dx[b] - st.dbar[b]);
				if constexpr (fused) nd.p[a] += eta * mom + dt * (-V * sg_g[a] + eta * fe[a]); // p + Δt f
				else {
					nd.p[a] += eta * mom;                 // momentum of the affine velocity field (Eq. 16)
					nd.f[a] += -V * sg_g[a] + eta * fe[a]; // Eq. 21 (f_int = −Σ V σ ∇ψ) + Eq. 22
				}
			}
		});
	}
	// G2P of a particle with a cut stencil: v_p = Σ η_i v_i, the velocity at x̄_p (Σ_p m_p v_p = Σ_i m_i v_i: momentum
	// conserved; exact for linear nodal fields at x̄_p), ∇v_p from the fit (Eq. 7). The position update adds
	// ∇v_p (x_p − x̄_p) (updateStress), so the particle moves with the velocity at x_p.
	// cached: P2G's fit of this particle (nullptr: fit again; P2G accepted it, so some node is active).
	template <bool flip>
	[[gnu::noinline]] void g2pCut(size_t p, const Kernel<D>& k, const Stencil<D>* cached, ErrorRecord& err)
	{
		Stencil<D> local;
		if (!cached && !fillStencil(grid, offs, k, local)) return err.record(p, noActiveNodeMessage);
		const Stencil<D>& st = cached ? *cached : local;
		const Real m = P.mass[p];
		Real       v[D] = {}, C[D][D] = {};
		forStencil(grid.vel.data(), offs, st, [&](const NodeVec<D>& nd, int n, const Real(&)[D]) {
			for (int a = 0; a < D; ++a) {
				v[a] += st.eta[n] * nd.c[a];                                    // Eq. 6 with positive weights
				for (int b = 0; b < D; ++b) C[a][b] += nd.c[a] * st.grad[n][b]; // Eq. 7
			}
		});
		if constexpr (flip) {
			Real vo[D] = {};
			forStencil(grid.vold.data(), offs, st, [&](const NodeVec<D>& nd, int n, const Real(&)[D]) {
				for (int a = 0; a < D; ++a) vo[a] += st.eta[n] * nd.c[a];
			});
			flipVelocity(p, v, vo, C);
		} else storeVelocity(p, v, C);
		forStencil(grid.mom.data(), offs, st, [&](NodeVec<D>& nd, int n, const Real(&dx)[D]) {
			const Real wm = st.w[n] * m;
			for (int a = 0; a < D; ++a) {
				Real h = v[a];
				for (int b = 0; b < D; ++b) h += C[a][b] * (dx[b] - st.dbar[b]);
				nd.c[a] += wm * h; // Eq. 16 numerator, h_p(x_i) = v_p + ∇v_p (x_i − x̄_p)
			}
		});
	}
	// FLIP: vg ← v (= Σ ψ_i v_i, the motion), v_p ← v_p + v − vo (the particle keeps what the grid cannot represent).
	void flipVelocity(size_t p, const Real (&v)[D], const Real (&vo)[D], const Real (&C)[D][D])
	{
		Real vf[D];
		for (int a = 0; a < D; ++a) vg[a][p] = v[a], vf[a] = P.v[a][p] + (v[a] - vo[a]);
		storeVelocity(p, vf, C);
	}
	// The stress-pass gather of a cut stencil (velocityGradient); cached: P2G's fit (nullptr: fit again).
	[[gnu::noinline]] bool velocityGradientCut(const Kernel<D>& k, const Stencil<D>* cached, Real (&L)[D][D], Real (&dbar)[D]) const
	{
		Stencil<D> local;
		if (!cached && !fillStencil(grid, offs, k, local)) return false;
		const Stencil<D>& st = cached ? *cached : local;
		for (int a = 0; a < D; ++a) dbar[a] = st.dbar[a];
		forStencil(grid.vmusl.data(), offs, st, [&](const NodeVec<D>& nd, int n, const Real(&)[D]) {
			for (int a = 0; a < D; ++a)
				for (int c = 0; c < D; ++c) L[a][c] += nd.c[a] * st.grad[n][c];
		});
		return true;
	}
	[[gnu::noinline, gnu::cold]] void recordOutside(size_t p, ErrorRecord& err) const
	{
		err.record(p, "has a position outside the grid or not finite: " + positionText(p));
	}
	// State written through the views without requestSort(): the first of the failed checks, named.
	[[gnu::noinline, gnu::cold]] void recordViewWrite(size_t p, const Real (&cellLo)[D], const Real (&cellHi)[D], ErrorRecord& err) const
	{
		const Real invH = 1.0 / grid.spacing, m = P.mass[p], V = P.vol[p];
		for (int a = 0; a < D; ++a) {
			const Real f = (P.x[a][p] - grid.origin[a]) * invH;
			if (!(f >= cellLo[a] && f < cellHi[a]))
				return err.record(p, "at " + positionText(p) + " lies beyond the cells its block may reach before a re-sort "
				                     "(moved through a view?): call solver.requestSort() after writing positions");
		}
		if (!(m > 0 && m < INFINITY)) return err.record(p, "has mass m = " + fmtNum(m) + " kg, must be finite and > 0 (written through a view?)");
		err.record(p, "has volume V = " + fmtNum(V) + " m³, must be finite and > 0 (written through a view?)");
	}

	void storeVelocity(size_t p, const Real (&v)[D], const Real (&C)[D][D])
	{
		for (int a = 0; a < D; ++a) {
			P.v[a][p] = v[a];
			for (int b = 0; b < D; ++b) P.C[a * D + b][p] = C[a][b];
		}
	}
};

} // namespace mpm
