// MPI domain decomposition of one scene (MPI build only, module yade_mpm._core_mpi; doc/scaling.md). Every rank
// builds the same scene; at the first step each keeps the particles of its slab (SlabLayout) and drops the others.
// Then: particles migrate to the rank of their block layer at each re-sort, the shared node bands are summed
// (HaloExchange), the Δt limits are global, and a phase that failed on one rank stops every rank.
#pragma once
#include "HaloExchange.hpp"
#include "ParticlePack.hpp"
#include <malloc.h>
#include <unistd.h>

#ifdef MPM_MPI
namespace mpm {

template <int D>
class Decomposition {
	using Pack = ParticlePack<D>;

public:
	const int       rank = Comm::rank(), R = Comm::size();
	SlabLayout<D>   layout;
	HaloExchange<D> halo;
	bool            decomposed = false;
	size_t          migrated   = 0; // particles sent by this rank since the split

	bool   building = false; // distributed construction (distribute): this rank keeps only its slab's particles
	size_t builtIds = 0;     // particles added over all ranks so far under distributed construction: the next global id

	bool distributed() const { return R > 1; }
	// Distributed construction, before any particle exists: the slabs start evenly (block layers split by
	// count), the grid keeps this rank's window of them, and every later addParticles keeps only the particles
	// of this rank's slab (clip), with the global running index as id (the ids of 1 process). add_region sets
	// the start layout from its lattice counts first (plan); the first step re-cuts by the particle counts
	// (the start rule) and moves particles to their owners.
	void distribute(Grid<D>& g, size_t particles)
	{
		if (!distributed() || building) return;
		if (decomposed) throw InputError("mpiDistribute: the solver has stepped already; call it right after creating the solver");
		if (particles)
			throw InputError("mpiDistribute: this rank holds " + std::to_string(particles) + " particles already; call it before adding particles");
		layout = SlabLayout<D>::balanced(std::vector<double>(size_t(SlabLayout<D>::layers(g)), 1.0), R); // even: one per layer
		int lo, hi;
		layout.reachedLayers(g, rank, lo, hi);
		const double nodes = double(hi + 1 - lo) * double(g.stride[D - 1]), bytes = nodes * (sizeof(Node<D>) + 2),
		             phys = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
		if (bytes > phys) // as the solver's constructor refuses a whole grid the machine cannot hold
			throw InputError("mpiDistribute: this rank's grid window of " + fmtNum(nodes) + " nodes needs " + fmtNum(bytes / 1e9) + " GB, more than this machine's "
			                 + fmtNum(phys / 1e9) + " GB of memory; use more ranks, fewer cells or a larger spacing");
		g.setWindow(lo, hi + 1);
		malloc_trim(0);                        // the whole grid's arrays (if it was allocated) go back to the system
		mallopt(M_MMAP_THRESHOLD, 1 << 20); // fixed: arrays ≥ 1 MB are mapped and go back when freed (no heap high-water)
		building = true;
	}
	// Distributed construction: appends of the n particles at x (x[p·D + a]) those of this rank's slab, with the
	// global running index as id (a non-finite coordinate stays on rank 0, whose check names it). False if none.
	bool appendOwn(const Grid<D>& g, Particles<D>& P, const Real* x, const Real* vol, const Real* mass, size_t n, uint8_t material)
	{
		std::vector<size_t> kept;
		for (size_t p = 0; p < n; ++p) {
			const Real z = x[p * D + D - 1];
			if (std::isfinite(z) ? layout.owner(SlabLayout<D>::layerOf(g, z)) == rank : rank == 0) kept.push_back(p);
		}
		const size_t old = P.n, first = builtIds;
		builtIds += n;
		if (kept.empty()) return false;
		std::vector<Real> xk(kept.size() * D), vk(kept.size()), mk(kept.size());
		for (size_t k = 0; k < kept.size(); ++k) {
			for (int a = 0; a < D; ++a) xk[k * D + a] = x[kept[k] * D + a];
			vk[k] = vol[kept[k]], mk[k] = mass[kept[k]];
		}
		P.reserve(P.n + kept.size()); // exact growth: a doubling vector would hold up to 2× the rank's particles
		P.append(xk.data(), vk.data(), mk.data(), kept.size(), g.origin, g.upper(), material);
		for (size_t k = 0; k < kept.size(); ++k) P.id[old + k] = int64_t(first + kept[k]); // the id of 1 process
		return true;
	}
	// Distributed construction, before a region's particles are added (add_region counts them first): count[c]
	// = the region's particles in block layer c, the same on every rank (checked). The scene's first particles
	// set the start layout from their counts (SlabLayout::balanced: each rank starts near N/R, the first step
	// moves few particles) and the grid window; every region reserves this rank's share of it at once, which
	// moves the arrays: refused on every rank while a NumPy view of them is alive on any (liveViews).
	void plan(Grid<D>& g, Particles<D>& P, const std::vector<double>& count, size_t liveViews)
	{
		const int L = SlabLayout<D>::layers(g);
		if (!building) throw InputError("mpiPlan: the solver is not under distributed construction (yade_mpm.parallel.distribute)");
		if (int(count.size()) != L) throw InputError("mpiPlan: counts has " + std::to_string(count.size()) + " entries; expected " + std::to_string(L) + " (one per block layer)");
		double sum[2] = { 0, 0 }, neg[2];
		for (int c = 0; c < L; ++c) {
			if (!(count[size_t(c)] >= 0 && std::isfinite(count[size_t(c)])))
				throw InputError("mpiPlan: counts[" + std::to_string(c) + "] = " + fmtNum(count[size_t(c)]) + " must be a finite count in [0, inf)");
			sum[0] += count[size_t(c)], sum[1] += count[size_t(c)] * (c + 1);
		}
		neg[0] = -sum[0], neg[1] = -sum[1];
		double views = double(liveViews);
		Comm::max(sum, 2), Comm::max(neg, 2), Comm::max(&views, 1);
		if (sum[0] != -neg[0] || sum[1] != -neg[1]) throw InputError("mpiPlan: the ranks passed different counts (every rank must count the whole region)");
		if (views > 0)
			throw InputError("add_region: NumPy view(s) of the particle arrays are alive (" + fmtNum(views) + " on some rank) and adding particles under "
			                 "distributed construction moves the arrays they point to; delete the views first (del v)");
		if (builtIds == 0) {
			layout = SlabLayout<D>::balanced(count, R);
			int lo, hi;
			layout.reachedLayers(g, rank, lo, hi);
			g.setWindow(lo, hi + 1);
			malloc_trim(0);
		}
		double own = 0;
		for (int c = layout.first[size_t(rank)]; c < layout.first[size_t(rank) + 1]; ++c) own += count[size_t(c)];
		P.reserve(P.n + size_t(own)); // the arrays grow once per region (appendOwn's chunks then fit)
	}
	bool needsSplit() const { return R > 1 && !decomposed; } // the first step on > 1 rank always sorts (and splits)

	// Refuses, before any work, what this build does not distribute yet (the same answer on every rank).
	void checkStep(size_t liveViews) const
	{
		if (!distributed()) return;
		if (liveViews)
			throw InputError("MPI: " + std::to_string(liveViews) + " NumPy view(s) of the particle arrays are alive; particles migrate between ranks and the "
			                 "arrays change length: delete the views before stepping (del v) and take new ones after");
	}

	// What needs the whole scene on every rank is refused once the ranks hold their own particles.
	void refuseAfterSplit(const char* what) const
	{
		if (building && !decomposed && std::string(what).rfind("addParticles", 0) != 0)
			throw InputError(std::string("MPI: ") + what + " is not supported under distributed construction (yade_mpm.parallel.distribute): each rank "
			                 "holds only its slab's particles; build the scene without distribute");
		if (decomposed)
			throw InputError(std::string("MPI: ") + what + " after the first step is not supported on " + std::to_string(R)
			                 + " ranks: each rank holds only its slab's particles now (doc/scaling.md)");
	}
	// Checkpoint resume (py/yade_mpm/checkpoint.py) into the freshly built scene: the saved slab layout, and the
	// particle arrays sized to the rank's saved count n (the caller then writes the saved values). A replicated scene
	// holds every particle (cut to n); a distributed one holds its start slab's (cut or grown to n, zero-filled), with
	// the optional fields the piece has (opt: traction, damage state, flaw counts; ParticlePack::ensureFields).
	void restore(Grid<D>& g, Particles<D>& P, const std::vector<int>& first, size_t n, const double* opt)
	{
		if (decomposed) throw InputError("MPI checkpoint resume: the solver has stepped already; load the checkpoint into the freshly built scene");
		if (int(first.size()) != R + 1)
			throw InputError("MPI checkpoint resume: the checkpoint's slab layout has " + std::to_string(int(first.size()) - 1) + " ranks, this run has " + std::to_string(R));
		if (n > P.n && !building)
			throw InputError("MPI checkpoint resume: " + std::to_string(n) + " particles saved on this rank, the scene has " + std::to_string(P.n));
		SlabLayout<D> L;
		L.first = first;
		for (int r = 0; r < R; ++r)
			if (!(first[size_t(r)] < first[size_t(r) + 1]) || first[0] != 0 || first[size_t(R)] != SlabLayout<D>::layers(g))
				throw InputError("MPI checkpoint resume: the saved slab layout does not fit this grid");
		L.checkMirrors(g);
		layout = L;
		if (n < P.n) {
			std::vector<uint8_t> go(P.n, 0);
			for (size_t p = n; p < P.n; ++p) go[p] = 1;
			Pack::keep(P, go);
		} else if (n > P.n) { // distributed construction: this rank's start slab held fewer than its saved piece
			P.n = n;
			P.forEachRealField([&](std::vector<Real>& f) { f.resize(n, 0.0); });
			P.id.resize(n), P.mat.resize(n);
		}
		Pack::ensureFields(P, opt);
		settle(g);
	}
	// Before the counting sort: the first call splits the (replicated) scene, later calls re-balance (when the
	// busiest rank holds more than `threshold` × the mean particle count) and migrate.
	void migrate(Grid<D>& g, Particles<D>& P, Real threshold)
	{
		if (!distributed()) return;
		if (!decomposed) return split(g, P);
		if (!rebalance(g, P, threshold)) {
			hop(g, P, true);
			return;
		}
		// After a re-cut a particle may belong to a rank several slabs away: it hops one neighbour per pass
		// (≤ R − 1 passes; every rank takes part in every pass, so none waits in a collective).
		for (int pass = 0; pass < R - 1; ++pass)
			if (!hop(g, P, false)) break;
	}
	size_t rebalances = 0;     // re-cuts of the slabs since the split
	Real   imbalance  = 1;     // max / mean of the per-rank particle counts at the last re-sort (after any re-cut)

	// Dynamic load balance (doc/scaling.md), at every re-sort: the particle counts per block layer are summed
	// over the ranks (integers in doubles: exact, the same on every rank; one MPI_Allreduce of a few dozen
	// doubles); when max/mean of the per-rank counts exceeds the threshold (inf: never), the slabs are cut
	// again by the start rule (SlabLayout::balanced). A new cut that would put a
	// symmetry plane across a slab boundary is not taken (the same answer on every rank). True if re-cut.
	bool rebalance(Grid<D>& g, const Particles<D>& P, Real threshold)
	{
		std::vector<double> count = layerCounts(g, P);
		Comm::sum(count.data(), int(count.size()));
		imbalance = imbalanceOf(layout, count);
		if (!(imbalance > threshold)) return false;
		SlabLayout<D> cut = SlabLayout<D>::balanced(count, R);
		if (cut.first == layout.first) return false;
		try {
			cut.checkMirrors(g);
		} catch (const InputError&) {
			return false;
		}
		layout = cut;
		settle(g);
		imbalance = imbalanceOf(layout, count);
		++rebalances;
		return true;
	}
	// max / mean of the per-rank particle counts of a layout (1 for no particles).
	Real imbalanceOf(const SlabLayout<D>& s, const std::vector<double>& count) const
	{
		double total = 0, most = 0;
		for (int r = 0; r < R; ++r) {
			double n = 0;
			for (int c = s.first[size_t(r)]; c < s.first[size_t(r) + 1]; ++c) n += count[size_t(c)];
			total += n, most = std::max(most, n);
		}
		return total > 0 ? most * R / total : 1;
	}

	// One migration pass: particles whose block layer belongs to another rank move one rank towards it.
	// strict: a particle must not be more than one slab away (no re-cut since the last re-sort). Returns
	// whether any particle on any rank moved.
	bool hop(Grid<D>& g, Particles<D>& P, bool strict)
	{
		std::vector<uint8_t> go;
		bool                 ok, more;
		size_t               nd, nu;
		mark(g, P, go, ok, nd, nu, more);
		if (strict && !Comm::all(ok)) throw SimulationError("MPI: a particle moved past a neighbouring rank's slab between two re-sorts (lower sortPeriod)");
		if (!strict && Comm::all(nd + nu == 0)) return false;
		double opt[3] = { double(P.hasTraction()), double(P.hasDamageState()), double(!P.nFlaw.empty()) };
		Comm::max(opt, 3); // the optional fields some rank holds: every rank sends and receives them (zero where absent)
		Pack::ensureFields(P, opt);
		const size_t nf = size_t(2 + 2 * D + D * D + 3 + Particles<D>::NS) + size_t(opt[0] > 0) * D + size_t(opt[1] > 0) * 3 + size_t(opt[2] > 0);
		std::vector<double> sd, su, rd, ru;
		while (true) { // rounds of at most `batch` particles per direction (one round unless many move)
			std::vector<double> cd { double(nd) }, cu { double(nu) };
			rd.assign(1, 0.0), ru.assign(1, 0.0);
			Comm::neighbours(rank - 1, rank + 1, cd, rd, cu, ru); // counts first
			const size_t ad = rank > 0 ? size_t(rd[0]) : 0, au = rank + 1 < R ? size_t(ru[0]) : 0;
			sd.clear(), su.clear(), sd.reserve(nd * nf), su.reserve(nu * nf);
			for (size_t p = 0; p < P.n; ++p)
				if (go[p]) Pack::pack(P, p, go[p] == 1 ? sd : su);
			rd.assign(ad * nf, 0.0), ru.assign(au * nf, 0.0);
			Comm::neighbours(rank - 1, rank + 1, sd, rd, su, ru);
			Pack::keep(P, go);
			Pack::unpack(P, rd, ad, nf, opt), Pack::unpack(P, ru, au, nf, opt); // arrivals from below, then from above: a fixed order
			migrated += nd + nu;
			if (Comm::all(!more)) return true;
			mark(g, P, go, ok, nd, nu, more);
		}
	}
	// Migration in rounds of at most `batch` particles per direction: the send and receive buffers stay bounded
	// (≈ 15 MB in 3D) when a re-cut moves a large part of a rank's particles (distributed construction).
	static constexpr size_t batch = size_t(1) << 16;
	// go[p]: 0 stays, 1 to rank − 1, 2 to rank + 1, for at most `batch` particles per direction (nd, nu: marked;
	// more: some were left for another round); ok: every mover belongs to a neighbour.
	void mark(const Grid<D>& g, const Particles<D>& P, std::vector<uint8_t>& go, bool& ok, size_t& nd, size_t& nu, bool& more) const
	{
		go.assign(P.n, 0);
		ok = true, more = false, nd = nu = 0;
		for (size_t p = 0; p < P.n; ++p) {
			const int o = layout.owner(SlabLayout<D>::layerOf(g, P.x[D - 1][p]));
			if (o == rank) continue;
			ok          = ok && (o == rank - 1 || o == rank + 1);
			size_t& cnt = o < rank ? nd : nu;
			if (cnt == batch) {
				more = true;
				continue;
			}
			go[p] = o < rank ? 1 : 2, ++cnt;
		}
	}

	// Global limits for Δt and the mass floor (Solver::prepare); empty ranks contribute ±inf / 0.
	void reduceLimits(Real& dtDensityMin, Real& vmax, Real& massFloor) const
	{
		if (!distributed()) return;
		double v[3] = { -dtDensityMin, vmax, -massFloor };
		Comm::max(v, 3);
		dtDensityMin = -v[0], vmax = v[1], massFloor = -v[2];
	}
	// End of step: global ρ_min, max ‖v‖², re-sort flag, particles that left the grid; a failure of the particle pass on any rank stops all.
	void reduceStep(Real& dtDensityMin, Real& v2max, int& drift, ErrorRecord& errStress, ErrorRecord& errMove) const
	{
		if (!distributed()) return;
		double v[5] = { -dtDensityMin, v2max, double(drift), errStress.none() && errMove.none() ? 0.0 : 1.0, errMove.left.empty() ? 0.0 : 1.0 };
		Comm::max(v, 5);
		dtDensityMin = -v[0], v2max = v[1], drift = int(v[2]);
		errMove.leftAnywhere = v[4] > 0; // a particle left the grid on some rank: every rank settles it (Solver::settleLeaving)
		if (v[3] > 0 && errStress.none() && errMove.none())
			errMove.record(ErrorRecord::elsewhere, "stopped: the stress or position update of another MPI rank failed (its message names the particle)");
	}
	// Runs a validation on every rank; if it threw on any, every rank throws (its own message or a pointer to it).
	template <class F>
	void agree(F&& validate) const
	{
		std::string bad;
		try {
			validate();
		} catch (const InputError& e) {
			bad = e.what();
		}
		if (Comm::all(bad.empty())) return;
		throw InputError(bad.empty() ? "MPI: the particle check failed on another rank (its message names the particle)" : bad);
	}
	Real sum(Real v) const
	{
		if (distributed()) Comm::sum(&v, 1);
		return v;
	}
	// Sums over nodes (body reactions, PenaltyContact): node i is counted by one rank, the owner of the block layer
	// of the cells above it (the nodes [ownedLo, ownedHi) of the slab; the ghost layers go to the end ranks).
	bool ownsNode(size_t i) const { return !decomposed || (i >= ownedLo && i < ownedHi); }
	// v ← the sum of every rank's v in rank order (the same bits on every rank); called by one thread.
	void sumInRankOrder(double* v, int n)
	{
		if (distributed()) Comm::sumInRankOrder(v, n, gathered);
	}

private:
	// First step: the same particles on every rank (checked: count and a position checksum); slabs from
	// the particle counts per block layer; each rank keeps its own.
	void split(Grid<D>& g, Particles<D>& P)
	{
		if (building) { // each rank holds its slab of the even start layout: re-cut by the global counts, move
			std::vector<double> count = layerCounts(g, P);
			Comm::sum(count.data(), int(count.size()));
			SlabLayout<D> cut = SlabLayout<D>::balanced(count, R);
			cut.checkMirrors(g);
			layout = cut;
			for (int pass = 0; pass < R - 1; ++pass)
				if (!hop(g, P, false)) break;
			P.shrink();
			settle(g);
			return;
		}
		double s = 0;
		for (size_t p = 0; p < P.n; ++p) s += P.x[D - 1][p] + 0.5 * P.x[0][p] + 1e-3 * double(P.id[p]);
		double hiv[3] = { double(P.n), s, double(Pack::fieldCount(P)) }, lov[3] = { -hiv[0], -hiv[1], -hiv[2] };
		Comm::max(hiv, 3), Comm::max(lov, 3);
		if (hiv[0] != -lov[0] || hiv[1] != -lov[1] || hiv[2] != -lov[2])
			throw InputError("MPI: every rank must build the same scene before the first step (the script runs on every rank); the ranks hold "
			                 "different particles (counts " + fmtNum(-lov[0]) + " to " + fmtNum(hiv[0]) + ")");
		layout = SlabLayout<D>::balanced(layerCounts(g, P), R); // the scene is replicated: local counts are global
		layout.checkMirrors(g);
		std::vector<uint8_t> go(P.n, 0);
		for (size_t p = 0; p < P.n; ++p) go[p] = layout.owner(SlabLayout<D>::layerOf(g, P.x[D - 1][p])) != rank;
		Pack::keep(P, go);
		P.shrink(); // the other ranks' particles: their memory goes back
		settle(g);
	}
	// The layout in force: the grid keeps the node layers this rank's particles reach (its window, re-allocated
	// when the cut moved) and the nodes it counts in sums over nodes.
	void settle(Grid<D>& g)
	{
		const int    ax = D - 1, B = SlabLayout<D>::B, gh = Grid<D>::ghost;
		const size_t st = g.stride[ax];
		int          lo, hi;
		layout.reachedLayers(g, rank, lo, hi);
		g.setWindow(lo, hi + 1);
		ownedLo = rank == 0 ? g.offset : size_t(layout.first[size_t(rank)] * B + gh) * st;
		ownedHi = rank + 1 == R ? g.globalSize() : size_t(layout.first[size_t(rank) + 1] * B + gh) * st;
		ownedLo -= g.offset, ownedHi -= g.offset; // local indices
		decomposed = true;
		malloc_trim(0); // freed arrays (the old window, dropped particles, migration buffers) go back to the system
	}
	// This rank's particle count per block layer along the slab axis (the input of SlabLayout::balanced).
	static std::vector<double> layerCounts(const Grid<D>& g, const Particles<D>& P)
	{
		std::vector<double> count(size_t(SlabLayout<D>::layers(g)), 0.0);
		for (size_t p = 0; p < P.n; ++p) count[size_t(SlabLayout<D>::layerOf(g, P.x[D - 1][p]))] += 1;
		return count;
	}
	size_t              ownedLo = 0, ownedHi = 0; // nodes counted by this rank in sums over nodes (ownsNode)
	std::vector<double> gathered;                 // scratch of sumInRankOrder
};

} // namespace mpm
#endif
