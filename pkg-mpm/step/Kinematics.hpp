// Kinematics of one material point over one step, from its velocity gradient L = ∇v (Eq. 7):
// strain increment (Eq. 29), objective (Jaumann) stress rotation and volume ratio det(I + Δt L),
// plus the small tensor helpers the transfers share.
#pragma once
#include "../core/SymTensor.hpp"
#include <Eigen/LU>

namespace mpm {

// Δε = sym(L) Δt (Eq. 29). Plane strain: Δε_zz = 0.
template <int D>
inline void strainIncrement(const Real (&L)[D][D], Real dt, Sym<D>& de)
{
	de.c[0] = L[0][0] * dt;
	de.c[1] = L[1][1] * dt;
	de.c[2] = D == 3 ? L[D - 1][D - 1] * dt : 0.0;
	de.c[3] = 0.5 * (L[0][1] + L[1][0]) * dt;
	if constexpr (D == 3) {
		de.c[4] = 0.5 * (L[0][2] + L[2][0]) * dt;
		de.c[5] = 0.5 * (L[1][2] + L[2][1]) * dt;
	}
}

// Objective (Jaumann) rotation of the stress by the spin W = skew(L): σ += Δt(Wσ − σW).
template <int D>
inline void jaumannRotation(const Real (&L)[D][D], Real dt, Sym<D>& s)
{
	if constexpr (D == 2) {
		const Real w  = 0.5 * (L[0][1] - L[1][0]) * dt; // W_xy
		const Real sx = s.c[0], sy = s.c[1], sxy = s.c[3];
		s.c[0] = sx + 2 * w * sxy;
		s.c[1] = sy - 2 * w * sxy;
		s.c[3] = sxy + w * (sy - sx);
	} else { // σ + WσΔt − σWΔt = σ + M + Mᵀ with M = WσΔt (W antisymmetric)
		const Real w01 = 0.5 * (L[0][1] - L[1][0]) * dt, w02 = 0.5 * (L[0][2] - L[2][0]) * dt, w12 = 0.5 * (L[1][2] - L[2][1]) * dt;
		const Real xx = s.c[0], yy = s.c[1], zz = s.c[2], xy = s.c[3], xz = s.c[4], yz = s.c[5];
		s.c[0] = xx + 2 * (w01 * xy + w02 * xz);
		s.c[1] = yy + 2 * (w12 * yz - w01 * xy);
		s.c[2] = zz - 2 * (w02 * xz + w12 * yz);
		s.c[3] = xy + w01 * (yy - xx) + w02 * yz + w12 * xz;
		s.c[4] = xz + w01 * yz + w02 * (zz - xx) - w12 * xy;
		s.c[5] = yz - w01 * xz - w02 * xy + w12 * (zz - yy);
	}
}

// Volume ratio of the step, J = det(I + Δt L): V_p ← J V_p.
template <int D>
inline Real jacobian(const Real (&L)[D][D], Real dt)
{
	if constexpr (D == 2) return (1 + L[0][0] * dt) * (1 + L[1][1] * dt) - L[0][1] * L[1][0] * dt * dt;
	else {
		Eigen::Matrix3d F;
		for (int a = 0; a < 3; ++a)
			for (int b = 0; b < 3; ++b) F(a, b) = (a == b) + L[a][b] * dt;
		return F.determinant();
	}
}

// Full D×D matrix of a compact symmetric tensor (in-plane block in 2D).
template <int D>
inline void sym2full(const Sym<D>& s, Real (&f)[D][D])
{
	f[0][0] = s.c[0], f[1][1] = s.c[1], f[0][1] = f[1][0] = s.c[3];
	if constexpr (D == 3) {
		f[2][2] = s.c[2];
		f[0][2] = f[2][0] = s.c[4];
		f[1][2] = f[2][1] = s.c[5];
	}
}

// out = σ g (in-plane part in 2D).
template <int D>
inline void stressTimesVector(const Sym<D>& s, const Real* g, Real* out)
{
	if constexpr (D == 2) {
		out[0] = s.c[0] * g[0] + s.c[3] * g[1];
		out[1] = s.c[3] * g[0] + s.c[1] * g[1];
	} else {
		out[0] = s.c[0] * g[0] + s.c[3] * g[1] + s.c[4] * g[2];
		out[1] = s.c[3] * g[0] + s.c[1] * g[1] + s.c[5] * g[2];
		out[2] = s.c[4] * g[0] + s.c[5] * g[1] + s.c[2] * g[2];
	}
}

} // namespace mpm
