// Linear elastic rock in rate form (paper Eqs. 27–29). The elastic trial of every material goes through
// here, so the hypoelastic law is written once.
#pragma once
#include "MaterialParams.hpp"
#include "../core/Particles.hpp"

namespace mpm {

struct ElasticMat {
	MPM_PARAMS(ElasticMat, NoParams, MPM_ELASTIC_PARAMS) // young, poisson, density (MaterialParams.hpp)

	void validate() const { validateParams(); }
	Real bulk() const { return young / (3 * (1 - 2 * poisson)); }  // K [Pa]
	Real shear() const { return young / (2 * (1 + poisson)); }     // G [Pa]
	Real pWaveModulus() const { return bulk() + 4 * shear() / 3; } // K + 4G/3 [Pa]
	Real pWaveSpeed() const { return std::sqrt(pWaveModulus() / density); }
};

// σ ← σ + 2G Δε_dev + K tr(Δε) I  (Eqs. 27–28); Δε is the tensor strain increment of Eq. 29 × Δt.
template <int D>
inline void elasticTrial(Sym<D>& s, const Sym<D>& de, Real K, Real G)
{
	const Real tr  = de.trace();
	const Real lam = K - 2 * G / 3;
	for (int k = 0; k < 3; ++k) s.c[k] += 2 * G * de.c[k] + lam * tr;
	for (int k = 3; k < Dim<D>::nSym; ++k) s.c[k] += 2 * G * de.c[k];
}

// Material kernel for purely elastic scenes: no state, no plasticity, no damage work.
template <int D>
struct LinearElastic {
	Real K, G;
	explicit LinearElastic(const ElasticMat& m) : K(m.bulk()), G(m.shear()) { }

	void update(Particles<D>&, size_t, Sym<D>& s, const Sym<D>& de, Real) const { elasticTrial(s, de, K, G); }
	// Stress the particle exerts on the grid (Eq. 21).
	Sym<D> forceStress(const Particles<D>& P, size_t p) const { return P.stress(p); }
	static constexpr Real volumeLimit(const Particles<D>&, size_t) { return INFINITY; } // no failure: no limit
};

} // namespace mpm
