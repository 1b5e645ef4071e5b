// The data of the kinematic contact law (KinematicContact.hpp): one record per contacting particle and the table of
// the nodes a group's contacts share.
#pragma once
#include "../core/MpmTypes.hpp"
#include <array>
#include <vector>

namespace mpm {

// One contacting particle of a kinematic group, its stencil resolved to nodes of the modelled region (symmetry
// planes, Grid::mirrors): the particle reads v_i of a node beyond a plane as the reflection of its partner
// (rd: Σ ψ_i sign_i over the stencil nodes i whose source is node[k]), and its impulse reaches node[k] as fold
// sums it, from the particle and from its images (w: a node on a plane also takes its own reflection). Without
// planes rd = w = ψ.
template <int D>
struct KinematicContactRec {
	using Vec = typename Dim<D>::Vec;
	static constexpr int N = Dim<D>::nStencil;
	size_t   node[N];   // distinct nodes of the modelled region, global indices (count nn)
	int      slot[N];   // their entries in the group's node table
	Real     rd[N][D];  // per-axis weight of node[k] in the particle's velocity, v_p[a] = Σ_k rd[k][a] v[node k][a]
	Real     w[N][D];   // per-axis weight of node[k] in the particle's impulse, Δv[node k][a] = w[k][a] λ[a]/m_k
	Real     invM[N];   // 1/m of node[k] [1/kg]
	Real     vel[N][D]; // velocity of node[k] after the grid update [m/s] (the node table's input)
	uint8_t  fix[N];    // fixMask of node[k]
	int      nn;
	int      part;
	uint32_t block;     // the particle's block; contacts are solved in (block, id) order
	int64_t  id;        // the particle's id
	bool     mine;      // found by this process: its reaction is this process's share
	Vec      x, n, r;   // particle position, contact normal, lever arm x_p − c
	Real     g;         // target normal rate (d0 − d_p)/Δt [m/s]
	Real     cap0;      // cohesive part of the tangential capacity c a_p Δt [N s]
	Vec      kinvAxis;  // Σ_k rd[k][a] w[k][a]/m_k over the nodes whose component a is free [1/kg]
	Vec      lam;       // impulse on the particle [N s]
};

// The distinct nodes of a group's contacts (global indices, ascending) with the velocities the solver updates.
template <int D>
struct KinematicNodeTable {
	std::vector<size_t>            node;  // global index
	std::vector<std::array<Real, D>> v;   // velocity [m/s]
	std::vector<uint8_t>           fix;   // fixMask
	std::vector<size_t>            local; // index in this process's node arrays, SIZE_MAX when it does not hold the node
	struct Update {                        // a node's velocity sent by the process that owns it (refresh)
		size_t slot;
		Real   v[D];
	};
	std::vector<Update> upd;
};

// v_p = Σ_k rd_k v_k of contact c over the node table t (Eq. 6).
template <int D>
typename Dim<D>::Vec particleVelocity(const KinematicContactRec<D>& c, const KinematicNodeTable<D>& t)
{
	typename Dim<D>::Vec vp = Dim<D>::Vec::Zero();
	for (int k = 0; k < c.nn; ++k)
		for (int a = 0; a < D; ++a) vp[a] += c.rd[k][a] * t.v[size_t(c.slot[k])][a];
	return vp;
}

// The impulses the next step starts from (checkpoints): per group, particle ids (ascending), impulses, and the Δt of
// the step that found them.
template <int D>
struct KinematicWarmImpulse {
	int64_t              id;
	typename Dim<D>::Vec lam; // [N s]
};
template <int D>
struct KinematicWarmStart {
	std::vector<KinematicWarmImpulse<D>> imp;
	Real                                 dt = 0; // [s]
	void                                 clear() { imp.clear(), dt = 0; }
};

} // namespace mpm
