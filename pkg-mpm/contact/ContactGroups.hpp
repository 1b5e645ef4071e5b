#pragma once
// Registration of the rigid bodies a scene's MPM particles touch (paper Sec. 2.3): rigid parts (pose and velocity
// of a YADE body), contact groups (μ, c, χ, d0 of Eqs. 23–24) with their surface primitives, and the per-particle
// d0 of d0 = "initial". Set up between steps; the step's contact phase is PtsContact.hpp.
#include "../core/Particles.hpp"
#include "RigidSurface.hpp"

#include <algorithm>
#include <limits>

namespace mpm {

template <int D>
class ContactGroups {
public:
	using Vec = typename Dim<D>::Vec;

	std::vector<RigidPart<D>>  parts;
	std::vector<RigidGroup<D>> groups;

	bool active() const { return !groups.empty(); }

	int addPart()
	{
		parts.emplace_back();
		return int(parts.size()) - 1;
	}
	// A group of already-added parts with its contact parameters; primitives are added to the returned index.
	int addGroup(const ContactParams& prm, const std::vector<int>& ps)
	{
		prm.validate();
		if (ps.empty()) throw InputError("a contact group needs at least one rigid part");
		for (int p : ps)
			if (p < 0 || p >= int(parts.size())) throw InputError("rigid part index " + std::to_string(p) + " does not exist");
		RigidGroup<D> g;
		g.params = prm;
		g.parts  = ps;
		groups.push_back(g);
		return int(groups.size()) - 1;
	}
	// Undo the registration of the last group and of its parts when they are the last parts and no other group
	// uses them (a registration refused half-way, e.g. by captureInitialD0): the solver is as before it.
	void removeLastGroup()
	{
		if (groups.empty()) throw InputError("there is no contact group to remove");
		const auto& g     = groups.back();
		const int   first = int(parts.size()) - int(g.parts.size());
		for (size_t k = 0; k < g.parts.size(); ++k)
			if (g.parts[k] != first + int(k)) throw InputError("the last contact group's parts are not the last rigid parts; it cannot be removed");
		for (size_t gi = 0; gi + 1 < groups.size(); ++gi)
			for (int p : groups[gi].parts)
				if (p >= first) throw InputError("the last contact group's parts are shared with another group; it cannot be removed");
		parts.resize(size_t(first));
		groups.pop_back();
	}
	RigidGroup<D>& group(int g)
	{
		if (g < 0 || g >= int(groups.size())) throw InputError("contact group " + std::to_string(g) + " does not exist");
		return groups[g];
	}
	RigidPart<D>& part(int p)
	{
		if (p < 0 || p >= int(parts.size())) throw InputError("rigid part " + std::to_string(p) + " does not exist");
		return parts[p];
	}
	void checkPart(const RigidGroup<D>& g, int p) const
	{
		if (std::find(g.parts.begin(), g.parts.end(), p) == g.parts.end())
			throw InputError("rigid part " + std::to_string(p) + " is not a part of this contact group");
	}
	void addBox(int gi, int p, const Vec& cL, const typename Dim<D>::Mat& RL, const Vec& h)
	{
		auto& g = group(gi);
		checkPart(g, p);
		for (int a = 0; a < D; ++a) requireRange(h[a], 0, INFINITY, true, true, "box half extent", "[m]"), requireFinite(cL[a], "box centre");
		g.boxes.push_back({ p, cL, h, RL, cL, RL });
	}
	void addPlane(int gi, int p, const Vec& pL, const Vec& nL, bool twoSided)
	{
		auto& g = group(gi);
		checkPart(g, p);
		for (int a = 0; a < D; ++a) requireFinite(pL[a], "plane point"), requireFinite(nL[a], "plane normal");
		if (!(nL.norm() > 0)) throw InputError("plane normal must be non-zero");
		g.planes.push_back({ p, pL, nL.normalized(), twoSided, pL, nL.normalized() });
	}
	// Sphere (3D) / circle (2D) of radius r [m] centred at cL in the part frame.
	void addSphere(int gi, int p, const Vec& cL, Real r)
	{
		auto& g = group(gi);
		checkPart(g, p);
		for (int a = 0; a < D; ++a) requireFinite(cL[a], "sphere centre");
		requireRange(r, 0, INFINITY, true, true, "sphere radius", "[m]");
		g.spheres.push_back({ p, cL, r, cL });
	}
	// Groups switched off are skipped whole (no geometry update, no particle or node pass).
	void setEnabled(int gi, bool on) { group(gi).enabled = on; }
	// Segment (2D) or triangle (3D): D vertices in the part frame.
	void addElement(int gi, int p, const Vec* v)
	{
		auto& g = group(gi);
		checkPart(g, p);
		for (int k = 0; k < D; ++k)
			for (int a = 0; a < D; ++a) requireFinite(v[k][a], "surface element vertex");
		Real size = D == 2 ? (v[1] - v[0]).norm() : (v[1] - v[0]).norm() + (v[2] - v[0]).norm();
		if (!(size > 0)) throw InputError("surface element is degenerate (zero length or area)");
		for (int k = 0; k < D; ++k) g.elemL.push_back(v[k]), g.elem.push_back(v[k]);
		g.elemPart.push_back(p);
		g.topologyKnown = false;
	}

	// d0 = "initial" (ContactParams::initialD0): d0_p := d_p(0) for the first lattice layer of particles next to
	// the group's surface at its current pose (at registration), stored per stable particle id. First layer:
	// d_p(0) < e_p max_i |n_i|, e_p = V_p^{1/D}, n the outward normal at the closest point. A particle centre inside
	// the body (d_p(0) < 0) is refused.
	void captureInitialD0(int gi, const Particles<D>& P)
	{
		auto& g = group(gi);
		if (!g.params.initialD0) throw InputError("contact group " + std::to_string(gi) + " was not created with d0 = 'initial'");
		g.update(parts);
		int64_t maxId = -1;
		for (size_t p = 0; p < P.n; ++p) maxId = std::max(maxId, P.id[p]);
		std::vector<Real> d0(size_t(maxId + 1), std::numeric_limits<Real>::quiet_NaN());
		Real              dmax = 0;
		for (size_t p = 0; p < P.n; ++p) {
			Vec x;
			for (int a = 0; a < D; ++a) x[a] = P.x[a][p];
			const auto h = g.query(x);
			const Real e = edgeOf(P.vol[p]);
			if (!(h.d < e * h.n.cwiseAbs().maxCoeff())) continue; // not in the first layer
			if (h.d < 0)
				throw InputError("d0 = 'initial': particle id " + std::to_string(P.id[p]) + " lies inside the rigid body (signed distance "
				                 + fmtNum(h.d) + " m); the body must not overlap the particles when it is registered");
			d0[size_t(P.id[p])] = h.d, dmax = std::max(dmax, h.d);
		}
		g.d0Initial.swap(d0), g.d0InitialMax = dmax, g.d0Captured = true;
	}

	// Edge of a particle's cell from its volume V_p (2D: area per metre), V_p^{1/D} [m].
	static Real edgeOf(Real vol)
	{
		if constexpr (D == 2) return std::sqrt(vol);
		else return std::cbrt(vol);
	}
};

} // namespace mpm
