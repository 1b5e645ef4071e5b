// The kinematic contact law (ContactLaw::Kinematic, the default; Eq. 23's penalty is the named option beside it;
// doc/contact.md "Contact laws"): the Δt → 0
// limit of Eq. 23 — a non-penetrating frictional contact at the particles' faces — reached at any Δt by
// constraining velocities instead of pushing with a penalty spring whose compliance grows with Δt².
//
// Detection is the PTS test of Eq. 23 at each particle: d_p − d0 < ε_p (ε_p = 1e-3 of the particle's edge keeps a
// particle resting at d0 in contact, so its cohesion does not flicker), n_p the body's outward normal at the
// closest surface point. The constraint acts on what the particle moves with, its material-point velocity
// v_p = Σ_i ψ_i v_i (the WLS fit, Eq. 6; positions advance with it), relative to the body at x_p,
// u_p = v_p − (v + ω × r_p) (Eq. 26), after the grid update:
//   normal      u_p·n_p ≥ g_p,  g_p = (d0 − d_p)/Δt       (no approach; an overlap is closed in one step)
//   tangential  u_p,tan = 0 while ‖λ_t‖ ≤ μ λ_n + c a_p Δt  (Eq. 24 as an impulse limit, a_p the particle's face)
// with impulses λ_p applied to the nodes as Δv_i = ψ_i λ_p/m_i (Σ_i ψ_i = 1: the grid gains exactly Σ λ_p, the
// body receives −λ_p/Δt at x_p: momentum conserved to round-off; Σ_i ψ_i x_i = x_p: the moment acts at x_p).
// The particles share nodes, so the impulses are found together by projected Gauss–Seidel over the contacts in
// a fixed order (deterministic, serial), each update with the effective mass of its direction,
//   1/k = Σ_a e_a² Σ_i ψ_i²/m_i + e·(W_B e)  (i over the nodes whose component a is free; with symmetry planes the
//   read and write weights of the record below, Σ rd_i w_i/m_i; W_B: the free body's inverse mass and inertia at r_p,
//   0 if prescribed),
// λ_n clamped ≥ 0 and λ_t to the Coulomb + cohesion disc; a free body's velocity is updated with each impulse
// (−W_B J_pᵀ Δλ), so it takes its share of every exchange.
#pragma once
#include "../core/MpmTypes.hpp"

namespace mpm {

// Detection tolerance of the kinematic law, as a fraction of the particle's edge (ε_p above).
constexpr Real kinematicTouch = 1e-3;
// Projected Gauss–Seidel: at most this many sweeps over the contacts, fewer when the largest velocity
// correction of a sweep falls below kinematicTol × (the largest relative speed of the first sweep + 1e-12 m/s).
constexpr int  kinematicSweeps = 60;
constexpr Real kinematicTol    = 1e-6;

// One contacting particle of a kinematic group, its stencil resolved to nodes of the modelled region (symmetry
// planes, Grid::mirrors): the particle reads v_i of a node beyond a plane as the reflection of its partner
// (rd: Σ ψ_i sign_i over the stencil nodes i whose source is node[k]), and its impulse reaches node[k] as fold
// sums it, from the particle and from its images (w: a node on a plane also takes its own reflection). Without
// planes rd = w = ψ.
template <int D>
struct KinematicContactRec {
	using Vec = typename Dim<D>::Vec;
	static constexpr int N = Dim<D>::nStencil;
	size_t node[N]; // distinct nodes of the modelled region (count nn)
	Real   rd[N][D]; // per-axis weight of node[k] in the particle's velocity, v_p[a] = Σ_k rd[k][a] v[node k][a]
	Real   w[N][D]; // per-axis weight of node[k] in the particle's impulse, Δv[node k][a] = w[k][a] λ[a]/m_k
	Real   invM[N]; // 1/m of node[k] [1/kg]
	int    nn;
	int    part;
	Vec    x, n, r;  // particle position, contact normal, lever arm x_p − c
	Real   g;        // target normal rate (d0 − d_p)/Δt [m/s]
	Real   cap0;     // cohesive part of the tangential capacity c a_p Δt [N s]
	Vec    kinvAxis; // Σ_k rd[k][a] w[k][a]/m_k over the nodes whose component a is free [1/kg]
	Vec    lam;      // impulse on the particle [N s]
};

} // namespace mpm
