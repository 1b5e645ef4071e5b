// The two particle phases that close a step (paper Fig. 2): the constitutive update from the MUSL
// velocity gradient, then the position update with the stability and re-sort checks (run per block
// right after the block's stress update).
#pragma once
#include "../material/MaterialSet.hpp"
#include "Transfer.hpp"

namespace mpm {

// Velocity gradient from the MUSL nodal velocities (Eq. 7), strain increment (Eq. 29), Jaumann rotation,
// material update (Eqs. 27–40), volume V ← det(I + Δt∇v) V, block by block in parallel; after each block
// after(b, v2max, drift) runs on it (the position update: one parallel loop, the block still in cache).
// Returns the smallest dtDensity (for Δt) and what `after` reduced (max ‖v‖², drift). Failures (singular
// fit, non-finite stress, inverted volume) are recorded in err; the caller throws.
// Keep the particle loop where it is: the compiler's FMA contraction depends on its context (bit-identical results).
struct ParticleStepStats {
	Real dtDensityMin = INFINITY, v2max = 0; // min dtDensity (MaterialSet.hpp: ρ, or ρ/M in a mixed scene), max ‖v‖²
	int  drift  = 0;
};
template <int D, class Mat, class After>
inline ParticleStepStats updateStress(const Transfer<D>& tr, const Mat& mat, Real dt, ErrorRecord& err, After&& after)
{
	Particles<D>& P      = tr.P;
	const auto&   blocks = tr.sched.start;
	const long    nb     = long(blocks.size()) - 1;
	Real          rmin   = INFINITY, v2max = 0;
	int           drift  = 0;
	const KernelGeom<D> geo(tr.grid); // firstprivate: a local of each thread, not reloaded after the particle stores
#pragma omp parallel for schedule(dynamic, 4) reduction(min : rmin) reduction(max : v2max) reduction(| : drift) firstprivate(geo)
	for (long b = 0; b < nb; ++b) {
		const Stencil<D>* fits = tr.cuts.block(uint32_t(b)); // P2G's cut-stencil fits of this block, in order (or none)
		for (uint32_t pp = blocks[b]; pp < blocks[b + 1]; ++pp) {
			const size_t p = pp;
			Real L[D][D] = {}, dbar[D];
			bool cut;
			if (!tr.velocityGradient(geo, p, L, cut, dbar, fits)) {
				err.record(p, noActiveNodeMessage);
				continue;
			}
			if (cut) // v_p stands at x̄_p (Transfer::g2p): move with v_p + ∇v_p (x_p − x̄_p), the velocity at x_p
				for (int a = 0; a < D; ++a) {
					Real c = 0;
					for (int b = 0; b < D; ++b) c -= P.C[a * D + b][p] * dbar[b];
					P.x[a][p] += dt * c;
				}
			Sym<D> de; // Δε = sym(∇v) Δt, Eq. 29
			Sym<D> s = P.stress(p);
			strainIncrement(L, dt, de);
			jaumannRotation(L, dt, s);
			mat.update(P, p, s, de, dt); // Eqs. 27–40
			P.setStress(p, s);
			const Real J = jacobian(L, dt);
			P.vol[p] = std::min(P.vol[p] * J, mat.volumeLimit(P, p)); // a failed particle bulks at most to failedBulking × V₀
			Real check = J; // one sum carries every value that must be finite (NaN/inf propagate)
			for (int k = 0; k < Dim<D>::nSym; ++k) check += s.c[k];
			if (!(std::isfinite(check) && J > 0)) {
				static const char* comp[6] = { "xx", "yy", "zz", "xy", "xz", "yz" };
				std::string        what    = "has non-positive volume change det(I + Δt∇v) = " + fmtNum(J) + " (element inverted)";
				for (int k = Dim<D>::nSym - 1; k >= 0; --k)
					if (!std::isfinite(s.c[k])) what = std::string("has non-finite stress σ") + comp[k] + " = " + fmtNum(s.c[k]);
				err.record(p, what);
				continue;
			}
			rmin = std::min(rmin, dtDensity(mat, P, p)); // ρ (one material) or ρ/M (mixed), for Δt
		}
		after(uint32_t(b), v2max, drift);
	}
	return { rmin, v2max, drift };
}


// The messages of moveParticles for the particles of [p0, p1) that failed (rare; positions already moved).
template <int D>
inline void recordMoveFailures(const Particles<D>& P, const Grid<D>& grid, uint32_t p0, uint32_t p1, ErrorRecord& err)
{
	const auto lo = grid.origin, hi = grid.upper(), alo = grid.allowedLo, ahi = grid.allowedHi;
	for (uint32_t pp = p0; pp < p1; ++pp) {
		const size_t p  = pp;
		Real         sp = 0, check = 0;
		for (int a = 0; a < D; ++a) sp += P.v[a][p] * P.v[a][p], check += P.x[a][p];
		if (!(std::isfinite(check) && std::isfinite(sp))) {
			std::string what = "has a non-finite position";
			for (int a = D - 1; a >= 0; --a)
				if (!std::isfinite(P.v[a][p])) what = "has non-finite velocity component " + std::to_string(a) + " = " + fmtNum(P.v[a][p]);
			err.record(p, what);
			continue;
		}
		for (int a = 0; a < D; ++a)
			if (P.x[a][p] < lo[a] || P.x[a][p] >= hi[a]) {
				err.recordLeft(p); // not a failure yet: the solver's outside policy decides (Solver::settleLeaving)
				break;
			} else if (P.x[a][p] < alo[a] || P.x[a][p] >= ahi[a]) {
				err.record(p, "crossed a boundary plane along axis " + std::to_string(a) + " at x = " + fmtNum(P.x[a][p]) + " m (allowed: ["
				                      + fmtNum(alo[a]) + ", " + fmtNum(ahi[a]) + ") m)");
				break;
			}
	}
}

// The grid face particle p left through (position past the grid's edge): 2·axis + (1 if past the upper end),
// the first axis along which it is outside; −1 if it is on the grid.
template <int D>
inline int exitFace(const Particles<D>& P, const Grid<D>& grid, size_t p)
{
	const auto lo = grid.origin, hi = grid.upper();
	for (int a = 0; a < D; ++a)
		if (P.x[a][p] < lo[a] || P.x[a][p] >= hi[a]) return 2 * a + (P.x[a][p] >= hi[a] ? 1 : 0);
	return -1;
}
inline std::string faceName(int f) { return f < 0 ? "none" : std::string(1, "xyz"[f / 2]) + (f % 2 ? "+" : "-"); }

// The message of a particle that left the grid (the run stops): axis, face, the coordinate and the whole position.
template <int D>
inline std::string leftGridMessage(const Particles<D>& P, const Grid<D>& grid, size_t p)
{
	const int         f = exitFace(P, grid, p), a = f / 2;
	const auto        lo = grid.origin, hi = grid.upper();
	std::string       pos = "(";
	for (int b = 0; b < D; ++b) pos += (b ? ", " : "") + fmtNum(P.x[b][p]);
	return "left the grid along axis " + std::to_string(a) + " through its " + faceName(f) + " face at x = " + fmtNum(P.x[a][p]) + " m, position " + pos
	       + ") m (grid spans [" + fmtNum(lo[a]) + ", " + fmtNum(hi[a]) + ") m along axis " + std::to_string(a) + ")";
}

// x ← x + Δt v (the G2P velocity; flip: Σ ψ_i v_i, Transfer::vg) for the particles of block b. Checks that each
// stays finite and on the grid cut by the boundary planes (else err; a particle past the grid's edge goes to
// err.left, for the solver's outside policy) and within the cells its block may reach before a re-sort
// (BlockSchedule::reach): drift is set when one left them, so the deterministic colouring stays valid.
// Raises v2max to the largest ‖v_p‖² (for Δt). A branch-free loop over the arrays; the messages are built
// only when a particle failed.
template <int D>
inline void moveParticles(const Transfer<D>& tr, Real dt, uint32_t b, bool flip, Real& v2max, int& drift, ErrorRecord& err)
{
	Particles<D>&  P    = tr.P;
	const Grid<D>& grid = tr.grid;
	const uint32_t p0 = tr.sched.start[b], p1 = tr.sched.start[b + 1];
	Real           lo[D], alo[D], ahi[D], cellLo[D], cellHi[D];
	Real*          x[D];
	const Real *   u[D], *v[D]; // the velocity of the motion, the particle's velocity (the same array under PIC)
	tr.sched.reach(b, cellLo, cellHi); // cells a particle of block b may reach before a re-sort
	for (int a = 0; a < D; ++a) {
		lo[a] = grid.origin[a], alo[a] = grid.allowedLo[a], ahi[a] = grid.allowedHi[a]; // the grid cut by the boundary planes
		x[a] = P.x[a].data(), v[a] = P.v[a].data(), u[a] = flip ? tr.vg[a].data() : v[a];
	}
	const Real invH = 1.0 / grid.spacing;
	Real       vm = v2max;
	int        bad = 0, far = 0;
	for (uint32_t p = p0; p < p1; ++p) {
		Real sp = 0, check = 0;
		int  out = 0, nf = 0;
		for (int a = 0; a < D; ++a) {
			const Real va = v[a][p], xa = x[a][p] + dt * u[a][p];
			x[a][p] = xa;
			sp += va * va; // Δt's max ‖v‖ from v_p, the state a resumed run starts from
			check += xa;
			out |= !(xa >= alo[a] && xa < ahi[a]);
			const Real f = (xa - lo[a]) * invH;
			nf |= !(f >= cellLo[a] && f < cellHi[a]);
		}
		bad |= out | !(check - check == 0 && sp - sp == 0); // y − y ≠ 0: y is NaN or ±inf
		far |= nf;
		vm = std::max(vm, sp);
	}
	v2max = vm, drift |= far;
	if (bad) recordMoveFailures(P, grid, p0, p1, err);
}

} // namespace mpm
