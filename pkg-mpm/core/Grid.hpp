// The fixed regular background grid (Eulerian nodes, two ghost layers on every side so that every cubic-B-spline
// stencil stays inside the arrays), its axis-aligned boundary planes and the node-exclusion mask: a node with any
// exclusion bit set is left out of every WLS fit (doc/boundaries.md).
#pragma once
#include "MirrorPlanes.hpp"
#include <algorithm>
#include <climits>
#include <set>
#include <vector>

namespace mpm {

// Fixed: one-sided WLS, nodes beyond excluded, all components zero on the plane (on a node line). Slip: symmetry
// plane by reflected images (MirrorPlanes.hpp; on a node line or halfway). SlipOneSided: as Fixed, normal only.
enum class BoundaryKind : int { Fixed = 0, Slip = 1, SlipOneSided = 2 };

// Independent bits, each set and cleared by its owner only, through setBits (keeps stencilExcl and the images).
enum ExclusionBit : uint8_t {
	ExGhost   = 1, // stored node outside the physical grid, not an image of a symmetry plane (Grid)
	ExBeyond  = 2, // strictly beyond a one-sided plane, 'fixed' or 'slip-onesided' (Grid, from the planes)
	ExGap     = 4, // thin gap between the faces of a flaw (yade_mpm.scene) or user exclusion
	ExContact = 8  // covered by a rigid body (Fig. 1b; the contact phase, every step)
};

template <int D>
struct BoundaryPlane {
	int          axis;     // 0 = x, 1 = y, 2 = z
	int          side;     // -1: material above the plane (constrains nodes with coordinate ≤ position), +1: below
	Real         position; // [m]
	BoundaryKind kind;     // Fixed: all velocity components zero; Slip / SlipOneSided: normal component zero
};

template <int D>
struct Grid {
	using Vec  = typename Dim<D>::Vec;
	using IVec = typename Dim<D>::IVec;
	static constexpr int ghost = 2;

	Vec    origin;     // [m] coordinate of physical node (0,0[,0])
	Real   spacing;    // l [m]
	IVec   cells;      // number of cells per axis
	IVec   stored;     // stored nodes per axis (cells + 1 + 2·ghost)
	size_t stride[3];  // linear index strides
	std::vector<Node<D>>    nodes; // P2G: m, mw, momentum, force (GridNode.hpp)
	std::vector<NodeVec<D>> vel;   // gridUpdate (+ contact): updated velocity, Eq. 18
	std::vector<NodeVec<D>> vold;  // gridUpdate keepOld: velocity before the step, for dampAfterContact and FLIP (Transfer::g2p)
	std::vector<NodeVec<D>> mom;   // G2P: MUSL momentum Σ w m h_p(x_i), Eq. 16 numerator
	std::vector<NodeVec<D>> vmusl; // gridMusl: MUSL velocity, Eqs. 16–17
	std::vector<uint8_t> fixMask;     // bit a set: velocity component a is prescribed zero
	std::vector<uint8_t> excluded;    // exclusion bits (ExclusionBit); any bit → left out of the WLS fits
	std::vector<uint8_t> stencilExcl; // excluded nodes in the 4^D stencil starting at this node (one load per kernel)
	std::vector<BoundaryPlane<D>> planes;
	Vec allowedLo, allowedHi; // particles must stay in [allowedLo, allowedHi): the physical grid cut by the planes
	// The node arrays hold the stored layers [layer0, layerEnd) along the last axis (the whole grid unless an MPI rank
	// narrowed it to its slab, setWindow): a node index is local, the global index minus offset = layer0 · stride.
	int    layer0 = 0, layerEnd = 0;
	size_t offset = 0;

	MirrorPlanes<D> mirrors; // the Slip planes (fold/unfold of the reflected images)

	Grid() = default;
	Grid(const Vec& o, Real h, const IVec& n, int lo = 0, int hi = INT_MAX) { init(o, h, n, lo, hi); }

	// The grid of n cells from o; the node arrays hold the stored layers [lo, hi) along the last axis (clamped;
	// default: all; an MPI rank of a distributed construction starts with one layer and never holds the whole grid).
	void init(const Vec& o, Real h, const IVec& n, int lo = 0, int hi = INT_MAX)
	{
		for (int a = 0; a < D; ++a) {
			requireFinite(o[a], "grid origin");
			if (n[a] < 1) throw InputError("grid cells must be ≥ 1 along every axis (got " + std::to_string(n[a]) + ")");
		}
		requireRange(h, 0, INFINITY, true, true, "grid spacing", "[m]");
		origin  = o;
		spacing = h;
		cells   = n;
		size_t s = 1;
		for (int a = 0; a < D; ++a) {
			stored[a] = n[a] + 1 + 2 * ghost;
			stride[a] = s;
			s *= stored[a];
		}
		for (int a = D; a < 3; ++a) stride[a] = 0;
		layer0 = std::max(lo, 0), layerEnd = std::min(hi, int(stored[D - 1]));
		if (!(layer0 < layerEnd)) throw InputError("grid window: empty layer range [" + std::to_string(lo) + ", " + std::to_string(hi) + ")");
		offset = size_t(layer0) * stride[D - 1], s = size_t(layerEnd - layer0) * stride[D - 1];
		allocate(s);
		excluded.assign(s, 0);
		gapNodes.clear();
		planes.clear();
		rebuildPlanes();
	}
	size_t size() const { return nodes.size(); }
	size_t globalSize() const { return stride[D - 1] * size_t(stored[D - 1]); }
	bool   inWindow(const IVec& c) const { return c[D - 1] >= layer0 && c[D - 1] < layerEnd; }
	// Keeps only the stored layers [lo, hi) along the last axis (MPI: a rank's slab and halo, mpi/Decomposition.hpp):
	// the node arrays are re-allocated; exclusion bits of gaps and of rigid-body contact are kept, the rest rebuilt.
	void setWindow(int lo, int hi)
	{
		lo = std::max(lo, 0), hi = std::min(hi, int(stored[D - 1]));
		if (lo == layer0 && hi == layerEnd) return;
		if (!(lo < hi)) throw InputError("grid window: empty layer range [" + std::to_string(lo) + ", " + std::to_string(hi) + ")");
		const size_t st = stride[D - 1], s = size_t(hi - lo) * st, off = size_t(lo) * st;
		std::vector<uint8_t> ex(s, 0);
		const int a0 = std::max(lo, layer0), a1 = std::min(hi, layerEnd); // overlap: contact bits carry over
		for (int k = a0; k < a1; ++k)
			for (size_t j = 0; j < st; ++j) ex[size_t(k - lo) * st + j] = excluded[size_t(k - layer0) * st + j] & ExContact;
		for (size_t gi : gapNodes)
			if (gi >= off && gi < off + s) ex[gi - off] |= ExGap;
		layer0 = lo, layerEnd = hi, offset = off;
		excluded = std::move(ex);
		allocate(s);
		rebuildPlanes();
	}
	// Bytes held by the node arrays of this process (the window).
	size_t bytes() const
	{
		return size() * (sizeof(Node<D>) + 4 * sizeof(NodeVec<D>) + 3) + gapNodes.size() * 48; // a set entry ≈ 48 B
	}
	// Stored (ghost-shifted) integer coordinates of (local) node index i.
	IVec coords(size_t i) const
	{
		i += offset;
		IVec c;
		for (int a = 0; a < D; ++a) {
			c[a] = int(i % stored[a]);
			i /= stored[a];
		}
		return c;
	}
	// Outside the physical grid (geometrically; a ghost may still be the image of a symmetry plane).
	bool isGhost(size_t i) const
	{
		IVec c = coords(i);
		for (int a = 0; a < D; ++a)
			if (c[a] < ghost || c[a] > cells[a] + ghost) return true;
		return false;
	}
	// Physical position of stored node i.
	Vec position(size_t i) const
	{
		IVec c = coords(i);
		Vec  x;
		for (int a = 0; a < D; ++a) x[a] = origin[a] + (c[a] - ghost) * spacing;
		return x;
	}
	size_t linear(const IVec& storedCoords) const
	{
		size_t k = 0;
		for (int a = 0; a < D; ++a) k += size_t(storedCoords[a]) * stride[a];
		return k - offset;
	}
	// Upper corner of the physical grid.
	Vec upper() const
	{
		Vec u;
		for (int a = 0; a < D; ++a) u[a] = origin[a] + cells[a] * spacing;
		return u;
	}

	// ------------------------------------------------------------------ boundary planes
	void addPlane(const BoundaryPlane<D>& p)
	{
		if (p.axis < 0 || p.axis >= D) throw InputError("boundary axis must be in [0, " + std::to_string(D - 1) + "] (got " + std::to_string(p.axis) + ")");
		if (p.side != -1 && p.side != 1) throw InputError("boundary side must be -1 (material above the plane) or +1 (material below)");
		requireFinite(p.position, "boundary position");
		const Real lo = origin[p.axis], hi = upper()[p.axis], tol = 1e-9 * spacing;
		if (p.position < lo - tol || p.position > hi + tol)
			throw InputError("boundary position = " + num(p.position) + " m along axis " + std::to_string(p.axis) + " is outside the physical grid [" + num(lo)
			                 + ", " + num(hi) + "] m");
		// Exact treatments need node lines: no plane is silently moved to the nearest one.
		const Real f = (p.position - lo) / spacing, f2 = 2 * f;
		if (p.kind == BoundaryKind::Slip) {
			if (std::abs(f2 - std::round(f2)) > 1e-6)
				throw InputError("boundary position = " + num(p.position) + " m of a 'slip' plane along axis " + std::to_string(p.axis)
				                 + " must lie on a grid node line or halfway between two (origin + k·l/2 with l = " + num(spacing) + " m; nearest: "
				                 + num(lo + std::round(f2) * spacing / 2) + " m)");
		} else if (std::abs(f - std::round(f)) > 1e-6)
			throw InputError("boundary position = " + num(p.position) + " m of a '" + kindName(p.kind) + "' plane along axis " + std::to_string(p.axis)
			                 + " must lie on a grid node line (origin + k·l with l = " + num(spacing) + " m; nearest: " + num(lo + std::round(f) * spacing)
			                 + " m); move the plane or the grid origin");
		for (const auto& q : planes) {
			if (q.axis != p.axis) continue;
			if (q.side == p.side)
				throw InputError("a boundary plane with axis " + std::to_string(p.axis) + " and side " + std::to_string(p.side) + " exists already (at "
				                 + num(q.position) + " m)");
			const Real below = p.side < 0 ? p.position : q.position, above = p.side < 0 ? q.position : p.position;
			if (above - below < 2 * spacing - tol)
				throw InputError("boundary planes along axis " + std::to_string(p.axis) + " at " + num(below) + " m (side -1) and " + num(above)
				                 + " m (side +1) must enclose at least 2 grid cells (l = " + num(spacing) + " m)");
		}
		planes.push_back(p);
		rebuildPlanes();
	}
	bool hasMirrors() const { return !mirrors.empty(); }
	static const char* kindName(BoundaryKind k) { return k == BoundaryKind::Fixed ? "fixed" : k == BoundaryKind::Slip ? "slip" : "slip-onesided"; }

	// Rebuilds everything derived from the planes: fixed components, ghost and beyond bits, mirrors, counts.
	void rebuildPlanes()
	{
		const size_t s = size();
		mirrors.clear();
		allowedLo = origin, allowedHi = upper();
		for (const auto& p : planes) {
			const int twoP = int(std::lround(2 * (p.position - origin[p.axis]) / spacing)) + 2 * ghost;
			if (p.side < 0) allowedLo[p.axis] = std::max(allowedLo[p.axis], p.position);
			else allowedHi[p.axis] = std::min(allowedHi[p.axis], p.position);
			if (p.kind == BoundaryKind::Slip) mirrors.add(*this, p.axis, p.side, twoP);
		}
		std::fill(fixMask.begin(), fixMask.end(), 0);
		for (size_t i = 0; i < s; ++i) {
			const IVec c   = coords(i);
			uint8_t    bit = excluded[i] & ~uint8_t(ExGhost | ExBeyond);
			for (int a = 0; a < D; ++a)
				if ((c[a] < ghost || c[a] > cells[a] + ghost) && !mirrors.mirroredAlong(a, c[a])) bit |= ExGhost;
			for (const auto& p : planes) {
				const int twoP = int(std::lround(2 * (p.position - origin[p.axis]) / spacing)) + 2 * ghost;
				const int d2   = p.side * (2 * c[p.axis] - twoP); // > 0: beyond the plane, = 0: on it
				if (d2 == 0) fixMask[i] |= p.kind == BoundaryKind::Fixed ? uint8_t((1 << D) - 1) : uint8_t(1 << p.axis);
				else if (d2 > 0 && p.kind != BoundaryKind::Slip) bit |= ExBeyond;
			}
			excluded[i] = bit;
		}
		// images of symmetry planes carry their partner's gap/contact bits
		for (size_t i = 0; i < s; ++i) {
			size_t src = partnerOf(i);
			if (src != i && src < s) excluded[i] = (excluded[i] & uint8_t(ExGhost | ExBeyond)) | (excluded[src] & uint8_t(~(ExGhost | ExBeyond)));
		}
		recountStencils();
	}

	// ------------------------------------------------------------------ exclusion bits
	// Sets (on = true) or clears bits of physical node i; images of symmetry planes follow their partner,
	// and writes to an image itself are ignored (its partner decides).
	void setBits(size_t i, uint8_t bits, bool on)
	{
		if (partnerOf(i) != i) return;
		forImages(i, [&](size_t j) { writeBits(j, bits, on); });
	}
	// The user/gap exclusion of one physical node (Python: setNodeExcluded).
	void setExcluded(size_t i, bool ex)
	{
		if (i >= size()) throw InputError("node index " + std::to_string(i) + " is outside [0, " + std::to_string(size() - 1) + "]");
		if (isGhost(i)) throw InputError("node index " + std::to_string(i) + " is a ghost node outside the physical grid");
		setBits(i, ExGap, ex);
		if (ex) gapNodes.insert(i + offset); // kept for a later setWindow
		else gapNodes.erase(i + offset);
	}

	// ------------------------------------------------------------------ symmetry planes (MirrorPlanes.hpp)
	Real mirrorShare(size_t i) const { return mirrors.share(coords(i)); } // weight of node i in body reactions
	// The node whose content node i mirrors after unfold (partnerOf), with the reflection per axis: v_i = sign ∘ v_j
	// (sign[a] = −1 where the partner lies across a plane normal to a).
	size_t mirrorSource(size_t i, int (&sign)[D]) const
	{
		const IVec c = coords(i), p = mirrors.empty() ? c : mirrors.partner(c);
		for (int a = 0; a < D; ++a) sign[a] = p[a] == c[a] ? 1 : -1;
		return linear(p);
	}
	// f(j, sign) for every node j of the modelled region that receives a contribution to node i (MirrorPlanes::receivers).
	template <class F>
	void forMirrorReceivers(size_t i, F&& f) const
	{
		mirrors.receivers(coords(i), [&](const IVec& c, const int* sign) { f(linear(c), sign); });
	}

private:
	// Node arrays of exactly s zeroed nodes. The old arrays are freed first: assign would keep their capacity, so
	// a window narrowed from the whole grid (MPI, setWindow) would still hold the whole grid's pages.
	void allocate(size_t s)
	{
		fresh(nodes, s), fresh(vel, s), fresh(vold, s), fresh(mom, s), fresh(vmusl, s), fresh(fixMask, s);
	}
	template <class V>
	static void fresh(V& v, size_t s)
	{
		V().swap(v);
		v.resize(s); // value-initialised: zero
	}
	static std::string num(Real v)
	{
		char b[32];
		snprintf(b, sizeof(b), "%g", v);
		return b;
	}
	// The node whose content node i mirrors (i itself when i is not an image).
	size_t partnerOf(size_t i) const { return mirrors.empty() ? i : linear(mirrors.partner(coords(i))); } // may lie outside the window (≥ size())
	std::set<size_t> gapNodes; // global indices of the nodes with ExGap (setExcluded)
	// Node i and all its images across the symmetry planes (corners included).
	template <class F>
	void forImages(size_t i, F&& f) const
	{
		mirrors.forImages(coords(i), [&](const IVec& c) {
			if (inWindow(c)) f(linear(c));
		});
	}
	void writeBits(size_t i, uint8_t bits, bool on)
	{
		const uint8_t old = excluded[i], now = on ? uint8_t(old | bits) : uint8_t(old & ~bits);
		excluded[i]       = now;
		if (bool(old) == bool(now)) return;
		const IVec c = coords(i);
		// stencils starting at c − j (j = 0..3 per axis) contain node i
		for (int n = 0; n < Dim<D>::nStencil; ++n) {
			IVec b;
			bool ok = true;
			for (int a = 0; a < D; ++a) {
				b[a] = c[a] - ((n >> (2 * a)) & 3);
				ok   = ok && b[a] >= (a == D - 1 ? layer0 : 0) && b[a] + 3 < (a == D - 1 ? layerEnd : stored[a]);
			}
			if (!ok) continue;
			auto& cnt = stencilExcl[linear(b)];
			cnt       = now ? uint8_t(cnt + 1) : uint8_t(cnt - 1);
		}
	}
	// stencilExcl from scratch: separable box sums of (excluded ≠ 0) over 4 nodes along each axis.
	void recountStencils()
	{
		const size_t         s = size();
		std::vector<uint8_t> in(s), out(s);
		for (size_t i = 0; i < s; ++i) in[i] = excluded[i] != 0;
		for (int a = 0; a < D; ++a) {
			for (size_t i = 0; i < s; ++i) {
				const int k = coords(i)[a];
				uint8_t   t = 0;
				if (k + 3 < (a == D - 1 ? layerEnd : stored[a]))
					for (int j = 0; j < 4; ++j) t += in[i + size_t(j) * stride[a]];
				out[i] = t;
			}
			std::swap(in, out);
		}
		stencilExcl = std::move(in);
	}
};

} // namespace mpm
