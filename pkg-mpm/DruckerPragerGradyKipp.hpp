// Coupled Drucker–Prager plasticity and Grady–Kipp tensile damage (paper Sec. 2.4, Eqs. 27–40).
// One stress-update entry point: elastic trial → DP return (cone or apex, cohesion softening) →
// GK damage growth. The state stress is the undamaged one; the damaged stress (Eq. 40) is what the
// particle exerts on the grid and what is reported as "stress".
#pragma once
#include "ElasticMaterial.hpp"

namespace mpm {

enum class DamageGrowthLaw : int {
	BenzAsphaug = 0, // dD^{1/3}/dt = ⅓ c_g α^{1/3} ε̄^{m/3}: Grady–Kipp / Benz–Asphaug (default)
	AsPrinted   = 1  // dD^{1/3}/dt = ⅓ c_g α^{1/3} ε̄^{1/3}: Eq. 38 exactly as printed
};

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
			        + " gives cohesion softening steeper than the shear modulus allows (k̄φ·c₀/(√3·ε̄p,crit) must be < G); raise critPlasticStrain");
	}
	// Eq. 31 (outer-apex Mohr–Coulomb match) and Eq. 33.
	Real qPhi() const { return 6 * std::sin(frictionAngle) / (std::sqrt(3.0) * (3 - std::sin(frictionAngle))); }
	Real kPhi() const { return 6 * std::cos(frictionAngle) / (std::sqrt(3.0) * (3 - std::sin(frictionAngle))); }
	Real qPsi() const { return 6 * std::sin(dilationAngle) / (std::sqrt(3.0) * (3 - std::sin(dilationAngle))); }
	// |k̄φ H|/√3, H = dc/dε̄p in the softening branch.
	Real softeningModulusTerm() const { return kPhi() * cohesion / critPlasticStrain / std::sqrt(3.0); }
	// Eq. 34.
	Real cohesionAt(Real epsP) const { return std::max(cohesion * (1 - epsP / critPlasticStrain), residualCohesion * cohesion); }
	Real effectiveCrackSpeed() const { return crackSpeed > 0 ? crackSpeed : 0.4 * pWaveSpeed(); }
	// Eq. 39.
	Real alpha() const
	{
		const Real m = weibullM;
		return 8 * M_PI * weibullK * (m + 3) * (m + 3) / ((m + 1) * (m + 2));
	}
	// Eq. 37: ε_D⁰ = (V k)^(−1/m). V is the particle volume; in plane strain, area × 1 m.
	Real activationStrain(Real volume) const { return std::pow(volume * weibullK, -1.0 / weibullM); }
	// Eq. 37, refused outside (0, 1): V·k ≤ 1 (less than one flaw per particle) gives ε_D⁰ ≥ 1 and damage
	// that can never start; an underflow to 0 would damage every particle at once.
	Real threshold(Real volume) const
	{
		const Real e = activationStrain(volume);
		if (!(e > 0 && e < 1))
			throw InputError("damage threshold eps0 = (V·weibullK)^(−1/weibullM) = " + ParamInfo::num(e) + " for particle volume V = " + ParamInfo::num(volume)
			                 + " m³ is outside the allowed range (0, 1) (weibullK = " + ParamInfo::num(weibullK) + " m^-3, weibullM = " + ParamInfo::num(weibullM)
			                 + "; V·weibullK = " + ParamInfo::num(volume * weibullK) + " must exceed 1: at least one flaw per particle)");
		return e;
	}
	void checkThresholds(const Real* volume, size_t n) const
	{
		for (size_t p = 0; p < n && damage; ++p)
			if (volume[p] > 0 && volume[p] < INFINITY) threshold(volume[p]); // bad volumes are reported as such elsewhere
	}
};

// The parameter tables add no runtime state: hot loops copy and read plain structs.
static_assert(std::is_trivially_copyable_v<ElasticMat> && std::is_trivially_copyable_v<DpGkMat>, "material parameters must stay plain data");

// Result of a single DP return, exposed for the single-particle tests.
struct ReturnInfo {
	int  mode    = 0; // 0 elastic, 1 cone, 2 apex
	Real dLambda = 0; // plastic multiplier [-]
};

template <int D>
struct DruckerPragerGradyKipp {
	static constexpr bool hasDamage = true;
	DpGkMat mat;
	Real    K, G, M, qphi, kphi, qpsi, cFloor, epsFloor, H, alpha13, cg;

	explicit DruckerPragerGradyKipp(const DpGkMat& m) : mat(m)
	{
		K        = m.bulk();
		G        = m.shear();
		M        = m.pWaveModulus();
		qphi     = m.qPhi();
		kphi     = m.kPhi();
		qpsi     = m.qPsi();
		cFloor   = m.residualCohesion * m.cohesion;
		epsFloor = (1 - m.residualCohesion) * m.critPlasticStrain; // ε̄p where Eq. 34 reaches the floor
		H        = -m.cohesion / m.critPlasticStrain;              // dc/dε̄p before the floor
		alpha13  = m.damage ? std::cbrt(m.alpha()) : 0;
		cg       = m.effectiveCrackSpeed();
	}

	// DP plastic corrector (Eqs. 30–34). ε̄p grows by the von Mises equivalent of the plastic
	// deviatoric strain, Δε̄p = √(2/3)‖Δε^p_dev‖ = Δλ/√3 on the cone.
	ReturnInfo plasticReturn(Sym<D>& s, Real& epsP) const
	{
		ReturnInfo r;
		Sym<D>     dev = s;
		const Real sm  = dev.toDeviator();
		const Real tau = std::sqrt(0.5 * dev.contract());
		const Real c   = mat.cohesionAt(epsP);
		const Real F   = tau + qphi * sm - kphi * c; // Eq. 30
		if (F <= 0) return r;
		const Real s3 = std::sqrt(3.0);
		// Cone return with the non-associated potential (Eqs. 32–33): τ ← τ − GΔλ, σm ← σm − K qψ Δλ.
		Real dl;
		if (epsP < epsFloor) {
			dl = F / (G + K * qphi * qpsi + kphi * H / s3);
			if (epsP + dl / s3 > epsFloor) // passes the 0.1 c₀ floor inside this step
				dl = (tau + qphi * sm - kphi * cFloor) / (G + K * qphi * qpsi);
		} else {
			dl = F / (G + K * qphi * qpsi);
		}
		const Real tauNew = tau - G * dl;
		if (tauNew >= 0) {
			r.mode    = 1;
			r.dLambda = dl;
			epsP += dl / s3;
			const Real scale = tau > 0 ? tauNew / tau : 0;
			const Real smNew = sm - K * qpsi * dl;
			for (int k = 0; k < Dim<D>::nSym; ++k) s.c[k] = dev.c[k] * scale;
			for (int k = 0; k < 3; ++k) s.c[k] += smNew;
			return r;
		}
		// Apex return: the whole trial deviator is plastic, Δε̄p = τ/(√3 G); σm lands on the apex of
		// the softened cone, σm = k̄φ c / qφ (qφ > 0 here, otherwise the cone return is always valid).
		r.mode    = 2;
		r.dLambda = tau / G;
		epsP += tau / (s3 * G);
		const Real smApex = kphi * mat.cohesionAt(epsP) / qphi;
		for (int k = 0; k < Dim<D>::nSym; ++k) s.c[k] = 0;
		for (int k = 0; k < 3; ++k) s.c[k] = smApex;
		return r;
	}

	// GK damage growth (Eqs. 35–39) from the undamaged stress; D is non-decreasing and ≤ 1.
	void damageGrowth(const Sym<D>& s, Real& Dmg, Real eps0, Real dt) const
	{
		if (Dmg >= 1) return;
		const Real smax = maxPrincipal(s);
		if (smax <= 0) return;
		const Real eb = smax / M; // Eq. 36
		if (eb <= eps0) return;   // Eq. 35
		const Real m    = mat.weibullM;
		const Real rate = cg * alpha13 / 3 * (mat.growthLaw == 0 ? std::pow(eb, m / 3) : std::cbrt(eb)); // Eq. 38
		const Real d13  = std::cbrt(Dmg) + rate * dt;
		Dmg             = d13 >= 1 ? 1.0 : d13 * d13 * d13;
	}

	// Eq. 40: tensile principal stresses scaled by (1 − D), rotated back; compression unchanged.
	static Sym<D> damaged(const Sym<D>& s, Real Dmg)
	{
		if (Dmg <= 0) return s;
		auto pr = Principal<D>::of(s);
		if (pr.value[0] <= 0) return s;
		Real v[3];
		for (int k = 0; k < 3; ++k) v[k] = pr.value[k] > 0 ? (1 - Dmg) * pr.value[k] : pr.value[k];
		return pr.rebuild(v);
	}

	void update(Particles<D>& P, size_t p, Sym<D>& s, const Sym<D>& de, Real dt) const
	{
		elasticTrial(s, de, K, G); // Eqs. 27–29
		if (mat.plasticity) plasticReturn(s, P.epsP[p]);
		if (mat.damage) damageGrowth(s, P.damage[p], P.eps0[p], dt);
	}
	Sym<D> forceStress(const Particles<D>& P, size_t p) const { return damaged(P.stress(p), P.damage[p]); }
};

} // namespace mpm
