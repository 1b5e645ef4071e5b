// Several materials per scene (e.g. DP–GK rock with an elastic grout infill, or two rock layers).
// Particle p has the material index P.mat[p] (uint8, up to 256 materials). The hot loops stay templated
// on the material kernel: a one-material scene runs LinearElastic<D> or DruckerPragerGradyKipp<D> as a
// compile-time single-material path (exactly the code of a one-material solver); a mixed scene runs
// MixedMaterial<D>, which switches on the particle's index into the same templated kernels (no virtual
// calls). The stable time step uses the largest P-wave speed over the materials, each with the lowest
// current density among its own particles.
#pragma once
#include "DruckerPragerGradyKipp.hpp"

namespace mpm {

enum class MaterialKind : int { None = -1, Elastic = 0, DruckerPragerGradyKipp = 1 };

template <int D>
struct MixedMaterial {
	uint8_t                                kind[256] = {}; // MaterialKind of material index m
	uint8_t                                slot[256] = {}; // position of m's kernel in el or dp
	Real                                   modulus[256] = {}; // P-wave modulus K + 4G/3 [Pa]
	std::vector<LinearElastic<D>>          el;
	std::vector<DruckerPragerGradyKipp<D>> dp;

	void update(Particles<D>& P, size_t p, Sym<D>& s, const Sym<D>& de, Real dt) const
	{
		const uint8_t m = P.mat[p];
		if (kind[m] == uint8_t(MaterialKind::Elastic)) el[slot[m]].update(P, p, s, de, dt);
		else dp[slot[m]].update(P, p, s, de, dt);
	}
	Sym<D> forceStress(const Particles<D>& P, size_t p) const
	{
		const uint8_t m = P.mat[p];
		return kind[m] == uint8_t(MaterialKind::Elastic) ? el[slot[m]].forceStress(P, p) : dp[slot[m]].forceStress(P, p);
	}
	Real volumeLimit(const Particles<D>& P, size_t p) const
	{
		const uint8_t m = P.mat[p];
		return kind[m] == uint8_t(MaterialKind::Elastic) ? el[slot[m]].volumeLimit(P, p) : dp[slot[m]].volumeLimit(P, p);
	}
};

// Density measure whose minimum sets the time step: v_c = √(M / min dtDensity) for a single material
// (dtDensity = ρ = m/V), v_c = √(1 / min dtDensity) for a mixed scene (dtDensity = ρ/M of the particle's
// own material), i.e. v_c = max over materials of √(M_k/ρ_min,k).
template <class Mat, int D>
inline Real dtDensity(const Mat&, const Particles<D>& P, size_t p) { return P.mass[p] / P.vol[p]; }
template <int D>
inline Real dtDensity(const MixedMaterial<D>& m, const Particles<D>& P, size_t p) { return P.mass[p] / P.vol[p] / m.modulus[P.mat[p]]; }

template <int D>
class MaterialSet {
public:
	struct Entry {
		MaterialKind kind;
		ElasticMat   elastic; // the elastic part (every material has one)
		DpGkMat      dpgk;    // valid when kind is DruckerPragerGradyKipp
	};

	size_t       size() const { return list.size(); }
	bool         single() const { return list.size() == 1; }
	const Entry& operator[](size_t i) const { return list.at(i); }
	bool         anyDpgk() const
	{
		for (const auto& e : list)
			if (e.kind == MaterialKind::DruckerPragerGradyKipp) return true;
		return false;
	}
	size_t add(const ElasticMat& m) { return push({ MaterialKind::Elastic, (m.validate(), m), DpGkMat {} }); }
	size_t add(const DpGkMat& m) { return push({ MaterialKind::DruckerPragerGradyKipp, (m.validate(), ElasticMat(m)), m }); }
	// The only material of a one-material scene, replaced by m (Solver::setMaterial, older scripts), with
	// every particle's damage threshold recomputed; a scene with several materials refuses (it would
	// silently change other regions). Checked before any change.
	template <class Mat>
	void replaceOnly(const Mat& m, Particles<D>& P)
	{
		if (!single())
			throw InputError("setMaterial: this solver holds " + std::to_string(size())
			                 + " materials; setMaterial replaces the only material of a one-material scene — use addMaterial and addParticles(…, material=index)");
		m.validate();
		if constexpr (std::is_same_v<Mat, DpGkMat>) m.checkThresholds(P.vol0.data(), P.n, cell, D); // ε_D⁰ ∈ (0, 1) before anything changes
		if constexpr (std::is_same_v<Mat, DpGkMat>) list[0] = { MaterialKind::DruckerPragerGradyKipp, ElasticMat(m), m };
		else list[0] = { MaterialKind::Elastic, m, DpGkMat {} };
		rebuild();
		if (anyDpgk() && P.n) P.ensureDamageState(), initDamageThresholds(P, 0);
	}
	// Material index given through the public API: an integer in [0, size()) (0 allowed before any material exists).
	void checkIndex(long i) const
	{
		if (i < 0 || (i >= long(list.size()) && !(i == 0 && list.empty())))
			throw InputError("material = " + std::to_string(i) + " is not a material index of this solver: allowed range [0, " + std::to_string(long(list.size()) - 1)
			                 + "] (addMaterial returns the index)");
	}

	// Calls f(kernel) once: the single-material kernel for a one-material scene, else the mixed one.
	template <class F>
	void dispatch(F&& f) const
	{
		if (!single()) return f(mixed);
		if (list[0].kind == MaterialKind::Elastic) f(LinearElastic<D>(list[0].elastic));
		else f(DruckerPragerGradyKipp<D>(list[0].dpgk, cell));
	}
	// v_c from the minimum of dtDensity (see above) [m/s].
	Real waveSpeed(Real minDtDensity) const { return std::sqrt((single() ? list[0].elastic.pWaveModulus() : 1.0) / minDtDensity); }
	Real minDtDensity(const Particles<D>& P) const
	{
		Real r = INFINITY;
		dispatch([&](const auto& k) {
			for (size_t p = 0; p < P.n; ++p) r = std::min(r, dtDensity(k, P, p));
		});
		return r;
	}
	const Entry& of(const Particles<D>& P, size_t p) const { return list[P.mat[p]]; }
	// The stress particle p carries: the damaged stress for DP–GK (Eq. 40), else the state.
	Sym<D> effectiveStress(const Particles<D>& P, size_t p) const
	{
		if (of(P, p).kind == MaterialKind::DruckerPragerGradyKipp) return DruckerPragerGradyKipp<D>::damaged(P.stress(p), P.damage[p]);
		return P.stress(p);
	}
	// Current cohesion of a DP–GK particle (Eq. 34) [Pa]; NaN for other materials.
	Real cohesion(const Particles<D>& P, size_t p) const
	{
		const auto& e = of(P, p);
		return e.kind == MaterialKind::DruckerPragerGradyKipp ? e.dpgk.cohesionAt(P.epsP[p]) : NAN;
	}
	// Elastic energy stored by the effective stress, Σ V (s:s/(4G) + σm²/(2K)) with each particle's K, G [J].
	Real elasticEnergy(const Particles<D>& P) const
	{
		Real e = 0;
		for (size_t p = 0; p < P.n; ++p) {
			const ElasticMat& m  = of(P, p).elastic;
			Sym<D>            s  = effectiveStress(P, p);
			Real              sm = s.toDeviator();
			e += P.vol[p] * (s.contract() / (4 * m.shear()) + sm * sm / (2 * m.bulk()));
		}
		return e;
	}
	// Eq. 37 thresholds ε_D⁰ (with a flaw population: of the first flaw) for particles [from, n) whose
	// material is DP–GK with damage on; allocates the activated-flaw counts when a material has flaws.
	void initDamageThresholds(Particles<D>& P, size_t from) const
	{
		ensureFlawCounts(P);
		for (size_t p = from; p < P.n; ++p) {
			const Entry& e = of(P, p);
			if (e.kind == MaterialKind::DruckerPragerGradyKipp && e.dpgk.damage) P.eps0[p] = initialThreshold(e.dpgk, P.vol0[p], cell, D, P.id[p]);
		}
	}
	// Particle slots `slots` take material index `material` (Solver::setParticleMaterial) and that
	// material's ε_D⁰ (Eq. 37 with its V reading; 0 where it has no damage) with no
	// activated flaws; damage and plastic strain stay (the particle's history). Checked before any change:
	// the index, every slot in [0, n) and every threshold in (0, 1).
	void assign(Particles<D>& P, const std::vector<size_t>& slots, long material) const
	{
		if (list.empty()) throw InputError("setParticleMaterial: no material in this solver yet; add one with addMaterial");
		checkIndex(material);
		std::vector<Real> vol0;
		for (size_t p : slots) {
			if (p >= P.n) throw InputError("setParticleMaterial: particle index " + std::to_string(p) + " is outside the allowed range [0, " + std::to_string(P.n) + ")");
			vol0.push_back(P.vol0[p]);
		}
		const Entry& e = list[size_t(material)];
		if (e.kind == MaterialKind::DruckerPragerGradyKipp) e.dpgk.checkThresholds(vol0.data(), vol0.size(), cell, D);
		for (size_t p : slots) P.mat[p] = uint8_t(material);
		if (!anyDpgk()) return;
		P.ensureDamageState();
		ensureFlawCounts(P);
		const bool threshold = e.kind == MaterialKind::DruckerPragerGradyKipp && e.dpgk.damage;
		for (size_t p : slots) {
			P.eps0[p] = threshold ? initialThreshold(e.dpgk, P.vol0[p], cell, D, P.id[p]) : 0.0;
			if (!P.nFlaw.empty()) P.nFlaw[p] = 0;
		}
	}
	// Grid spacing l [m]: the V readings and the regularised threshold of Eq. 37 depend on it.
	void setCell(Real l)
	{
		cell = l;
		rebuild();
	}

private:
	std::vector<Entry> list;
	Real               cell = 0; // grid spacing l [m]
	MixedMaterial<D>   mixed; // kernels of a mixed scene, rebuilt when the list changes (never while stepping)

	void ensureFlawCounts(Particles<D>& P) const // activated-flaw counts, allocated when a material has flaws
	{
		for (const auto& e : list)
			if (e.kind == MaterialKind::DruckerPragerGradyKipp && e.dpgk.damage && e.dpgk.flawCount > 0 && P.nFlaw.size() != P.n) P.nFlaw.assign(P.n, 0.0);
	}
	size_t push(const Entry& e)
	{
		if (list.size() >= 256) throw InputError("addMaterial: a solver holds at most 256 materials (particle material index is 8-bit)");
		list.push_back(e);
		rebuild();
		return list.size() - 1;
	}
	void rebuild()
	{
		mixed.el.clear(), mixed.dp.clear();
		for (size_t i = 0; i < list.size(); ++i) {
			const Entry& e     = list[i];
			mixed.kind[i]      = uint8_t(e.kind);
			mixed.modulus[i]   = e.elastic.pWaveModulus();
			if (e.kind == MaterialKind::Elastic) mixed.slot[i] = uint8_t(mixed.el.size()), mixed.el.emplace_back(e.elastic);
			else mixed.slot[i] = uint8_t(mixed.dp.size()), mixed.dp.emplace_back(e.dpgk, cell);
		}
	}
};

} // namespace mpm
