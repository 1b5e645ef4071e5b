// The parameter classes, each generated from its one declaration (ParamTable.hpp): ElasticMat and DpGkMat
// (MaterialParams.hpp) and ContactParams (ContactParams.hpp): properties with unit and range, keyword
// constructors, toDict/fromDict (checkpoints), paramTable().
#include "binding_common.hpp"

namespace mpm {

void exposeMaterials()
{
	// Materials: properties, keyword constructors, toDict/fromDict generated from MaterialParams.hpp.
	using EB = ParamBinding<ElasticMat>;
	EB::declare("ElasticMat");
	bp::class_<ElasticMat, std::shared_ptr<ElasticMat>> elasticCls("ElasticMat", EB::classDoc("Linear elastic material (Eqs. 27–29).").c_str(), bp::no_init);
	EB::expose(elasticCls);
	elasticCls.def("bulk", &ElasticMat::bulk, "bulk modulus K [Pa]")
	        .def("shear", &ElasticMat::shear, "shear modulus G [Pa]")
	        .def("pWaveSpeed", &ElasticMat::pWaveSpeed, "P-wave speed √((K + 4G/3)/ρ) [m/s]");
	using DB = ParamBinding<DpGkMat>;
	DB::declare("DpGkMat", { { "dilatancyAngle", "dilationAngle" } });
	bp::class_<DpGkMat, std::shared_ptr<DpGkMat>, bp::bases<ElasticMat>> dpgkCls(
	        "DpGkMat", DB::classDoc("Drucker–Prager plasticity + Grady–Kipp damage rock (paper Sec. 2.4, Eqs. 27–40).").c_str(), bp::no_init);
	DB::expose(dpgkCls);
	dpgkCls.def("qPhi", &DpGkMat::qPhi, "q_φ of Eq. 31 [-]")
	        .def("kPhi", &DpGkMat::kPhi, "k̄_φ of Eq. 31 [-]")
	        .def("qPsi", &DpGkMat::qPsi, "q_ψ of Eq. 33 [-]")
	        .def("cohesionAt", &DpGkMat::cohesionAt, bp::arg("epsP"), "softened cohesion c(ε̄p) of Eq. 34 [Pa]")
	        .def("alpha", &DpGkMat::alpha, "α of Eq. 39 [m⁻³]")
	        .def("activationStrain", &DpGkMat::activationStrain, bp::arg("volume"), "damage threshold ε_D⁰ = (Vk)^(−1/m) of Eq. 37 [-] for a particle volume V [m³]")
	        .def("effectiveCrackSpeed", &DpGkMat::effectiveCrackSpeed, "c_g actually used [m/s]");

	// Contact parameters of one contact group (ContactParams.hpp); ym.RigidBodies/DemSpheres.add build one
	// from their keywords (d0 = None / 'initial' / a number set autoD0, initialD0, d0).
	using CB = ParamBinding<ContactParams>;
	CB::declare("ContactParams");
	bp::class_<ContactParams, std::shared_ptr<ContactParams>> contactCls(
	        "ContactParams", CB::classDoc("Parameters of the PTS contact of one contact group (paper Sec. 2.3, Eqs. 23–26).").c_str(), bp::no_init);
	CB::expose(contactCls);
	contactCls.def("validateFor", &ContactParams::validateFor, bp::arg("spacing"),
	               "validate() and, with the grid spacing l [m]: a fixed d0 (autoD0 off) is at most l.");
}

} // namespace mpm
