// Fixed regular background grid (Eulerian nodes) with boundary planes and an optional node mask.
// Two ghost layers on every side keep every cubic-B-spline stencil inside the arrays, so kernels never
// branch on array bounds: ghost nodes are simply excluded from the WLS fit (ψ_i = 0 there).
#pragma once
#include "MpmTypes.hpp"
#include <vector>

namespace mpm {

// One node: lumped mass (Eq. 20), Shepard mass Σ w m (Eq. 17 denominator) and two vector slots reused
// within a step: a = momentum → updated velocity, b = force → MUSL velocity.
// A node fills one 64-byte cache line (2D: 6 values + 2 padding lanes, 3D: 8 values), so the transfer
// kernels update a whole node with one 8-lane vector operation (lanes: m, mw, a…, b…, padding).
template <int D>
struct alignas(64) Node {
	Real m, mw;
	Real a[D];
	Real b[D];
};
typedef Real NodeLanes __attribute__((vector_size(64), may_alias));
static_assert(sizeof(Node<2>) == sizeof(NodeLanes) && sizeof(Node<3>) == sizeof(NodeLanes), "a node must fill one lane vector");
template <int D>
inline NodeLanes& lanes(Node<D>& n) { return *reinterpret_cast<NodeLanes*>(&n); }
template <int D>
inline const NodeLanes& lanes(const Node<D>& n) { return *reinterpret_cast<const NodeLanes*>(&n); }

enum class BoundaryKind : int { Fixed = 0, Slip = 1 };

template <int D>
struct BoundaryPlane {
	int          axis;     // 0 = x, 1 = y, 2 = z
	int          side;     // -1: constrains nodes with coordinate ≤ position, +1: ≥ position
	Real         position; // [m]
	BoundaryKind kind;     // Fixed: all velocity components zero; Slip: normal component zero
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
	std::vector<Node<D>> nodes;
	std::vector<uint8_t> fixMask;  // bit a set: velocity component a is prescribed zero
	std::vector<uint8_t> excluded; // non-zero = node excluded from WLS fits; bits: ExclUser (ghosts always, user mask), ExclContact
	enum : uint8_t { ExclUser = 1, ExclContact = 2 };
	std::vector<BoundaryPlane<D>> planes;

	Grid() = default;
	Grid(const Vec& o, Real h, const IVec& n) { init(o, h, n); }

	void init(const Vec& o, Real h, const IVec& n)
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
		nodes.assign(s, Node<D> {});
		fixMask.assign(s, 0);
		excluded.assign(s, 0);
		for (size_t i = 0; i < s; ++i)
			if (isGhost(i)) excluded[i] = 1;
	}
	size_t size() const { return nodes.size(); }
	// Stored (ghost-shifted) integer coordinates of linear index i.
	IVec coords(size_t i) const
	{
		IVec c;
		for (int a = 0; a < D; ++a) {
			c[a] = int(i % stored[a]);
			i /= stored[a];
		}
		return c;
	}
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
		return k;
	}
	// Upper corner of the physical grid.
	Vec upper() const
	{
		Vec u;
		for (int a = 0; a < D; ++a) u[a] = origin[a] + cells[a] * spacing;
		return u;
	}

	void addPlane(const BoundaryPlane<D>& p)
	{
		if (p.axis < 0 || p.axis >= D) throw InputError("boundary axis must be in [0, " + std::to_string(D - 1) + "] (got " + std::to_string(p.axis) + ")");
		if (p.side != -1 && p.side != 1) throw InputError("boundary side must be -1 (lower) or +1 (upper)");
		requireFinite(p.position, "boundary position");
		planes.push_back(p);
		rebuildFixMask();
	}
	void clearPlanes()
	{
		planes.clear();
		rebuildFixMask();
	}
	void rebuildFixMask()
	{
		std::fill(fixMask.begin(), fixMask.end(), 0);
		const Real tol = 1e-9 * spacing;
		for (size_t i = 0; i < size(); ++i) {
			Vec x = position(i);
			for (const auto& p : planes) {
				bool hit = p.side < 0 ? x[p.axis] <= p.position + tol : x[p.axis] >= p.position - tol;
				if (!hit) continue;
				fixMask[i] |= p.kind == BoundaryKind::Fixed ? uint8_t((1 << D) - 1) : uint8_t(1 << p.axis);
			}
		}
	}
	// Mark a physical node excluded from the WLS fits (e.g. a node covered by a rigid body).
	void setExcluded(size_t i, bool ex)
	{
		if (i >= size()) throw InputError("node index " + std::to_string(i) + " is outside [0, " + std::to_string(size() - 1) + "]");
		if (isGhost(i)) throw InputError("node index " + std::to_string(i) + " is a ghost node outside the physical grid");
		if (bool(excluded[i] & ExclUser) == ex) return;
		excluded[i] = ex ? (excluded[i] | ExclUser) : (excluded[i] & ~ExclUser);
		nUserExcluded += ex ? 1 : -1;
	}
	// Contact's own bit (a node covered by a rigid body, Fig. 1b), set and cleared every step by the contact
	// phase without touching the user bit. No range check: the contact phase passes physical nodes only.
	void setContactExcluded(size_t i, bool ex)
	{
		if (bool(excluded[i] & ExclContact) == ex) return;
		excluded[i] = ex ? (excluded[i] | ExclContact) : (excluded[i] & ~ExclContact);
		nContactExcluded += ex ? 1 : -1;
	}
	bool userExclusions() const { return nUserExcluded > 0 || nContactExcluded > 0; }
	long nUserExcluded = 0, nContactExcluded = 0;
};

} // namespace mpm
