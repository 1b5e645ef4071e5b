// Material points in structure-of-arrays storage. Arrays are sized once when particles are added and
// never reallocated during stepping, so NumPy views handed to Python stay valid; sorting permutes
// their contents in place.
#pragma once
#include "SymTensor.hpp"
#include <vector>

namespace mpm {

template <int D>
struct Particles {
	static constexpr int NS = Dim<D>::nSym;
	size_t n = 0;
	std::vector<Real> x[D];     // position x_p [m]
	std::vector<Real> v[D];     // velocity v_p [m/s]
	std::vector<Real> C[D * D]; // WLS velocity gradient from G2P (row-major ∂v_i/∂x_j) [1/s], affine part of Eq. 16
	std::vector<Real> mass;     // m_p [kg] (per unit thickness in 2D)
	std::vector<Real> vol;      // V_p [m³] (area × 1 m in 2D)
	std::vector<Real> vol0;     // initial V_p [m³]
	std::vector<Real> sig[NS];  // Cauchy stress (undamaged state) [Pa], tension positive
	std::vector<int64_t> id;    // stable particle id (the insertion order)

	// Optional fields, empty unless a scene uses them.
	std::vector<Real> trac[D]; // prescribed surface force on the particle (traction × area) [N]
	std::vector<Real> epsP;    // accumulated plastic strain ε̄p [-]
	std::vector<Real> damage;  // Grady–Kipp damage D [-]
	std::vector<Real> eps0;    // Grady–Kipp activation strain ε_D⁰, Eq. 37 [-]

	bool hasTraction() const { return !trac[0].empty(); }
	bool hasDamageState() const { return !damage.empty(); }

	void ensureTraction()
	{
		if (hasTraction()) return;
		for (int a = 0; a < D; ++a) trac[a].assign(n, 0.0);
	}
	void ensureDamageState()
	{
		if (hasDamageState()) return;
		epsP.assign(n, 0.0);
		damage.assign(n, 0.0);
		eps0.assign(n, 0.0);
	}

	// Every allocated per-particle Real array, for permutation and append.
	template <class F>
	void forEachRealField(F&& f)
	{
		for (int a = 0; a < D; ++a) f(x[a]), f(v[a]);
		for (int k = 0; k < D * D; ++k) f(C[k]);
		f(mass), f(vol), f(vol0);
		for (int k = 0; k < NS; ++k) f(sig[k]);
		for (int a = 0; a < D; ++a)
			if (!trac[a].empty()) f(trac[a]);
		if (!epsP.empty()) f(epsP), f(damage), f(eps0);
	}

	Sym<D> stress(size_t p) const
	{
		Sym<D> s;
		for (int k = 0; k < NS; ++k) s.c[k] = sig[k][p];
		return s;
	}
	void setStress(size_t p, const Sym<D>& s)
	{
		for (int k = 0; k < NS; ++k) sig[k][p] = s.c[k];
	}

	// Applies particle order perm (new slot k holds old particle perm[k]) to every field.
	// tmp, idTmp: work buffers kept by the caller, so a re-sort allocates nothing once they have grown.
	void permute(const std::vector<uint32_t>& perm, std::vector<Real>& tmp, std::vector<int64_t>& idTmp)
	{
		tmp.resize(n);
		forEachRealField([&](std::vector<Real>& a) {
			for (size_t k = 0; k < n; ++k) tmp[k] = a[perm[k]];
			std::copy(tmp.begin(), tmp.begin() + n, a.begin());
		});
		idTmp.resize(n);
		for (size_t k = 0; k < n; ++k) idTmp[k] = id[perm[k]];
		std::copy(idTmp.begin(), idTmp.begin() + n, id.begin()); // keep the buffer: Python views must stay valid
	}
	size_t bytesPerParticle() const
	{
		size_t b = sizeof(int64_t);
		const_cast<Particles*>(this)->forEachRealField([&](std::vector<Real>&) { b += sizeof(Real); });
		return b;
	}
};

} // namespace mpm
