// Which MPI rank owns which particles and nodes (doc/scaling.md): slabs of whole block layers along the last axis
// (y in 2D, z in 3D), rank r owning the block layers [first[r], first[r+1]) and their particles; the nodes a rank
// touches are one contiguous index range. Two neighbours share the 2·margin + 3 = 5 node layers around their
// boundary (a particle drifts ≤ margin cells out of its block before a re-sort, its stencil spans 4 nodes).
#pragma once
#include "../core/BlockSchedule.hpp"
#include <algorithm>
#include <string>
#include <vector>

namespace mpm {

template <int D>
struct SlabLayout {
	static constexpr int axis = D - 1, B = BlockSchedule<D>::B, margin = BlockSchedule<D>::margin, ghost = Grid<D>::ghost;
	static_assert(B > 2 * margin + 2, "the shared node bands of one rank must not overlap");

	std::vector<int> first; // first[r]: first block layer of rank r; first[R] = number of block layers

	int ranks() const { return int(first.size()) - 1; }
	static int layers(const Grid<D>& g) { return (g.cells[axis] + B - 1) / B; }
	// Block layer of a particle at coordinate x along the slab axis (BlockSchedule::blockOf's clamp).
	static int layerOf(const Grid<D>& g, Real x)
	{
		const int c = int(std::floor((x - g.origin[axis]) / g.spacing)) / B;
		return std::min(std::max(c, 0), layers(g) - 1);
	}
	int owner(int layer) const { return int(std::upper_bound(first.begin() + 1, first.end() - 1, layer) - (first.begin() + 1)); }

	// Load-balance rule: rank r starts at the block layer whose count of particles below it is nearest
	// to r·N/R (ties: the lower layer), keeping at least one layer per rank. count[c]: particles of layer c.
	static SlabLayout balanced(const std::vector<double>& count, int R)
	{
		const int L = int(count.size());
		if (R < 1 || R > L)
			throw InputError("MPI ranks = " + std::to_string(R) + " must be in [1, " + std::to_string(L) + "]: each rank owns at least one layer of "
			                 + std::to_string(B) + "-cell blocks along axis " + std::to_string(axis) + " (use fewer ranks or a longer grid along that axis)");
		std::vector<double> cum(size_t(L) + 1, 0.0);
		for (int c = 0; c < L; ++c) cum[size_t(c) + 1] = cum[size_t(c)] + count[size_t(c)];
		SlabLayout s;
		s.first.assign(size_t(R) + 1, 0);
		s.first[size_t(R)] = L;
		for (int r = 1; r < R; ++r) {
			const double target = cum[size_t(L)] * r / R;
			int          c      = int(std::lower_bound(cum.begin(), cum.end(), target) - cum.begin());
			if (c > 0 && target - cum[size_t(c) - 1] <= cum[std::min(size_t(c), size_t(L))] - target) --c; // the nearer of the two
			s.first[size_t(r)] = std::min(std::max(c, s.first[size_t(r) - 1] + 1), L - (R - r));
		}
		return s;
	}

	// Stored node layers [lo, hi] along the slab axis that rank r's particles reach (clamped to the grid).
	void reachedLayers(const Grid<D>& g, int r, int& lo, int& hi) const
	{
		lo = std::max(first[size_t(r)] * B - margin - 1 + ghost, 0);
		hi = std::min(first[size_t(r) + 1] * B + margin + 1 + ghost, int(g.stored[axis]) - 1);
	}
	// Stored node layers [lo, hi] shared by ranks r − 1 and r (r ≥ 1).
	void sharedLayers(const Grid<D>& g, int r, int& lo, int& hi) const
	{
		lo = first[size_t(r)] * B - margin - 1 + ghost;
		hi = std::min(first[size_t(r)] * B + margin + 1 + ghost, int(g.stored[axis]) - 1);
	}
	// Local node index range [i0, i1) of stored layers [lo, hi] (inside the grid's window, Grid::setWindow).
	static void nodeRange(const Grid<D>& g, int lo, int hi, size_t& i0, size_t& i1)
	{
		i0 = size_t(lo) * g.stride[axis] - g.offset, i1 = size_t(hi + 1) * g.stride[axis] - g.offset;
	}

	// Symmetry planes normal to the slab axis fold the 2 node layers beyond them onto the 2 inside: that band
	// must lie inside the reach of every rank that touches it (a fold needs the whole sums). Throws otherwise.
	void checkMirrors(const Grid<D>& g) const
	{
		for (const auto& p : g.planes) {
			if (p.kind != BoundaryKind::Slip || p.axis != axis) continue;
			const int twoP = int(std::lround(2 * (p.position - g.origin[axis]) / g.spacing)) + 2 * ghost;
			const int bLo = twoP / 2 - 2, bHi = (twoP + 1) / 2 + 2;
			for (int r = 0; r < ranks(); ++r) {
				int lo, hi;
				reachedLayers(g, r, lo, hi);
				const bool touches = bLo <= hi && bHi >= lo, inside = bLo >= lo && bHi <= hi;
				if (touches && !inside)
					throw InputError("MPI: the 'slip' plane at " + fmtNum(p.position) + " m along axis " + std::to_string(axis)
					                 + " lies within 2 cells of the boundary between two ranks' slabs; use another rank count or move the plane");
			}
		}
	}
};

} // namespace mpm
