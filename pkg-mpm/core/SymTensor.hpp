// Symmetric second-order tensors (stress, strain increment) in the compact storage of Dim<D>::nSym,
// plus the closed-form principal decomposition used by the damage model and the output.
#pragma once
#include "MpmTypes.hpp"
#include <Eigen/Eigenvalues>
#include <algorithm>

namespace mpm {

// Components: [0]=xx [1]=yy [2]=zz [3]=xy [4]=xz [5]=yz (the last two only in 3D).
template <int D>
struct Sym {
	static constexpr int N = Dim<D>::nSym;
	Real c[N];

	static Sym zero()
	{
		Sym s;
		for (int k = 0; k < N; ++k) s.c[k] = 0;
		return s;
	}
	Real trace() const { return c[0] + c[1] + c[2]; }
	Real mean() const { return trace() / 3.0; }
	// Deviatoric part in place; returns the mean (σ_m = I1/3).
	Real toDeviator()
	{
		Real m = mean();
		c[0] -= m;
		c[1] -= m;
		c[2] -= m;
		return m;
	}
	// s:s for a deviator (off-diagonals counted twice).
	Real contract() const
	{
		Real r = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
		for (int k = 3; k < N; ++k) r += 2 * c[k] * c[k];
		return r;
	}
	// τ = sqrt(J2) of a full tensor.
	Real sqrtJ2() const
	{
		Sym d = *this;
		d.toDeviator();
		return std::sqrt(0.5 * d.contract());
	}
	Eigen::Matrix3d full() const
	{
		Eigen::Matrix3d m;
		m(0, 0) = c[0];
		m(1, 1) = c[1];
		m(2, 2) = c[2];
		m(0, 1) = m(1, 0) = c[3];
		m(0, 2) = m(2, 0) = (N > 4 ? c[N > 4 ? 4 : 0] : 0.0);
		m(1, 2) = m(2, 1) = (N > 4 ? c[N > 5 ? 5 : 0] : 0.0);
		return m;
	}
	static Sym fromFull(const Eigen::Matrix3d& m)
	{
		Sym s;
		s.c[0] = m(0, 0);
		s.c[1] = m(1, 1);
		s.c[2] = m(2, 2);
		s.c[3] = m(0, 1);
		if constexpr (N > 4) {
			s.c[N > 4 ? 4 : 0] = m(0, 2);
			s.c[N > 5 ? 5 : 0] = m(1, 2);
		}
		return s;
	}
};

// Principal values (descending) and, on request, directions of a symmetric tensor.
// 2D plane strain: exact closed form of the in-plane 2×2 block plus σzz (xz = yz = 0).
// 3D: Eigen's direct 3×3 solver.
template <int D>
struct Principal {
	Real value[3];          // σ1 ≥ σ2 ≥ σ3
	Eigen::Matrix3d vector; // 3D: columns match value[]
	Real c2 = 1, s2 = 0;    // 2D: cos 2θ, sin 2θ of the in-plane direction of the larger in-plane value
	int  slot[3] = { 0, 1, 2 }; // 2D: index in value[] of the larger in-plane, smaller in-plane, zz value

	static Principal of(const Sym<D>& s)
	{
		Principal p;
		if constexpr (D == 2) {
			Real a = 0.5 * (s.c[0] + s.c[1]), b = 0.5 * (s.c[0] - s.c[1]);
			Real r = std::sqrt(b * b + s.c[3] * s.c[3]);
			Real l1 = a + r, l2 = a - r;
			// In plane strain the directions are the in-plane pair at angle θ, 2θ = atan2(2σxy, σxx − σyy),
			// and z. Only cos 2θ = b/r and sin 2θ = σxy/r are kept: rebuild() needs nothing else, so this
			// per-particle path has no trigonometric calls (`vector` stays unset in 2D).
			const Real ir = r > 0 ? 1 / r : 0;
			p.c2          = r > 0 ? b * ir : 1;
			p.s2          = s.c[3] * ir;
			const Real v[3] = { l1, l2, s.c[2] };
			int        o[3] = { 0, 1, 2 }; // l1 ≥ l2 always; place σzz
			if (v[2] > v[0]) o[0] = 2, o[1] = 0, o[2] = 1;
			else if (v[2] > v[1]) o[1] = 2, o[2] = 1;
			for (int k = 0; k < 3; ++k) {
				p.value[k] = v[o[k]];
				p.slot[o[k]] = k;
			}
		} else {
			Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
			es.computeDirect(s.full());
			for (int k = 0; k < 3; ++k) { // Eigen sorts ascending
				p.value[k]      = es.eigenvalues()(2 - k);
				p.vector.col(k) = es.eigenvectors().col(2 - k);
			}
		}
		return p;
	}
	Sym<D> rebuild(const Real v[3]) const
	{
		if constexpr (D == 2) { // in-plane pair (f1 along θ, f2 across) and z: σ = ½(f1+f2) I + ½(f1−f2)[cos 2θ, sin 2θ]
			const Real f1 = v[slot[0]], f2 = v[slot[1]], a = 0.5 * (f1 + f2), b = 0.5 * (f1 - f2);
			Sym<D>     s;
			s.c[0] = a + b * c2;
			s.c[1] = a - b * c2;
			s.c[2] = v[slot[2]];
			s.c[3] = b * s2;
			return s;
		}
		Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
		for (int k = 0; k < 3; ++k) m += v[k] * vector.col(k) * vector.col(k).transpose();
		return Sym<D>::fromFull(m);
	}
};

// Largest principal value only (no directions): cheap, used for outputs and damage triggers.
template <int D>
inline Real maxPrincipal(const Sym<D>& s)
{
	if constexpr (D == 2) {
		Real a = 0.5 * (s.c[0] + s.c[1]), b = 0.5 * (s.c[0] - s.c[1]);
		return std::max(a + std::sqrt(b * b + s.c[3] * s.c[3]), s.c[2]);
	} else {
		return Principal<3>::of(s).value[0];
	}
}

// Whether σ may have a tensile principal value (σ1 > 0), without a root or a decomposition: exact in 2D
// (a + r > 0 ⇔ a > 0 or r² > a²), Gershgorin's bound in 3D (false: σ1 ≤ 0; true may still be compression).
template <int D>
inline bool mayBeTensile(const Sym<D>& s)
{
	if constexpr (D == 2) {
		const Real a = 0.5 * (s.c[0] + s.c[1]), b = 0.5 * (s.c[0] - s.c[1]);
		return s.c[2] > 0 || a > 0 || b * b + s.c[3] * s.c[3] > a * a;
	} else {
		const Real xy = std::abs(s.c[3]), xz = std::abs(s.c[4]), yz = std::abs(s.c[5]);
		return s.c[0] + xy + xz > 0 || s.c[1] + xy + yz > 0 || s.c[2] + xz + yz > 0;
	}
}

} // namespace mpm
