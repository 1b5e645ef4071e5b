// Material points in structure-of-arrays storage. Arrays are sized once when particles are added and
// never reallocated during stepping, so NumPy views handed to Python stay valid; sorting permutes
// their contents in place.
#pragma once
#include "SymTensor.hpp"
#include <cstring>
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
	std::vector<uint8_t> mat;   // material index (MaterialSet.hpp)

	// Optional fields, empty unless a scene uses them.
	std::vector<Real> trac[D]; // prescribed surface force on the particle (traction × area) [N]
	std::vector<Real> epsP;    // accumulated plastic strain ε̄p [-]
	std::vector<Real> damage;  // Grady–Kipp damage D [-]
	std::vector<Real> eps0;    // Grady–Kipp activation strain ε_D⁰, Eq. 37 (with flaws: of the first flaw) [-]
	std::vector<Real> nFlaw;   // activated Benz–Asphaug flaws (only with a flaw population) [-]

	bool hasTraction() const { return !trac[0].empty(); }
	bool hasDamageState() const { return !damage.empty(); }

	void ensureTraction()
	{
		if (hasTraction()) return;
		for (int a = 0; a < D; ++a) trac[a].reserve(x[0].capacity()), trac[a].assign(n, 0.0);
	}
	void ensureDamageState()
	{
		if (hasDamageState()) return;
		for (auto* f : { &epsP, &damage, &eps0 }) f->reserve(x[0].capacity()), f->assign(n, 0.0);
	}
	// Room for `total` particles in every allocated array (no move while appending up to that count).
	void reserve(size_t total)
	{
		forEachRealField([&](std::vector<Real>& f) { f.reserve(total); });
		id.reserve(total), mat.reserve(total);
	}
	// Gives back the memory beyond n particles in every array (after an MPI rank dropped the others' particles).
	void shrink()
	{
		forEachRealField([&](std::vector<Real>& f) { f.shrink_to_fit(); });
		id.shrink_to_fit(), mat.shrink_to_fit();
	}
	// True if n more particles fit into every allocated array without moving it.
	bool fits(size_t more) const
	{
		bool ok = id.capacity() >= n + more && mat.capacity() >= n + more;
		const_cast<Particles*>(this)->forEachRealField([&](std::vector<Real>& f) { ok = ok && f.capacity() >= n + more; });
		return ok;
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
		if (!nFlaw.empty()) f(nFlaw);
	}

	// Appends n particles (positions x[p·D + a] [m], volumes [m³], masses [kg]) after checking every value;
	// the grid spans [lo, hi). Throws InputError naming the particle and quantity, before any change.
	template <class Vec>
	void append(const Real* x, const Real* vol, const Real* mass, size_t n, const Vec& lo, const Vec& hi, uint8_t material)
	{
		if (n == 0) throw InputError("particles: the particle set to add is empty");
		for (size_t p = 0; p < n; ++p) {
			const std::string who = "particle " + std::to_string(this->n + p);
			for (int a = 0; a < D; ++a) {
				Real xa = x[p * D + a];
				if (!std::isfinite(xa)) throw InputError("position of " + who + " is not finite (NaN or inf)");
				if (xa < lo[a] || xa >= hi[a])
					throw InputError("position of " + who + " is outside the grid along axis " + std::to_string(a) + ": " + std::to_string(xa)
					                 + " m not in [" + std::to_string(lo[a]) + ", " + std::to_string(hi[a]) + ") m");
			}
			if (!(std::isfinite(vol[p]) && vol[p] > 0))
				throw InputError("volume of " + who + " must be finite and > 0 m³ (got " + std::to_string(vol[p]) + ")");
			if (!(std::isfinite(mass[p]) && mass[p] > 0)) throw InputError("mass of " + who + " must be finite and > 0 kg (got " + std::to_string(mass[p]) + ")");
		}
		const size_t old = this->n;
		this->n += n;
		forEachRealField([&](std::vector<Real>& f) { f.resize(this->n, 0.0); });
		id.resize(this->n);
		this->mat.resize(this->n, material);
		for (size_t p = 0; p < n; ++p) {
			for (int a = 0; a < D; ++a) this->x[a][old + p] = x[p * D + a];
			this->vol[old + p] = vol0[old + p] = vol[p];
			this->mass[old + p]                = mass[p];
			id[old + p]                        = int64_t(old + p);
		}
	}

	// Checks the state written from outside through views (like append's input) and summarises it.
	struct Summary {
		Real rhoMin = INFINITY, massMin = INFINITY, vmax = 0;
	};
	template <class Vec>
	Summary check(const Vec& lo, const Vec& hi, size_t nMaterials) const
	{
		Summary c;
		for (size_t p = 0; p < n; ++p) {
			auto who = [&] { return "particle id " + std::to_string(id[p]); }; // built only for a message
			for (int a = 0; a < D; ++a)
				if (!(x[a][p] >= lo[a] && x[a][p] < hi[a]))
					throw InputError("position of " + who() + " along axis " + std::to_string(a) + " = " + fmtNum(x[a][p])
					                 + " m is not finite or outside the grid cut by the boundary planes [" + fmtNum(lo[a]) + ", " + fmtNum(hi[a]) + ") m");
			if (!(std::isfinite(mass[p]) && mass[p] > 0)) throw InputError("mass of " + who() + " = " + fmtNum(mass[p]) + " kg must be finite and > 0");
			if (!(std::isfinite(vol[p]) && vol[p] > 0)) throw InputError("volume of " + who() + " = " + fmtNum(vol[p]) + " m³ must be finite and > 0");
			if (mat[p] >= nMaterials)
				throw InputError("material of " + who() + " = " + std::to_string(mat[p]) + " is not a material index of this solver [0, " + std::to_string(nMaterials - 1) + "]");
			c.rhoMin  = std::min(c.rhoMin, mass[p] / vol[p]);
			c.massMin = std::min(c.massMin, mass[p]);
			Real sp   = 0;
			for (int a = 0; a < D; ++a) {
				if (!std::isfinite(v[a][p])) throw InputError("velocity of " + who() + " is not finite");
				sp += v[a][p] * v[a][p];
			}
			for (int k = 0; k < NS; ++k)
				if (!std::isfinite(sig[k][p])) throw InputError("stress of " + who() + " is not finite");
			c.vmax = std::max(c.vmax, std::sqrt(sp));
		}
		return c;
	}

	// DP–GK state written through the views (validated after requestSort()): D ∈ [0, 1], ε̄p finite
	// and ≥ 0, and with damage on ε_D⁰ ∈ (0, 1) (Eq. 37); out-of-range values were used as they were.
	template <class ThresholdOn>
	void checkDamageState(ThresholdOn&& thresholds) const // thresholds(p): check ε_D⁰ of particle p
	{
		if (!hasDamageState()) return;
		auto bad = [&](const char* what, size_t p, Real v, const char* range) {
			throw InputError(std::string(what) + " of particle id " + std::to_string(id[p]) + " = " + fmtNum(v) + " is outside the allowed range " + range);
		};
		for (size_t p = 0; p < n; ++p) {
			if (!(damage[p] >= 0 && damage[p] <= 1)) bad("damage D", p, damage[p], "[0, 1]");
			if (!(epsP[p] >= 0 && std::isfinite(epsP[p]))) bad("plastic strain epsP", p, epsP[p], "[0, inf)");
			if (thresholds(p) && !(eps0[p] > 0 && eps0[p] < 1)) bad("damage threshold eps0", p, eps0[p], "(0, 1)");
		}
	}

	Real kineticEnergy() const // Σ ½ m v² [J]
	{
		Real e = 0;
		for (size_t p = 0; p < n; ++p)
			for (int a = 0; a < D; ++a) e += 0.5 * mass[p] * v[a][p] * v[a][p];
		return e;
	}
	// Work of gravity g and the surface forces (× loadScale) on the particles over dt, Σ (m g + s f)·u dt [J], u the
	// velocity each particle moved with (v, or FLIP's Transfer::vg).
	template <class Vec>
	Real externalWork(const Vec& g, Real loadScale, Real dt, const std::vector<Real> (&u)[D]) const
	{
		Real w = 0;
		for (size_t p = 0; p < n; ++p)
			for (int a = 0; a < D; ++a) w += (mass[p] * g[a] + (hasTraction() ? loadScale * trac[a][p] : 0.0)) * u[a][p] * dt;
		return w;
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

	// Keeps the particles with drop[p] == 0, in their order (particles removed after leaving the grid); the
	// arrays shrink in place (no reallocation).
	void compact(const std::vector<uint8_t>& drop)
	{
		size_t k       = 0;
		auto   squeeze = [&](auto& f) {
			k = 0;
			for (size_t p = 0; p < n; ++p)
				if (!drop[p]) f[k++] = f[p];
			f.resize(k);
		};
		forEachRealField(squeeze);
		squeeze(id), squeeze(mat);
		n = k;
	}

	// Applies particle order perm (new slot k holds old particle perm[k]) to every field.
	// tmp: a work buffer kept by the caller, so a re-sort allocates nothing once it has grown; the material
	// indices and ids pass through it too (the ids' 64 bits copied as they are): one buffer, not two.
	void permute(const std::vector<uint32_t>& perm, std::vector<Real>& tmp)
	{
		static_assert(sizeof(int64_t) == sizeof(Real), "an id must fit a slot of the work buffer");
		tmp.resize(n);
		forEachRealField([&](std::vector<Real>& a) {
			for (size_t k = 0; k < n; ++k) tmp[k] = a[perm[k]];
			std::copy(tmp.begin(), tmp.begin() + n, a.begin());
		});
		for (size_t k = 0; k < n; ++k) tmp[k] = Real(mat[perm[k]]);
		for (size_t k = 0; k < n; ++k) mat[k] = uint8_t(tmp[k]);
		for (size_t k = 0; k < n; ++k) std::memcpy(&tmp[k], &id[perm[k]], sizeof(int64_t));
		if (n) std::memcpy(id.data(), tmp.data(), n * sizeof(int64_t)); // in place: Python views must stay valid
	}
	size_t bytesPerParticle() const
	{
		size_t b = sizeof(int64_t) + sizeof(uint8_t);
		const_cast<Particles*>(this)->forEachRealField([&](std::vector<Real>&) { b += sizeof(Real); });
		return b;
	}
};

} // namespace mpm
