// Boxes of grid nodes and particle blocks around a region (axis-aligned), for the passes that visit only
// the part of the grid near a rigid body (PtsContact): node and block coordinate ranges, iteration.
#pragma once
#include "BlockSchedule.hpp"

namespace mpm {

template <int D>
struct GridBoxes {
	using Vec  = typename Dim<D>::Vec;
	using IVec = typename Dim<D>::IVec;

	// Stored coordinates of the physical nodes within [lo, hi]; false when empty.
	static bool nodeRange(const Grid<D>& grid, const Vec& lo, const Vec& hi, IVec& nlo, IVec& nhi)
	{
		const int gh = Grid<D>::ghost;
		for (int a = 0; a < D; ++a) {
			Real fl = (lo[a] - grid.origin[a]) / grid.spacing, fh = (hi[a] - grid.origin[a]) / grid.spacing;
			fl      = std::max(fl, Real(0)), fh = std::min(fh, Real(grid.cells[a]));
			if (!(fl <= fh)) return false;
			nlo[a] = int(std::ceil(fl)) + gh, nhi[a] = int(std::floor(fh)) + gh;
			if (nlo[a] > nhi[a]) return false;
		}
		// a grid holding a window of layers (MPI rank, Grid::setWindow): the box clipped to it, possibly empty
		// (nhi < nlo: boxCount 0) but still true, so every rank takes the same decisions
		nlo[D - 1] = std::max(nlo[D - 1], grid.layer0), nhi[D - 1] = std::min(nhi[D - 1], grid.layerEnd - 1);
		if (nhi[D - 1] < nlo[D - 1]) nhi[D - 1] = nlo[D - 1] - 1;
		return true;
	}
	// Block coordinates whose particles may lie within [lo, hi]; false when the box misses the grid.
	static bool blockBox(const Grid<D>& grid, const BlockSchedule<D>& s, const Vec& lo, const Vec& hi, IVec& blo, IVec& bhi)
	{
		constexpr int B = BlockSchedule<D>::B, M = BlockSchedule<D>::margin;
		for (int a = 0; a < D; ++a) {
			Real fl = (lo[a] - grid.origin[a]) / grid.spacing - M, fh = (hi[a] - grid.origin[a]) / grid.spacing + M;
			fl      = std::max(fl, Real(0)), fh = std::min(fh, Real(grid.cells[a]));
			if (!(fl <= fh)) return false;
			blo[a] = std::min(int(fl) / B, s.nBlocks[a] - 1), bhi[a] = std::min(int(fh) / B, s.nBlocks[a] - 1);
		}
		return true;
	}
	// The same; false also when none of these blocks holds particles.
	static bool blockRange(const Grid<D>& grid, const BlockSchedule<D>& s, const Vec& lo, const Vec& hi, IVec& blo, IVec& bhi)
	{
		if (!blockBox(grid, s, lo, hi, blo, bhi)) return false;
		bool any = false;
		IVec bl = blo, bh = bhi;
		forBox(bl, bh, [&](const IVec& c) {
			size_t b = 0, st = 1;
			for (int a = 0; a < D; ++a) b += size_t(c[a]) * st, st *= s.nBlocks[a];
			any = any || s.start[b] != s.start[b + 1];
		});
		return any;
	}
	template <class F>
	static void forBox(const IVec& lo, const IVec& hi, F&& f)
	{
		IVec c = lo;
		while (true) {
			f(c);
			int a = 0;
			for (; a < D; ++a) {
				if (++c[a] <= hi[a]) break;
				c[a] = lo[a];
			}
			if (a == D) return;
		}
	}
	template <class F>
	static void forNodes(const Grid<D>& grid, const IVec& lo, const IVec& hi, F&& f)
	{
		if (!boxCount(lo, hi)) return;
		forBox(lo, hi, [&](const IVec& c) { f(grid.linear(c)); });
	}
	static size_t boxCount(const IVec& lo, const IVec& hi)
	{
		size_t n = 1;
		for (int a = 0; a < D; ++a) n *= size_t(std::max(hi[a] - lo[a] + 1, 0));
		return n;
	}
	static size_t boxNode(const Grid<D>& grid, const IVec& lo, const IVec& hi, size_t j)
	{
		size_t i = 0;
		for (int a = 0; a < D; ++a) {
			const size_t w = size_t(hi[a] - lo[a] + 1);
			i += size_t(lo[a] + int(j % w)) * grid.stride[a];
			j /= w;
		}
		return i - grid.offset;
	}
};

} // namespace mpm
