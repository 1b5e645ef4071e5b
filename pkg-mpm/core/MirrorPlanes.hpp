// Symmetry ('slip') boundary planes by reflected images (doc/boundaries.md): after a scatter the nodes within
// 2 cells on the material side add their partner's reflected content (fold), after a nodal update the nodes beyond
// take their partner's reflection (unfold), so the nodal field is that of the mirror-symmetric full-space problem.
// fold/unfold are orphaned OpenMP loops inside the step's region. Coordinates are stored (ghost-shifted) indices.
#pragma once
#include "GridNode.hpp"
#include <vector>

namespace mpm {

template <int D>
class MirrorPlanes {
public:
	using IVec = typename Dim<D>::IVec;

	// A symmetry plane in stored index units: node line k pairs with k' = twoP − k.
	struct Mirror {
		int                 axis, side, twoP;
		size_t              stride;        // linear-index stride along axis
		int                 nStored;       // stored nodes along axis
		int                 physLo, physHi; // stored index range of the physical nodes along axis
		std::vector<size_t> columns;       // linear index of the first node (coordinate 0 along axis) of every node line along axis
		int                 nPairs = 0, pairK[3], pairKp[3]; // node lines within 2 cells on the material side and their partners
	};

	bool empty() const { return list.empty(); }
	void clear() { list.clear(), groups.clear(); }
	// The plane along `axis` with material on `side` (-1: above, +1: below) at stored half-index twoP,
	// on grid g (Grid<D>: size, coords, stride, stored, cells, ghost).
	template <class G>
	void add(const G& g, int axis, int side, int twoP)
	{
		Mirror m;
		m.axis = axis, m.side = side, m.twoP = twoP;
		m.stride = g.stride[axis], m.nStored = g.stored[axis];
		m.physLo = G::ghost, m.physHi = g.cells[axis] + G::ghost;
		// the grid may hold a window of layers along the last axis (Grid::setWindow): a column's index is that of
		// coordinate 0 (wrapping size_t arithmetic), and only pairs inside the window are kept
		const int kLo = axis == D - 1 ? g.layer0 : 0, kHi = axis == D - 1 ? g.layerEnd : m.nStored;
		for (size_t i = 0; i < g.size(); ++i)
			if (g.coords(i)[axis] == kLo) m.columns.push_back(i - size_t(kLo) * m.stride);
		for (int k = kLo; k < kHi; ++k) {
			const int d2 = -side * (2 * k - twoP), kp = twoP - k; // ≥ 0 on the material side (half cells)
			if (d2 >= 0 && d2 < 4 && kp >= kLo && kp < kHi && m.nPairs < 3) m.pairK[m.nPairs] = k, m.pairKp[m.nPairs++] = kp;
		}
		list.push_back(std::move(m));
		const Mirror& added = list.back();
		if (groups.empty() || list[groups.back().first].axis != axis) groups.push_back({ list.size() - 1, 0, {}, {} });
		Group& g2 = groups.back();
		for (int j = 0; j < added.nPairs; ++j) g2.k[g2.n] = added.pairK[j], g2.kp[g2.n] = added.pairKp[j], ++g2.n;
	}

	// Fold after a scatter: nodes within 2 cells on the material side add their partner's reflection.
	// E: Node<D> (after P2G, all lanes) or NodeVec<D> (the MUSL momentum after G2P).
	template <class E>
	void fold(std::vector<E>& nodes) const
	{
		for (const auto& g : groups) {
			const Mirror& m  = list[g.first];
			const auto    sg = signLanes(nodes.data(), m.axis);
			const long    nc = long(m.columns.size());
#pragma omp for schedule(static)
			for (long c = 0; c < nc; ++c) {
				const size_t col = m.columns[size_t(c)];
				for (int e = 0; e < g.n; ++e) lanes(nodes[col + size_t(g.k[e]) * m.stride]) += sg * lanes(nodes[col + size_t(g.kp[e]) * m.stride]);
			}
		}
	}
	// Unfold: every node beyond a plane takes the reflection of its partner (planes in reverse order).
	template <class E>
	void unfold(std::vector<E>& nodes) const
	{
		for (auto it = groups.rbegin(); it != groups.rend(); ++it) {
			const Group&  g  = *it;
			const Mirror& m  = list[g.first];
			const auto    sg = signLanes(nodes.data(), m.axis);
			const long    nc = long(m.columns.size());
#pragma omp for schedule(static)
			for (long c = 0; c < nc; ++c) {
				const size_t col = m.columns[size_t(c)];
				for (int e = g.n - 1; e >= 0; --e)
					if (g.k[e] != g.kp[e]) lanes(nodes[col + size_t(g.kp[e]) * m.stride]) = sg * lanes(nodes[col + size_t(g.k[e]) * m.stride]);
			}
		}
	}
	// The same reflection for per-node arrays kept outside Node<D> (the contact phase's nodal forces):
	// f(k, kp, axis) with linear indices for every (material-side node k, partner kp) of every plane, in
	// plane order, k == kp on the plane. Serial (call from one thread).
	template <class F>
	void forEachPair(F&& f) const
	{
		for (const auto& m : list)
			for (size_t col : m.columns)
				for (int j = 0; j < m.nPairs; ++j) f(col + size_t(m.pairK[j]) * m.stride, col + size_t(m.pairKp[j]) * m.stride, m.axis);
	}
	// The nodes of the modelled region that receive a particle's contribution to the node at c0 in the mirror-symmetric
	// full-space problem (what fold does to the nodal sums): f(c, sign) for c0 itself if it is not beyond a plane, and
	// for every reflection of c0 across planes within 2 cells that lands in the modelled region, sign[a] = −1 for an odd
	// number of reflections along a (a node on a plane receives its own reflection too).
	template <class F>
	void receivers(const IVec& c0, F&& f) const
	{
		const size_t nm = list.size();
		for (size_t mask = 0; mask < (size_t(1) << nm); ++mask) {
			IVec c  = c0;
			int  sg[D];
			for (int a = 0; a < D; ++a) sg[a] = 1;
			bool ok = true;
			for (size_t k = 0; k < nm && ok; ++k) {
				if (!((mask >> k) & 1)) continue;
				const Mirror& m  = list[k];
				const int     d2 = 2 * c[m.axis] - m.twoP;
				ok = d2 > -4 && d2 < 4 && m.twoP - c[m.axis] >= 0 && m.twoP - c[m.axis] < m.nStored;
				c[m.axis] = m.twoP - c[m.axis], sg[m.axis] = -sg[m.axis];
			}
			for (size_t k = 0; k < nm && ok; ++k) ok = list[k].side * (2 * c[list[k].axis] - list[k].twoP) <= 0;
			if (ok) f(c, sg);
		}
	}
	// Share of the node at c in the modelled region: 0 beyond a plane (an image), 1/2 for each plane it
	// lies on (its content includes the reflected half), else 1.
	Real share(const IVec& c) const
	{
		Real s = 1;
		for (const auto& m : list) {
			const int d2 = m.side * (2 * c[m.axis] - m.twoP);
			if (d2 > 0) return 0;
			if (d2 == 0) s *= 0.5;
		}
		return s;
	}
	// Stored coordinate k along axis a lies beyond a plane within 2 cells, with its partner inside the
	// physical grid.
	bool mirroredAlong(int a, int k) const
	{
		for (const auto& m : list) {
			if (m.axis != a) continue;
			const int d2 = m.side * (2 * k - m.twoP);
			const int kp = m.twoP - k;
			if (d2 > 0 && d2 < 4 && kp >= m.physLo && kp <= m.physHi) return true;
		}
		return false;
	}
	// The node whose content the node at c mirrors (c itself when it is not an image).
	IVec partner(IVec c) const
	{
		for (int r = 0; r < 3; ++r) // an image of an image (corner): repeat until on the material side
			for (const auto& m : list) {
				const int d2 = m.side * (2 * c[m.axis] - m.twoP);
				if (d2 > 0 && d2 < 4) c[m.axis] = m.twoP - c[m.axis];
			}
		return c;
	}
	// f(c') for the node at c and all its images across the planes (corners included), c first.
	template <class F>
	void forImages(const IVec& c0, F&& f) const
	{
		IVec list8[8] = { c0 };
		int  n        = 1;
		for (const auto& m : list) {
			const int cur = n;
			for (int j = 0; j < cur; ++j) {
				IVec      c  = list8[j];
				const int d2 = -m.side * (2 * c[m.axis] - m.twoP);
				if (d2 > 0 && d2 < 4) {
					c[m.axis] = m.twoP - c[m.axis];
					if (c[m.axis] >= 0 && c[m.axis] < m.nStored && n < 8) list8[n++] = c;
				}
			}
		}
		for (int j = 0; j < n; ++j) f(list8[j]);
	}

private:
	std::vector<Mirror> list;
	// Consecutive planes along the same axis (≥ 2 cells apart) share one loop over the node lines (one barrier
	// per pass): bitwise the same as plane after plane.
	struct Group {
		size_t    first; // its first plane in list (columns, stride)
		int       n;     // (k, kp) pairs of all its planes, in plane order
		int       k[6], kp[6];
	};
	std::vector<Group> groups;

	// +1 on every lane except −1 on the normal component of the vectors (mass is even, the normal
	// momentum, force and velocity odd).
	static NodeLanes signLanes(const Node<D>*, int axis)
	{
		NodeLanes l;
		for (int i = 0; i < 8; ++i) l[i] = 1;
		l[2 + axis] = l[2 + D + axis] = -1;
		return l;
	}
	static NodeVecLanes<D> signLanes(const NodeVec<D>*, int axis)
	{
		NodeVecLanes<D> l;
		for (int i = 0; i < NodeVec<D>::S; ++i) l[i] = 1;
		l[axis] = -1;
		return l;
	}
};

} // namespace mpm
