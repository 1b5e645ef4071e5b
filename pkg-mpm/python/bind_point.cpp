// The single material-point DP–GK update (the same updatePoint the solver runs) and the damage thresholds of
// Eq. 37 and of the Benz–Asphaug flaws, for tests and for checking the return map by hand.
#include "binding_common.hpp"

namespace mpm {
namespace {

// Single material point DP–GK update (the same updatePoint the solver runs), for tests and for checking
// the return map by hand. With m.flawCount > 0, nFlaw/vol0/id/spacing describe the particle's flaws.
template <int D>
bp::tuple dpgkPointUpdate(bp::object matO, bp::object stress, bp::object strainInc, bp::object epsPO, bp::object damageO, bp::object eps0O, bp::object dtO,
                          bp::object nFlawO, bp::object vol0O, bp::object idO, bp::object spacingO)
{
	const std::string fn = "dpgkPointUpdate" + std::to_string(D) + "D: ";
	bp::extract<const DpGkMat&> mx(matO);
	if (!mx.check()) throw InputError(fn + "material must be a DpGkMat (got " + pyTypeName(matO.ptr()) + ")");
	const DpGkMat& m = mx();
	m.validate();
	constexpr int NS = Dim<D>::nSym;
	const auto    sv = argReals(stress, fn + "stress", NS, "Pa");
	const auto    dv = argReals(strainInc, fn + "strainInc", NS, "-");
	Real epsP   = argReal(epsPO, fn + "epsP (accumulated plastic strain)", "-", 0, INFINITY, CO);
	Real damage = argReal(damageO, fn + "damage", "-", 0, 1, CC);
	Real eps0   = argReal(eps0O, fn + "eps0 (damage threshold strain)", "-", 0, INFINITY, OO);
	Real dt     = argReal(dtO, fn + "dt", "s", 0, INFINITY, CO);
	Real nFlaw  = argReal(nFlawO, fn + "nFlaw (activated flaws)", "-", 0, m.flawCount, CC);
	const Real vol0    = argReal(vol0O, fn + "vol0 (initial particle volume)", "m³", 0, INFINITY, CO);
	const Real spacing = argReal(spacingO, fn + "spacing (grid spacing)", "m", 0, INFINITY, CO);
	const Real idR     = argReal(idO, fn + "id (particle id)", "-", 0, 9.0e15, CC);
	if (m.flawCount > 0 && !(vol0 > 0 && spacing > 0)) throw InputError(fn + "with flawCount > 0, vol0 [m³] and spacing [m] must be > 0");
	DruckerPragerGradyKipp<D> mat(m, spacing);
	Sym<D>                    s, de;
	for (int k = 0; k < NS; ++k) s.c[k] = sv[k], de.c[k] = dv[k];
	ReturnInfo r = mat.updatePoint(s, de, epsP, damage, eps0, dt, m.flawCount > 0 ? &nFlaw : nullptr, vol0, int64_t(idR));
	Sym<D>    eff = DruckerPragerGradyKipp<D>::damaged(s, damage);
	bp::list  ls, le;
	for (int k = 0; k < NS; ++k) ls.append(s.c[k]), le.append(eff.c[k]);
	return bp::make_tuple(ls, le, epsP, damage, r.mode, r.dLambda, nFlaw);
}

// Thresholds ε_1 … ε_count of the Benz–Asphaug flaws of particle id for the threshold scale ε_D⁰.
bp::list flawThresholds(const DpGkMat& m, double scale, long id, int count)
{
	m.validate();
	if (!(scale > 0 && scale < INFINITY)) throw InputError("dpgkFlawThresholds: scale = " + ParamInfo::num(scale) + " [-] must be in (0, inf)");
	if (id < 0) throw InputError("dpgkFlawThresholds: id = " + std::to_string(id) + " must be ≥ 0");
	if (count < 1 || count > 1000) throw InputError("dpgkFlawThresholds: count = " + std::to_string(count) + " must be in [1, 1000]");
	bp::list out;
	for (int j = 1; j <= count; ++j) out.append(flawThreshold(m, scale, id, j));
	return out;
}
// ε_D⁰ of a particle of initial volume vol0 [m³] on a grid of spacing l [m] (V reading and regularisation).
double thresholdScale(const DpGkMat& m, double vol0, double spacing, int dim)
{
	m.validate();
	if (dim != 2 && dim != 3) throw InputError("dpgkThresholdScale: dim = " + std::to_string(dim) + " must be 2 or 3");
	if (!(vol0 > 0 && vol0 < INFINITY)) throw InputError("dpgkThresholdScale: vol0 = " + ParamInfo::num(vol0) + " [m³] must be in (0, inf)");
	if (!(spacing > 0 && spacing < INFINITY)) throw InputError("dpgkThresholdScale: spacing = " + ParamInfo::num(spacing) + " [m] must be in (0, inf)");
	return m.thresholdScale(vol0, spacing, dim);
}

} // namespace

void exposePointUpdate()
{
	const auto pointArgs = (bp::arg("material"), bp::arg("stress"), bp::arg("strainInc"), bp::arg("epsP"), bp::arg("damage"), bp::arg("eps0"), bp::arg("dt"),
	                        bp::arg("nFlaw") = 0.0, bp::arg("vol0") = 0.0, bp::arg("id") = 0, bp::arg("spacing") = 0.0);
	const char* pointDoc  = "One DP–GK material-point update: (state stress, damaged stress, epsP, damage, mode 0/1/2 elastic/cone/apex, Δλ, nFlaw). "
	                        "With material.flawCount > 0: nFlaw = activated flaws, vol0 [m³], id, spacing [m] of the particle.";
	bp::def("dpgkPointUpdate2D", &dpgkPointUpdate<2>, pointArgs, pointDoc);
	bp::def("dpgkPointUpdate3D", &dpgkPointUpdate<3>, pointArgs, pointDoc);
	bp::def("dpgkFlawThresholds", &flawThresholds, (bp::arg("material"), bp::arg("scale"), bp::arg("id"), bp::arg("count")),
	        "Thresholds ε_1 < … < ε_count [-] of the Benz–Asphaug flaws of particle `id` for threshold scale ε_D⁰ = `scale` (flawSeed of the material).");
	bp::def("dpgkThresholdScale", &thresholdScale, (bp::arg("material"), bp::arg("vol0"), bp::arg("spacing"), bp::arg("dim")),
	        "ε_D⁰ [-] of a particle of initial volume vol0 [m³] on a grid of spacing [m] in dim = 2 or 3 (V reading of Eq. 37 and regularisation).");
}

} // namespace mpm
