// The material parameters, each declared once (see ParamTable.hpp for the columns).
// The C++ fields, range validation, Python properties and docstrings, keyword constructors and
// toDict/fromDict are all generated from these lists. Names follow YADE where YADE has the concept
// (FrictMat/JCFpmMat: young, poisson, density, frictionAngle, cohesion; JCFpmMat's
// jointDilationAngle → dilationAngle, with the paper's "dilatancyAngle" kept as a Python alias).
#pragma once
#include "../core/ParamTable.hpp"

namespace mpm {
// Named options of DpGkMat (Python sees the words; enumerator k = word k).
// V of Eq. 37. The paper: "the volume of the material particle"; plane strain leaves the thickness open.
enum class ThresholdVolume : int {
	Particle     = 0, // the particle volume vol0 (2D: area × 1 m, per unit thickness; literal, the reference code's)
	SpacingCubed = 1, // dp³, dp = vol0^(1/D) the particle spacing (calibration: picked to fit Fig. 9)
	CellSpacing  = 2  // l²·dp, l the grid spacing (2D: cell area × particle spacing)
};
MPM_CHOICES(ThresholdVolume, "particle|cube|cell")
// ε̄ of Eq. 36.
enum class DamageStrain : int {
	Uniaxial        = 0, // σ̃max/(K + 4G/3): the strain of the maximum principal stress under uniaxial strain (as printed)
	PrincipalStrain = 1  // ((1 + ν)σ1 − ν tr σ)/E: the true maximum principal elastic strain of the state stress
};
MPM_CHOICES(DamageStrain, "uniaxial|principal")
// Eq. 38.
enum class DamageGrowthLaw : int {
	BenzAsphaug = 0, // dD^{1/3}/dt = ⅓ c_g α^{1/3} ε̄^{m/3}: Grady–Kipp / Benz–Asphaug (default)
	AsPrinted   = 1  // dD^{1/3}/dt = ⅓ c_g α^{1/3} ε̄^{1/3}: Eq. 38 exactly as printed
};
MPM_CHOICES(DamageGrowthLaw, "benz-asphaug|as-printed")
// Growth of ε̄p per plastic step (Eq. 34 softens with ε̄p; the paper does not define the increment, it cites
// Deb & Pramanik 2013). Δλ is the plastic multiplier of Eqs. 32–33 (τ ← τ − GΔλ).
enum class PlasticStrainIncrement : int {
	ReferenceCode = 0, // Δε̄p = k̄φ Δλ: the reference code's (Graphyt ConstitutiveModels.cpp, druckerPrager_Damage)
	VonMises      = 1  // Δε̄p = Δλ/√3 = √(2/3)‖Δε^p_dev‖: von Mises equivalent of the deviatoric plastic strain
};
MPM_CHOICES(PlasticStrainIncrement, "reference-code|von-mises")
} // namespace mpm

// X(type, name, default, unit, lo, hi, ends, symbol, doc, equation, gate)
#define MPM_ELASTIC_PARAMS(X)                                                                                  \
	X(Real, young, MPM_REQUIRED, "Pa", 0, INFINITY, OO, "E", "Young's modulus", "Eqs. 27–28", "")              \
	X(Real, poisson, MPM_REQUIRED, "-", -1, 0.5, OO, "ν", "Poisson's ratio", "Eqs. 27–28", "")                 \
	X(Real, density, MPM_REQUIRED, "kg/m³", 0, INFINITY, OO, "ρ", "mass density (particle mass m_p = ρV_p)", \
	  "Eq. 20", "")

// Weibull m in [1, 50]: rocks and ceramics lie between ~3 and ~40 (Grady & Kipp 1980); below 1 ε_D⁰ under/overflows.
#define MPM_DPGK_PARAMS(X)                                                                                                        \
	X(bool, plasticity, true, "-", 0, 1, CC, "", "Drucker–Prager return mapping on/off", "Eqs. 30–34", "")                       \
	X(bool, damage, true, "-", 0, 1, CC, "", "Grady–Kipp tensile damage on/off", "Eqs. 35–40", "")                               \
	X(Real, frictionAngle, MPM_REQUIRED, "rad", 0, M_PI / 2, CO, "φ", "friction angle", "Eqs. 30–31", "plasticity")             \
	X(Real, dilationAngle, 0, "rad", 0, M_PI / 2, CO, "ψ", "dilation (dilatancy) angle, at most frictionAngle", \
	  "Eqs. 32–33", "plasticity")                                                                                                \
	X(Real, cohesion, MPM_REQUIRED, "Pa", 0, INFINITY, OO, "c₀", "initial cohesion", "Eq. 34", "plasticity")                    \
	X(Real, critPlasticStrain, 0.1, "-", 0, INFINITY, OO, "ε̄p,crit", "accumulated plastic strain at which cohesion softening ends", \
	  "Eq. 34", "plasticity")                                                                                                    \
	X(PlasticStrainIncrement, plasticStrainIncrement, PlasticStrainIncrement::ReferenceCode, "-", 0, 1, CC, "Δε̄p",              \
	  "growth of ε̄p per plastic step (the paper leaves it open): 'reference-code' = k̄φ·Δλ as the reference code grows it "    \
	  "(Graphyt, ConstitutiveModels.cpp, druckerPrager_Damage: acc_plastic_strain += dL·ξ), 'von-mises' = Δλ/√3, the von Mises " \
	  "equivalent of the deviatoric plastic strain (this code's earlier default); Δλ is Eq. 32's plastic multiplier, the apex " \
	  "return uses Δλ = τ/G; not a calibration; see doc/damage_growth_law.md", "Eq. 34", "plasticity")                                    \
	X(Real, residualCohesion, 0.1, "-", 0, 1, CC, "", "cohesion floor as a fraction of c₀ (paper: 0.1)", "Eq. 34", "plasticity") \
	X(Real, weibullK, MPM_REQUIRED, "m^-3", 0, INFINITY, OO, "k", "Weibull flaw density", "Eqs. 37, 39", "damage")              \
	X(Real, weibullM, MPM_REQUIRED, "-", 1, 50, CC, "m", "Weibull modulus", "Eqs. 37–39", "damage")                              \
	X(Real, crackSpeed, 0, "m/s", 0, INFINITY, CO, "c_g", "crack growth speed; 0 = 0.4 × P-wave speed", "Eq. 38", "damage")     \
	X(DamageGrowthLaw, growthLaw, DamageGrowthLaw::BenzAsphaug, "-", 0, 1, CC, "",                                             \
	  "damage growth law: 'benz-asphaug' = Grady–Kipp/Benz–Asphaug dD^⅓/dt ∝ ε̄^(m/3), 'as-printed' = Eq. 38 as printed ∝ ε̄^(1/3)", \
	  "Eq. 38", "damage")                                                                                                        \
	X(ThresholdVolume, thresholdVolume, ThresholdVolume::Particle, "-", 0, 2, CC, "V",                                          \
	  "V of Eq. 37 in m³: 'particle' = the particle volume (2D: area × 1 m; the paper's text and the reference code), "         \
	  "'cube' = dp³ (particle spacing cubed; calibration, picked to fit Fig. 9), 'cell' = l²·dp (grid spacing² × particle "     \
	  "spacing); see doc/damage_growth_law.md", "Eq. 37", "damage")                                                              \
	X(DamageStrain, damageStrain, DamageStrain::Uniaxial, "-", 0, 1, CC, "ε̄",                                                  \
	  "tensile strain of Eq. 36: 'uniaxial' = σ̃max/(K + 4G/3) as printed, 'principal' = maximum principal elastic strain of "   \
	  "the state stress", "Eqs. 35–36", "damage")                                                                                \
	X(Real, thresholdCell, 0, "m", 0, INFINITY, CO, "l_ref",                                                                     \
	  "regularised threshold: ε_D⁰ of the l_ref grid scaled by √(l_ref/l), same effective toughness on every grid; 0 = off",   \
	  "Eq. 37", "damage")                                                                                                        \
	X(int, flawCount, 0, "-", 0, 1000, CC, "",                                                                                   \
	  "Benz–Asphaug flaws per particle (Weibull thresholds from k, m; D ≤ activated fraction); 0 = one threshold (Eq. 37)",    \
	  "Eqs. 37–38", "damage")                                                                                                    \
	X(int, flawSeed, 0, "-", 0, 2147483647, CC, "", "seed of the flaw population (thresholds depend on seed and particle id)",  \
	  "Eq. 37", "damage")                                                                                                        \
	X(Real, failedBulking, 1.5, "-", 1, INFINITY, CC, "J_max",                                                                  \
	  "largest volume of a failed particle (D = 1) over its initial one, as the bulking factor of broken rock (1.3–1.6 in "      \
	  "rock engineering); beyond it the opening is void between particles, not material; inf = no limit (the paper's: a lone "  \
	  "failed fragment keeps its expansion rate, grows without bound and drives Δt towards 0, doc/validation/stability.md)",    \
	  "", "damage")
