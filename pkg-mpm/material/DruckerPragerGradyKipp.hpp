// Coupled Drucker–Prager plasticity and Grady–Kipp tensile damage (paper Sec. 2.4, Eqs. 27–40).
// One stress-update entry point: elastic trial → DP return (cone or apex, cohesion softening) →
// GK damage growth. The state stress is the undamaged one; the damaged stress (Eq. 40) is what the
// particle exerts on the grid and what is reported as "stress".
#pragma once
#include "ElasticMaterial.hpp"

namespace mpm {

struct DpGkMat : ElasticMat {
	MPM_PARAMS(DpGkMat, ElasticMat, MPM_DPGK_PARAMS) // plasticity, damage, φ, ψ, c₀, … (MaterialParams.hpp)

	// Ranges of the table, then the conditions that tie parameters together.
	void validate() const
	{
		validateParams();
		if (plasticity && dilationAngle > frictionAngle)
			throw InputError("dilationAngle (alias dilatancyAngle) = " + ParamInfo::num(dilationAngle) + " [rad] is outside the allowed range [0, frictionAngle = "
			                 + ParamInfo::num(frictionAngle) + "] (ψ ≤ φ)");
		if (plasticity && softeningModulusTerm() >= shear())
			throw InputError(
			        "critPlasticStrain = " + ParamInfo::num(critPlasticStrain)
			        + " gives cohesion softening steeper than the shear modulus allows (k̄φ·c₀·r/ε̄p,crit must be < G, r = dε̄p/dΔλ = "
			        + ParamInfo::num(epsPerLambda()) + " for plasticStrainIncrement = '" + paramWord(plasticStrainIncrement) + "'); raise critPlasticStrain");
	}
	// Eq. 31 (outer-apex Mohr–Coulomb match) and Eq. 33.
	Real qPhi() const { return 6 * std::sin(frictionAngle) / (std::sqrt(3.0) * (3 - std::sin(frictionAngle))); }
	Real kPhi() const { return 6 * std::cos(frictionAngle) / (std::sqrt(3.0) * (3 - std::sin(frictionAngle))); }
	Real qPsi() const { return 6 * std::sin(dilationAngle) / (std::sqrt(3.0) * (3 - std::sin(dilationAngle))); }
	// dε̄p/dΔλ (plasticStrainIncrement): k̄φ (the reference code's) or 1/√3 (von Mises equivalent).
	Real epsPerLambda() const { return plasticStrainIncrement == PlasticStrainIncrement::VonMises ? 1 / std::sqrt(3.0) : kPhi(); }
	// |k̄φ H| dε̄p/dΔλ, H = dc/dε̄p in the softening branch.
	Real softeningModulusTerm() const { return kPhi() * cohesion / critPlasticStrain * epsPerLambda(); }
	// Eq. 34.
	Real cohesionAt(Real epsP) const { return std::max(cohesion * (1 - epsP / critPlasticStrain), residualCohesion * cohesion); }
	Real effectiveCrackSpeed() const { return crackSpeed > 0 ? crackSpeed : 0.4 * pWaveSpeed(); }
	// Eq. 39.
	Real alpha() const
	{
		const Real m = weibullM;
		return 8 * M_PI * weibullK * (m + 3) * (m + 3) / ((m + 1) * (m + 2));
	}
	// Eq. 37: ε_D⁰ = (V k)^(−1/m) for a given V [m³].
	Real activationStrain(Real volume) const { return std::pow(volume * weibullK, -1.0 / weibullM); }
	// V of Eq. 37 for a particle of initial volume vol0 [m³] (2D: area × 1 m) on a grid of spacing l [m].
	Real thresholdVolumeOf(Real vol0, Real l, int dim) const
	{
		const Real dp = std::pow(vol0, 1.0 / dim); // particle spacing
		switch (thresholdVolume) {
			case ThresholdVolume::Particle: return vol0;
			case ThresholdVolume::SpacingCubed: return dp * dp * dp;
			default: return l * l * dp;
		}
	}
	// The particle's threshold scale ε_D⁰ (Eq. 37 with the V reading) on a grid of spacing l; with
	// thresholdCell = l_ref > 0 the value of the l_ref grid (same ppc) scaled by √(l_ref/l), so that the
	// effective toughness ε_D⁰ √l (and the energy per crack area of a one-cell crack band) is grid-independent.
	Real thresholdScale(Real vol0, Real l, int dim) const
	{
		if (thresholdCell <= 0) return activationStrain(thresholdVolumeOf(vol0, l, dim));
		const Real r = thresholdCell / l;
		return activationStrain(thresholdVolumeOf(vol0 * std::pow(r, dim), thresholdCell, dim)) * std::sqrt(r);
	}
	// The particle's ε_D⁰, refused outside (0, 1): V·k ≤ 1 (less than one flaw per particle) gives ε_D⁰ ≥ 1
	// and damage that can never start; an underflow to 0 would damage every particle at once.
	Real threshold(Real vol0, Real l, int dim) const
	{
		const Real e = thresholdScale(vol0, l, dim);
		if (!(e > 0 && e < 1)) {
			const Real V = thresholdVolumeOf(vol0, l, dim);
			throw InputError("damage threshold eps0 = (V·weibullK)^(−1/weibullM) = " + ParamInfo::num(e) + " for V = " + ParamInfo::num(V)
			                 + " m³ (particle volume " + ParamInfo::num(vol0) + " m³, thresholdVolume = '" + paramWord(thresholdVolume) + "'"
			                 + ") is outside the allowed range (0, 1) (weibullK = " + ParamInfo::num(weibullK) + " m^-3, weibullM = " + ParamInfo::num(weibullM)
			                 + "; V·weibullK = " + ParamInfo::num(V * weibullK) + " must exceed 1: at least one flaw per particle)");
		}
		return e;
	}
	void checkThresholds(const Real* vol0, size_t n, Real l, int dim) const
	{
		for (size_t p = 0; p < n && damage; ++p)
			if (vol0[p] > 0 && vol0[p] < INFINITY) threshold(vol0[p], l, dim); // bad volumes are reported as such elsewhere
	}
};

// The parameter tables add no runtime state: hot loops copy and read plain structs.
static_assert(std::is_trivially_copyable_v<ElasticMat> && std::is_trivially_copyable_v<DpGkMat>, "material parameters must stay plain data");

// Benz–Asphaug flaw population (Benz & Asphaug 1995): the flaw thresholds of a particle are the points
// of a Poisson process in Λ = k V ε^m (so the expected number of flaws activated at strain ε is k V ε^m,
// Eq. 37's Weibull law), i.e. ε_j = ε_D⁰ Λ_j^(1/m) with Λ_j = E_1 + … + E_j, E_i ~ Exp(1). E_i comes from
// a counter-based hash of (seed, particle id, i): no stored stream, independent of threads and order.
inline uint64_t splitmix64(uint64_t x)
{
	x += 0x9E3779B97F4A7C15ull;
	x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
	x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
	return x ^ (x >> 31);
}
inline Real flawExp(int seed, int64_t id, int i)
{
	const uint64_t h = splitmix64(splitmix64(splitmix64(uint64_t(seed)) ^ uint64_t(id)) ^ uint64_t(i));
	const Real     u = (Real(h >> 11) + 0.5) * (1.0 / 9007199254740992.0); // (0, 1)
	return -std::log(u);
}
// Threshold of flaw j = 1, 2, … of particle id: ε_j = scale · (E_1 + … + E_j)^(1/m).
inline Real flawThreshold(const DpGkMat& m, Real scale, int64_t id, int j)
{
	Real L = 0;
	for (int i = 1; i <= j; ++i) L += flawExp(m.flawSeed, id, i);
	return scale * std::pow(L, 1.0 / m.weibullM);
}
// ε_D⁰ a particle starts with (checked in (0, 1)): Eq. 37 with the V reading, or its first flaw's threshold.
inline Real initialThreshold(const DpGkMat& m, Real vol0, Real l, int dim, int64_t id)
{
	const Real scale = m.threshold(vol0, l, dim);
	return m.flawCount > 0 ? flawThreshold(m, scale, id, 1) : scale;
}

// Result of a single DP return, exposed for the single-particle tests.
struct ReturnInfo {
	int  mode    = 0; // 0 elastic, 1 cone, 2 apex
	Real dLambda = 0; // plastic multiplier [-]
};

template <int D>
struct DruckerPragerGradyKipp {
	DpGkMat mat;
	Real    K, G, M, qphi, kphi, qpsi, rate, cFloor, epsFloor, H, alpha13, cg, E, nu;
	Real    cell; // grid spacing l [m] (threshold readings that depend on it)

	explicit DruckerPragerGradyKipp(const DpGkMat& m, Real gridSpacing = 0) : mat(m), cell(gridSpacing)
	{
		E        = m.young;
		nu       = m.poisson;
		K        = m.bulk();
		G        = m.shear();
		M        = m.pWaveModulus();
		qphi     = m.qPhi();
		kphi     = m.kPhi();
		qpsi     = m.qPsi();
		rate     = m.epsPerLambda();
		cFloor   = m.residualCohesion * m.cohesion;
		epsFloor = (1 - m.residualCohesion) * m.critPlasticStrain; // ε̄p where Eq. 34 reaches the floor
		H        = -m.cohesion / m.critPlasticStrain;              // dc/dε̄p before the floor
		alpha13  = m.damage ? std::cbrt(m.alpha()) : 0;
		cg       = m.effectiveCrackSpeed();
	}

	// DP plastic corrector (Eqs. 30–34). ε̄p grows by rate·Δλ (plasticStrainIncrement): k̄φΔλ as the
	// reference code (Graphyt druckerPrager_Damage) or Δλ/√3 = √(2/3)‖Δε^p_dev‖ (von Mises equivalent).
	ReturnInfo plasticReturn(Sym<D>& s, Real& epsP) const
	{
		ReturnInfo r;
		Sym<D>     dev = s;
		const Real sm   = dev.toDeviator();
		const Real tau2 = 0.5 * dev.contract();
		const Real c    = mat.cohesionAt(epsP);
		const Real room = kphi * c - qphi * sm; // Eq. 30: F = τ − room ≤ 0 ⇔ room ≥ 0 and τ² ≤ room² (no root for elastic points)
		if (room >= 0 && tau2 <= room * room) return r;
		const Real tau = std::sqrt(tau2);
		const Real F   = tau + qphi * sm - kphi * c; // Eq. 30
		if (F <= 0) return r;
		// Cone return with the non-associated potential (Eqs. 32–33): τ ← τ − GΔλ, σm ← σm − K qψ Δλ.
		Real dl;
		if (epsP < epsFloor) {
			dl = F / (G + K * qphi * qpsi + kphi * H * rate);
			if (epsP + rate * dl > epsFloor) // passes the 0.1 c₀ floor inside this step
				dl = (tau + qphi * sm - kphi * cFloor) / (G + K * qphi * qpsi);
		} else {
			dl = F / (G + K * qphi * qpsi);
		}
		const Real tauNew = tau - G * dl;
		if (tauNew >= 0) {
			r.mode    = 1;
			r.dLambda = dl;
			epsP += rate * dl;
			const Real scale = tau > 0 ? tauNew / tau : 0;
			const Real smNew = sm - K * qpsi * dl;
			for (int k = 0; k < Dim<D>::nSym; ++k) s.c[k] = dev.c[k] * scale;
			for (int k = 0; k < 3; ++k) s.c[k] += smNew;
			return r;
		}
		// Apex return: the whole trial deviator is plastic, Δλ = τ/G and Δε̄p = rate·τ/G (the cone's measure,
		// continuous with it where τ − GΔλ = 0); σm lands on the apex of the softened cone, σm = k̄φ c / qφ
		// (qφ > 0 here, otherwise the cone return is always valid).
		r.mode    = 2;
		r.dLambda = tau / G;
		epsP += rate * tau / G;
		const Real smApex = kphi * mat.cohesionAt(epsP) / qphi;
		for (int k = 0; k < Dim<D>::nSym; ++k) s.c[k] = 0;
		for (int k = 0; k < 3; ++k) s.c[k] = smApex;
		return r;
	}

	// ε̄ of Eq. 36 from the undamaged state stress (smax = its maximum principal value).
	Real damageStrain(const Sym<D>& s, Real smax) const
	{
		if (mat.damageStrain == DamageStrain::Uniaxial) return smax / M;
		return ((1 + nu) * smax - nu * (s.c[0] + s.c[1] + s.c[2])) / E; // max principal elastic strain
	}

	// GK damage growth (Eqs. 35–39) from the undamaged stress; D is non-decreasing and ≤ 1. Only under
	// tension (σ̃max > 0). With a flaw population (nFlaw != nullptr: activated flaws so far) the flaws
	// whose thresholds ε̄ has passed are activated and D is capped by their fraction (Benz & Asphaug 1995).
	void damageGrowth(const Sym<D>& s, Real& Dmg, Real eps0, Real dt, Real* nFlaw = nullptr, Real vol0 = 0, int64_t id = 0) const
	{
		if (Dmg >= 1 || !mayBeTensile(s)) return;
		const Real smax = maxPrincipal(s);
		if (smax <= 0) return;
		const Real eb = damageStrain(s, smax); // Eq. 36
		if (eb <= eps0) return;                // Eq. 35
		Real cap = 1;
		if (nFlaw) {
			const int N = mat.flawCount;
			int       n = int(*nFlaw);
			if (n < N) {
				const Real scale = mat.thresholdScale(vol0, cell, D);
				Real       L     = 0;
				for (int i = 1; i <= n; ++i) L += flawExp(mat.flawSeed, id, i);
				while (n < N) {
					const Real Ln = L + flawExp(mat.flawSeed, id, n + 1);
					if (eb <= scale * std::pow(Ln, 1.0 / mat.weibullM)) break;
					L = Ln, ++n;
				}
				*nFlaw = n;
			}
			if (n == 0) return; // eps0 edited above the first flaw's threshold
			cap = Real(n) / N;
		}
		const Real m    = mat.weibullM;
		const Real rate = cg * alpha13 / 3 * (mat.growthLaw == DamageGrowthLaw::BenzAsphaug ? std::pow(eb, m / 3) : std::cbrt(eb)); // Eq. 38
		const Real d13  = std::cbrt(Dmg) + rate * dt;
		Dmg             = d13 >= 1 ? 1.0 : d13 * d13 * d13;
		if (Dmg > cap) Dmg = cap;
	}

	// Eq. 40: tensile principal stresses scaled by (1 − D), rotated back; compression unchanged.
	static Sym<D> damaged(const Sym<D>& s, Real Dmg)
	{
		if (Dmg <= 0 || !mayBeTensile(s)) return s;
		auto pr = Principal<D>::of(s);
		if (pr.value[0] <= 0) return s;
		Real v[3];
		for (int k = 0; k < 3; ++k) v[k] = pr.value[k] > 0 ? (1 - Dmg) * pr.value[k] : pr.value[k];
		return pr.rebuild(v);
	}

	// One material point: elastic trial → DP return → GK damage. A fully damaged particle (D = 1) is a
	// tensile crack: its state keeps no tensile principal stress (Sec. 2.4.2, "a zero-stress state" in
	// tension) before and after the DP return, so an opening crack neither stores tension nor yields;
	// compression (a closed crack) is carried and may yield like rock. ε̄p is thus plastic strain of rock.
	ReturnInfo updatePoint(Sym<D>& s, const Sym<D>& de, Real& epsP, Real& Dmg, Real eps0, Real dt, Real* nFlaw = nullptr, Real vol0 = 0,
	                       int64_t id = 0) const
	{
		elasticTrial(s, de, K, G); // Eqs. 27–29
		const bool cracked = mat.damage && Dmg >= 1;
		if (cracked) s = damaged(s, 1);
		ReturnInfo r;
		if (mat.plasticity) r = plasticReturn(s, epsP); // Eqs. 30–34
		if (cracked) s = damaged(s, 1);                  // an apex return may land in tension
		else if (mat.damage) damageGrowth(s, Dmg, eps0, dt, nFlaw, vol0, id); // Eqs. 35–39
		return r;
	}
	void update(Particles<D>& P, size_t p, Sym<D>& s, const Sym<D>& de, Real dt) const
	{
		if (!mat.damage) {
			elasticTrial(s, de, K, G);
			if (mat.plasticity) plasticReturn(s, P.epsP[p]);
			return;
		}
		if (mat.flawCount > 0) updatePoint(s, de, P.epsP[p], P.damage[p], P.eps0[p], dt, &P.nFlaw[p], P.vol0[p], P.id[p]);
		else updatePoint(s, de, P.epsP[p], P.damage[p], P.eps0[p], dt); // vol0 and id are read only by the flaw population
	}
	Sym<D> forceStress(const Particles<D>& P, size_t p) const { return damaged(P.stress(p), P.damage[p]); }
	// Largest volume of particle p [m³]: failedBulking × V₀ once it has failed (D = 1), else none.
	Real volumeLimit(const Particles<D>& P, size_t p) const
	{
		return mat.damage && P.damage[p] >= 1 ? mat.failedBulking * P.vol0[p] : INFINITY;
	}
};

} // namespace mpm
