// Rigid surfaces with kinematics for the PTS contact (paper Sec. 2.3), without YADE dependency: a YADE body is a
// RigidPart (pose, velocity, the reaction it receives), its shape primitives (box, plane, sphere/circle, surface
// elements) live in the part's frame, and a RigidGroup, the union of the primitives of one or more parts with one
// set of contact parameters, answers query(x): signed distance (> 0 outside), outward normal, owning part.
#pragma once
#include "ContactParams.hpp"
#include "../core/MpmTypes.hpp"
#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <vector>

namespace mpm {

template <int D>
using SpinOf = Eigen::Matrix<Real, D == 2 ? 1 : 3, 1>; // angular velocity / torque: ω_z in 2D, ω in 3D

// ω × r (2D: ω about z).
template <int D>
inline typename Dim<D>::Vec crossSpin(const SpinOf<D>& w, const typename Dim<D>::Vec& r)
{
	if constexpr (D == 2) return typename Dim<D>::Vec(-w[0] * r[1], w[0] * r[0]);
	else return w.cross(r);
}
// r × f (2D: its z component).
template <int D>
inline SpinOf<D> momentOf(const typename Dim<D>::Vec& r, const typename Dim<D>::Vec& f)
{
	if constexpr (D == 2) return SpinOf<D>(r[0] * f[1] - r[1] * f[0]);
	else return r.cross(f);
}

template <int D>
struct RigidPart {
	using Vec = typename Dim<D>::Vec;
	using Mat = typename Dim<D>::Mat;
	Vec        c = Vec::Zero();           // reference point (YADE: state.pos, the centre of mass) [m]
	Mat        R = Mat::Identity();       // orientation (local → world)
	Vec        v = Vec::Zero();           // velocity of the reference point [m/s]
	SpinOf<D>  w = SpinOf<D>::Zero();     // angular velocity [rad/s]
	Vec        force  = Vec::Zero();      // reaction from the MPM grid in the last step [N] (2D: N per m)
	SpinOf<D>  torque = SpinOf<D>::Zero(); // its moment about c [N m] (2D: N m per m)
	// The body's inertia as the stick step of Eq. 24 sees it (PenaltyContact::bodyResponse: the body's motion after the step):
	// mass [kg] (2D: kg per m of thickness), in (0, inf]; inf (default) = immovable along its translations
	// (a prescribed body: blocked DOFs, not dynamic), which gives the paper's stick step unchanged.
	Real       mass    = INFINITY;
	// principal moments of inertia about c along the axes of R [kg m²] (2D: I_z only, kg m² per m), each in
	// (0, inf]; inf (default) = that rotation prescribed.
	SpinOf<D>  inertia = SpinOf<D>::Constant(INFINITY);
	Vec velocityAt(const Vec& x) const { return v + crossSpin<D>(w, x - c); }
	bool movable() const { return mass < INFINITY || (inertia.array() < INFINITY).any(); }

	void setMass(Real m, const SpinOf<D>& I)
	{
		auto check = [](Real x, const char* name, const char* unit) {
			if (!(x > 0)) throw InputError(std::string(name) + " = " + fmtNum(x) + " " + unit + " is outside the allowed range (0, inf]");
		};
		check(m, "rigid body mass", D == 2 ? "[kg/m]" : "[kg]");
		for (int k = 0; k < I.size(); ++k) check(I[k], "rigid body moment of inertia", D == 2 ? "[kg m^2/m]" : "[kg m^2]");
		mass = m, inertia = I;
	}
	// Inverse inertia tensor in the world frame, R diag(1/I) R^T (an infinite moment gives 0) [1/(kg m²)].
	Eigen::Matrix<Real, D == 2 ? 1 : 3, D == 2 ? 1 : 3> inverseInertia() const
	{
		const SpinOf<D> inv = inertia.cwiseInverse();
		if constexpr (D == 2) return inv;
		else return R * inv.asDiagonal() * R.transpose();
	}

	void setState(const Vec& c_, const Mat& R_, const Vec& v_, const SpinOf<D>& w_)
	{
		for (int a = 0; a < D; ++a) requireFinite(c_[a], "rigid body position [m]"), requireFinite(v_[a], "rigid body velocity [m/s]");
		for (int k = 0; k < w_.size(); ++k) requireFinite(w_[k], "rigid body angular velocity [rad/s]");
		const Real orth = (R_.transpose() * R_ - Mat::Identity()).cwiseAbs().maxCoeff();
		if (!(orth < 1e-6) || !(R_.determinant() > 0)) throw InputError("rigid body orientation must be a rotation matrix (orthonormal, det = +1)");
		c = c_, R = R_, v = v_, w = w_;
	}
};

template <int D>
struct BoxPrim { // oriented box (2D: a rectangle, the trace of a box at z = 0)
	using Vec = typename Dim<D>::Vec;
	using Mat = typename Dim<D>::Mat;
	int part;
	Vec cL, h;  // centre in the part frame, half extents [m]
	Mat RL;     // orientation in the part frame
	Vec c;      // world centre (updated)
	Mat R;      // world orientation (updated)
};
template <int D>
struct PlanePrim { // one-sided (the half-space behind n, a YADE Wall) or two-sided plane
	using Vec = typename Dim<D>::Vec;
	int  part;
	Vec  pL, nL;  // point and unit normal in the part frame
	bool twoSided; // false: the body is the half-space behind n (material on the +n side)
	Vec  p, n;     // world (updated)
};

template <int D>
struct SpherePrim { // sphere (3D) or circle (2D: the trace at z = 0); a clump: one per member
	using Vec = typename Dim<D>::Vec;
	int  part;
	Vec  cL; // centre in the part frame
	Real r;  // radius [m] (2D: radius of the trace circle)
	Vec  c;  // world centre (updated)
};

template <int D>
struct RigidGroup {
	using Vec = typename Dim<D>::Vec;
	using Mat = typename Dim<D>::Mat;
	static constexpr int NV = D; // vertices per element: 2 (segment), 3 (triangle)

	ContactParams            params;
	std::vector<int>         parts; // indices into the contact's part list
	std::vector<BoxPrim<D>>  boxes;
	std::vector<PlanePrim<D>> planes;
	std::vector<SpherePrim<D>> spheres;
	bool                     enabled = true; // false: skipped entirely this step (a DEM sphere far from the particles)
	std::vector<Vec>         elemL;    // segment (2D) / triangle (3D) vertices in their part's frame, NV per element
	std::vector<int>         elemPart; // owning part of each element
	std::vector<Vec>         elem;     // world vertices (updated)
	bool                     closed = false; // the elements bound a volume: signed distance (else a thin two-sided surface)
	// d0 = "initial" only (params.initialD0): d0 [m] per stable particle id, NaN = the default ½ V_p^{1/D};
	// empty until captured (ContactGroups::captureInitialD0). d0InitialMax: the largest captured value.
	std::vector<Real>        d0Initial;
	Real                     d0InitialMax = 0;
	bool                     d0Captured   = false;
	bool                     topologyKnown = false;

	struct Hit {
		Real d = INFINITY; // signed distance, > 0 outside [m]
		Vec  n;            // outward unit normal at the closest point
		int  part = -1;    // part owning the closest point
	};

	// World geometry from the parts' current poses.
	void update(const std::vector<RigidPart<D>>& P)
	{
		for (auto& b : boxes) {
			const auto& q = P[b.part];
			b.c = q.c + q.R * b.cL;
			b.R = q.R * b.RL;
		}
		for (auto& sp : spheres) {
			const auto& q = P[sp.part];
			sp.c = q.c + q.R * sp.cL;
		}
		for (auto& pl : planes) {
			const auto& q = P[pl.part];
			pl.p = q.c + q.R * pl.pL;
			pl.n = q.R * pl.nL;
		}
		for (size_t e = 0; e < elemPart.size(); ++e) {
			const auto& q = P[elemPart[e]];
			for (int k = 0; k < NV; ++k) elem[e * NV + k] = q.c + q.R * elemL[e * NV + k];
		}
		if (!topologyKnown) decideClosed();
	}

	// Signed distance, outward normal and owning part at x (union of all primitives).
	Hit query(const Vec& x) const
	{
		Hit h;
		for (const auto& b : boxes) boxQuery(b, x, h);
		for (const auto& sp : spheres) {
			const Vec  r   = x - sp.c;
			const Real rn  = r.norm();
			const Real d   = rn - sp.r;
			if (d < h.d) {
				h.d = d, h.part = sp.part;
				if (rn > 0) h.n = r / rn;
				else h.n = Vec::Unit(0); // at the centre every direction is the nearest
			}
		}
		for (const auto& pl : planes) {
			Real s = (x - pl.p).dot(pl.n);
			Real d = pl.twoSided ? std::abs(s) : s;
			if (d < h.d) h.d = d, h.n = (pl.twoSided && s < 0) ? Vec(-pl.n) : pl.n, h.part = pl.part;
		}
		if (!elemPart.empty()) meshQuery(x, h);
		return h;
	}

	// World bounding box of the region within `out` outside and `in` inside the surface (clipped later
	// to the grid). Unbounded directions get ±inf.
	void bounds(Real out, Real in, Vec& lo, Vec& hi) const
	{
		lo.setConstant(INFINITY), hi.setConstant(-INFINITY);
		auto grow = [&](const Vec& a, const Vec& b) { lo = lo.cwiseMin(a), hi = hi.cwiseMax(b); };
		for (const auto& b : boxes) {
			Vec e = b.R.cwiseAbs() * b.h; // half extents of the rotated box's AABB
			grow(b.c - e - Vec::Constant(out), b.c + e + Vec::Constant(out));
		}
		for (const auto& sp : spheres) grow(sp.c - Vec::Constant(sp.r + out), sp.c + Vec::Constant(sp.r + out));
		for (const auto& pl : planes) {
			int axis = -1;
			for (int a = 0; a < D; ++a)
				if (std::abs(std::abs(pl.n[a]) - 1) < 1e-12) axis = a;
			Vec l = Vec::Constant(-INFINITY), u = Vec::Constant(INFINITY);
			if (axis >= 0) { // axis-aligned: a slab around the plane
				const Real s = pl.n[axis] > 0 ? 1 : -1;
				const Real behind = pl.twoSided ? out : in;
				Real       a0 = pl.p[axis] - s * behind, a1 = pl.p[axis] + s * out;
				l[axis] = std::min(a0, a1), u[axis] = std::max(a0, a1);
			}
			grow(l, u);
		}
		for (size_t k = 0; k < elem.size(); ++k) grow(elem[k] - Vec::Constant(out), elem[k] + Vec::Constant(out));
	}

private:
	static void boxQuery(const BoxPrim<D>& b, const Vec& x, Hit& h)
	{
		const Vec q = b.R.transpose() * (x - b.c);
		Vec       a = q.cwiseAbs() - b.h; // per-axis excess
		Real      d;
		Vec       nl = Vec::Zero();
		if ((a.array() > 0).any()) {
			Vec o = a.cwiseMax(0);
			d     = o.norm();
			for (int k = 0; k < D; ++k) nl[k] = (q[k] < 0 ? -1 : 1) * o[k] / d;
		} else {
			int k = 0;
			d     = a.maxCoeff(&k);
			nl[k] = q[k] < 0 ? -1 : 1;
		}
		if (d < h.d) h.d = d, h.n = b.R * nl, h.part = b.part;
	}

	// Closest point on segment [a, b] / triangle (a, b, c) to x (Ericson, Real-Time Collision Detection 5.1).
	static Vec closestOnSegment(const Vec& x, const Vec& a, const Vec& b)
	{
		Vec  ab = b - a;
		Real t  = ab.squaredNorm() > 0 ? std::clamp((x - a).dot(ab) / ab.squaredNorm(), Real(0), Real(1)) : 0;
		return a + t * ab;
	}
	static Vec closestOnTriangle(const Vec& p, const Vec& a, const Vec& b, const Vec& c)
	{
		Vec  ab = b - a, ac = c - a, ap = p - a;
		Real d1 = ab.dot(ap), d2 = ac.dot(ap);
		if (d1 <= 0 && d2 <= 0) return a;
		Vec  bp = p - b;
		Real d3 = ab.dot(bp), d4 = ac.dot(bp);
		if (d3 >= 0 && d4 <= d3) return b;
		Real vc = d1 * d4 - d3 * d2;
		if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
		Vec  cp = p - c;
		Real d5 = ab.dot(cp), d6 = ac.dot(cp);
		if (d6 >= 0 && d5 <= d6) return c;
		Real vb = d5 * d2 - d1 * d6;
		if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
		Real va = d3 * d6 - d5 * d4;
		if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
		Real den = 1 / (va + vb + vc);
		return a + ab * (vb * den) + ac * (vc * den);
	}
	Vec elementNormal(size_t e) const // unit normal of an element (sign arbitrary), used only at zero distance
	{
		const Vec* v = &elem[e * NV];
		if constexpr (D == 2) {
			Vec t = v[1] - v[0];
			return Vec(-t[1], t[0]).normalized();
		} else return (v[1] - v[0]).cross(v[2] - v[0]).normalized();
	}
	// Inside test of a closed element set: crossing parity of a ray (2D: along +x; 3D: three skew rays).
	bool inside(const Vec& x) const
	{
		if constexpr (D == 2) {
			bool in = false;
			for (size_t e = 0; e < elemPart.size(); ++e) {
				const Vec &a = elem[2 * e], &b = elem[2 * e + 1];
				if ((a[1] > x[1]) != (b[1] > x[1])) {
					Real xc = a[0] + (x[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
					if (x[0] < xc) in = !in;
				}
			}
			return in;
		} else { // ray crossing parity, independent of the triangles' orientation; majority of 3 skew rays
			static const Vec dirs[3] = { Vec(0.5366, 0.6358, 0.5547).normalized(), Vec(-0.7071, 0.3141, 0.6330).normalized(),
				                     Vec(0.2718, -0.8284, 0.4899).normalized() };
			int votes = 0;
			for (const auto& r : dirs) {
				bool in = false;
				for (size_t e = 0; e < elemPart.size(); ++e)
					if (rayHits(x, r, elem[3 * e], elem[3 * e + 1], elem[3 * e + 2])) in = !in;
				votes += in;
			}
			return votes >= 2;
		}
	}
	// Möller–Trumbore: does the ray x + t r (t > 0) cross triangle (a, b, c)?
	static bool rayHits(const Vec& x, const Vec& r, const Vec& a, const Vec& b, const Vec& c)
	{
		if constexpr (D == 3) {
			const Vec  e1 = b - a, e2 = c - a, p = r.cross(e2);
			const Real det = e1.dot(p);
			if (std::abs(det) < 1e-300) return false;
			const Real inv = 1 / det;
			const Vec  s   = x - a;
			const Real u   = s.dot(p) * inv;
			if (u < 0 || u > 1) return false;
			const Vec  q = s.cross(e1);
			const Real v = r.dot(q) * inv;
			if (v < 0 || u + v > 1) return false;
			return e2.dot(q) * inv > 0;
		} else return false;
	}
	void meshQuery(const Vec& x, Hit& h) const
	{
		Real   best = INFINITY;
		Vec    cp   = Vec::Zero();
		size_t be   = 0;
		for (size_t e = 0; e < elemPart.size(); ++e) {
			Vec  q  = D == 2 ? closestOnSegment(x, elem[NV * e], elem[NV * e + 1]) : closestOnTriangleV(x, e);
			Real d2 = (x - q).squaredNorm();
			if (d2 < best) best = d2, cp = q, be = e;
		}
		Real d = std::sqrt(best);
		Vec  n = d > 0 ? Vec((x - cp) / d) : elementNormal(be);
		if (closed && inside(x)) d = -d, n = -n; // inside: outward normal points from x to the surface
		if (d < h.d) h.d = d, h.n = n, h.part = elemPart[be];
	}
	Vec closestOnTriangleV(const Vec& x, size_t e) const
	{
		if constexpr (D == 3) return closestOnTriangle(x, elem[3 * e], elem[3 * e + 1], elem[3 * e + 2]);
		else return x;
	}
	// Closed when every edge (3D) / vertex (2D) is shared by exactly two elements (vertices matched
	// within 1e-9 of the set's size).
	void decideClosed()
	{
		topologyKnown = true;
		closed        = false;
		const size_t ne = elemPart.size();
		if (ne < (D == 2 ? 3u : 4u)) return;
		Vec lo = elem[0], hi = elem[0];
		for (const auto& v : elem) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
		const Real tol = 1e-9 * std::max((hi - lo).norm(), Real(1e-300));
		auto same = [&](const Vec& a, const Vec& b) { return (a - b).norm() <= tol; };
		if constexpr (D == 2) {
			for (const auto& v : elem) {
				int k = 0;
				for (const auto& u : elem) k += same(u, v);
				if (k != 2) return;
			}
		} else {
			for (size_t e = 0; e < ne; ++e)
				for (int k = 0; k < 3; ++k) {
					const Vec &a = elem[3 * e + k], &b = elem[3 * e + (k + 1) % 3];
					int        shared = 0;
					for (size_t f = 0; f < ne; ++f)
						for (int j = 0; j < 3; ++j) {
							const Vec &c = elem[3 * f + j], &d = elem[3 * f + (j + 1) % 3];
							shared += (same(a, c) && same(b, d)) || (same(a, d) && same(b, c));
						}
					if (shared != 2) return;
				}
		}
		closed = true;
	}
};

} // namespace mpm
