// Boost.Python binding of the MPM core (module yade_mpm._core): the same binding layer YADE uses.
// Particle fields are exposed as NumPy views on the solver's own arrays (no copy); the views keep
// the solver alive and stay valid while stepping (arrays are never reallocated during a step).
#include "../pkg-mpm/Solver.hpp"
#include "param_binding.hpp"
#include <boost/python.hpp>
#include <boost/python/numpy.hpp>

namespace bp = boost::python;
namespace np = boost::python::numpy;
using namespace mpm;

namespace {

PyObject* simulationErrorType = nullptr;

void translateInput(const InputError& e) { PyErr_SetString(PyExc_ValueError, e.what()); }
void translateSimulation(const SimulationError& e) { PyErr_SetString(simulationErrorType, e.what()); }

template <int D>
typename Dim<D>::Vec toVec(const bp::object& o, const char* name)
{
	if (bp::len(o) != D) throw InputError(std::string(name) + " must have " + std::to_string(D) + " components");
	typename Dim<D>::Vec v;
	for (int a = 0; a < D; ++a) v[a] = bp::extract<double>(o[a]);
	return v;
}
template <int D>
bp::tuple fromVec(const typename Dim<D>::Vec& v)
{
	if constexpr (D == 2) return bp::make_tuple(v[0], v[1]);
	else return bp::make_tuple(v[0], v[1], v[2]);
}

// A contiguous float64 array of the given shape, copied (asarray semantics), or an error naming `name`.
np::ndarray asDoubleArray(const bp::object& o, const char* name, int cols, size_t rows = size_t(-1))
{
	np::ndarray a = np::from_object(o, np::dtype::get_builtin<double>(), np::ndarray::C_CONTIGUOUS);
	const int   nd = a.get_nd();
	if ((cols == 0 && nd != 1) || (cols > 0 && (nd != 2 || a.shape(1) != cols)))
		throw InputError(std::string(name) + (cols == 0 ? " must be a 1-D array" : " must be an (N, " + std::to_string(cols) + ") array"));
	if (rows != size_t(-1) && size_t(a.shape(0)) != rows)
		throw InputError(std::string(name) + " has " + std::to_string(a.shape(0)) + " rows, expected " + std::to_string(rows));
	return a;
}

template <int D>
struct SolverWrap {
	using S = Solver<D>;

	static std::shared_ptr<S> make(bp::object origin, double spacing, bp::object cells)
	{
		typename Dim<D>::IVec n;
		if (bp::len(cells) != D) throw InputError("cells must have " + std::to_string(D) + " components");
		for (int a = 0; a < D; ++a) n[a] = bp::extract<int>(cells[a]);
		return std::make_shared<S>(toVec<D>(origin, "origin"), spacing, n);
	}
	static void addParticles(S& s, bp::object pos, bp::object vol, bp::object mass)
	{
		np::ndarray x = asDoubleArray(pos, "positions", D);
		size_t      n = x.shape(0);
		np::ndarray v = asDoubleArray(vol, "volumes", 0, n);
		np::ndarray m = asDoubleArray(mass, "masses", 0, n);
		s.addParticles(reinterpret_cast<double*>(x.get_data()), reinterpret_cast<double*>(v.get_data()), reinterpret_cast<double*>(m.get_data()), n);
	}
	static void setForces(S& s, bp::object idx, bp::object forces)
	{
		np::ndarray i = np::from_object(idx, np::dtype::get_builtin<int64_t>(), np::ndarray::C_CONTIGUOUS);
		if (i.get_nd() != 1) throw InputError("particle indices must be a 1-D integer array");
		size_t      n = i.shape(0);
		np::ndarray f = asDoubleArray(forces, "forces", D, n);
		auto*       ip = reinterpret_cast<int64_t*>(i.get_data());
		auto*       fp = reinterpret_cast<double*>(f.get_data());
		for (size_t k = 0; k < n; ++k) {
			if (ip[k] < 0) throw InputError("particle index " + std::to_string(ip[k]) + " is negative");
			typename Dim<D>::Vec fv;
			for (int a = 0; a < D; ++a) fv[a] = fp[k * D + a];
			s.setParticleForce(size_t(ip[k]), fv);
		}
	}
	static void addPlane(S& s, int axis, int side, double pos, const std::string& kind)
	{
		BoundaryKind k;
		if (kind == "fixed") k = BoundaryKind::Fixed;
		else if (kind == "slip") k = BoundaryKind::Slip;
		else throw InputError("boundary kind must be 'fixed' or 'slip' (got '" + kind + "')");
		s.addBoundaryPlane(axis, side, pos, k);
	}

	// NumPy view on one particle array. The owner reference keeps the solver alive.
	static np::ndarray view(bp::object self, const std::string& name)
	{
		S&                 s = bp::extract<S&>(self);
		auto&              P = s.P;
		std::vector<Real>* f = nullptr;
		auto comp = [&](const char* prefix, std::vector<Real>* arr, int count) {
			for (int k = 0; k < count; ++k)
				if (name == prefix + std::to_string(k)) f = &arr[k];
		};
		comp("x", P.x, D);
		comp("v", P.v, D);
		comp("C", P.C, D * D);
		comp("sig", P.sig, Dim<D>::nSym);
		comp("trac", P.trac, D);
		if (name == "mass") f = &P.mass;
		if (name == "vol") f = &P.vol;
		if (name == "vol0") f = &P.vol0;
		if (name == "epsP") f = &P.epsP;
		if (name == "damage") f = &P.damage;
		if (name == "eps0") f = &P.eps0;
		if (name == "id")
			return np::from_data(P.id.data(), np::dtype::get_builtin<int64_t>(), bp::make_tuple(P.n), bp::make_tuple(sizeof(int64_t)), self);
		if (!f) throw InputError("unknown particle field '" + name + "'");
		if (f->size() != P.n) throw InputError("particle field '" + name + "' is not allocated in this scene");
		return np::from_data(f->data(), np::dtype::get_builtin<double>(), bp::make_tuple(P.n), bp::make_tuple(sizeof(double)), self);
	}

	// Per-particle stress actually carried (damaged for DP–GK), shape (N, nSym), copied.
	static np::ndarray effectiveStress(S& s)
	{
		constexpr int NS = Dim<D>::nSym;
		np::ndarray   out = np::empty(bp::make_tuple(s.P.n, NS), np::dtype::get_builtin<double>());
		auto*         o   = reinterpret_cast<double*>(out.get_data());
		for (size_t p = 0; p < s.P.n; ++p) {
			Sym<D> t = s.effectiveStress(p);
			for (int k = 0; k < NS; ++k) o[p * NS + k] = t.c[k];
		}
		return out;
	}
	static np::ndarray maxPrincipalStress(S& s)
	{
		np::ndarray out = np::empty(bp::make_tuple(s.P.n), np::dtype::get_builtin<double>());
		auto*       o   = reinterpret_cast<double*>(out.get_data());
		for (size_t p = 0; p < s.P.n; ++p) o[p] = maxPrincipal<D>(s.effectiveStress(p));
		return out;
	}
	// ψ_i and ∇ψ_i at a point: (node indices, ψ, ∇ψ) over the 4^D stencil; for tests and inspection.
	static bp::tuple shapeFunctions(S& s, bp::object point)
	{
		auto       x = toVec<D>(point, "point");
		Stencil<D> st;
		StencilOffsets<D> so(s.grid);
		Real xa[D];
		for (int a = 0; a < D; ++a) {
			xa[a] = x[a];
			if (!(x[a] >= s.grid.origin[a] && x[a] < s.grid.upper()[a])) throw InputError("point is outside the grid");
		}
		if (!computeStencil(s.grid, so, xa, st)) throw SimulationError("singular WLS moment matrix at this point");
		constexpr int N   = Dim<D>::nStencil;
		np::ndarray   idx = np::empty(bp::make_tuple(N), np::dtype::get_builtin<int64_t>());
		np::ndarray   psi = np::empty(bp::make_tuple(N), np::dtype::get_builtin<double>());
		np::ndarray   grd = np::empty(bp::make_tuple(N, D), np::dtype::get_builtin<double>());
		for (int n = 0; n < N; ++n) {
			reinterpret_cast<int64_t*>(idx.get_data())[n] = int64_t(st.base + so.off[n]);
			reinterpret_cast<double*>(psi.get_data())[n]  = st.psi[n];
			for (int a = 0; a < D; ++a) reinterpret_cast<double*>(grd.get_data())[n * D + a] = st.grad[n][a];
		}
		return bp::make_tuple(idx, psi, grd, st.general);
	}
	static np::ndarray nodePositions(S& s)
	{
		np::ndarray out = np::empty(bp::make_tuple(s.grid.size(), D), np::dtype::get_builtin<double>());
		auto*       o   = reinterpret_cast<double*>(out.get_data());
		for (size_t i = 0; i < s.grid.size(); ++i) {
			auto x = s.grid.position(i);
			for (int a = 0; a < D; ++a) o[i * D + a] = x[a];
		}
		return out;
	}
	// Nodal lumped mass and momentum of the last P2G is overwritten within a step; this returns
	// the state after the last completed step: (mass, Shepard mass, MUSL velocity).
	static bp::tuple nodeState(S& s)
	{
		size_t      n  = s.grid.size();
		np::ndarray m  = np::empty(bp::make_tuple(n), np::dtype::get_builtin<double>());
		np::ndarray mw = np::empty(bp::make_tuple(n), np::dtype::get_builtin<double>());
		np::ndarray v  = np::empty(bp::make_tuple(n, D), np::dtype::get_builtin<double>());
		for (size_t i = 0; i < n; ++i) {
			reinterpret_cast<double*>(m.get_data())[i]  = s.grid.nodes[i].m;
			reinterpret_cast<double*>(mw.get_data())[i] = s.grid.nodes[i].mw;
			for (int a = 0; a < D; ++a) reinterpret_cast<double*>(v.get_data())[i * D + a] = s.grid.nodes[i].b[a];
		}
		return bp::make_tuple(m, mw, v);
	}
	static bp::dict phaseTimes(S& s)
	{
		bp::dict d;
		d["sort"]   = s.phase.sort;
		d["p2g"]    = s.phase.p2g;
		d["grid"]   = s.phase.grid;
		d["g2p"]    = s.phase.g2p;
		d["stress"] = s.phase.stress;
		return d;
	}
	static void resetPhaseTimes(S& s) { s.phase = PhaseTimes {}; }
	static void run(S& s, long n)
	{
		if (n < 0) throw InputError("number of steps must be ≥ 0");
		for (long k = 0; k < n; ++k) s.step();
	}
	static bp::tuple getGravity(S& s) { return fromVec<D>(s.gravity); }
	static void setGravity(S& s, bp::object g)
	{
		auto v = toVec<D>(g, "gravity");
		for (int a = 0; a < D; ++a) requireFinite(v[a], "gravity");
		s.gravity = v;
	}
	static size_t numParticles(S& s) { return s.P.n; }
	static size_t bytesPerParticle(S& s) { return s.P.bytesPerParticle(); }
	static double getSpacing(S& s) { return s.grid.spacing; }
	static bp::tuple getOrigin(S& s) { return fromVec<D>(s.grid.origin); }
	static bp::tuple getCells(S& s)
	{
		if constexpr (D == 2) return bp::make_tuple(s.grid.cells[0], s.grid.cells[1]);
		else return bp::make_tuple(s.grid.cells[0], s.grid.cells[1], s.grid.cells[2]);
	}
	static bp::tuple getStored(S& s)
	{
		if constexpr (D == 2) return bp::make_tuple(s.grid.stored[0], s.grid.stored[1]);
		else return bp::make_tuple(s.grid.stored[0], s.grid.stored[1], s.grid.stored[2]);
	}
	// Checkpoint (py/yade_mpm/checkpoint.py): the solver state that is not in the particle views.
	static bp::dict getResumeState(S& s)
	{
		const auto r = s.resumeState();
		bp::dict   d;
		d["steps"] = r.steps, d["time"] = r.time, d["lastDt"] = r.lastDt, d["externalWork"] = r.externalWork;
		d["vmax"] = r.vmax, d["rhoMin"] = r.rhoMin, d["massFloor"] = r.massFloor;
		d["needSort"] = r.needSort, d["needCheck"] = r.needCheck;
		const auto& st = s.schedule().start;
		np::ndarray a  = np::empty(bp::make_tuple(st.size()), np::dtype::get_builtin<uint32_t>());
		std::copy(st.begin(), st.end(), reinterpret_cast<uint32_t*>(a.get_data()));
		d["blockStart"] = a;
		int nReal       = 0; // particle arrays of the scene: the checkpoint must hold every one
		s.P.forEachRealField([&](std::vector<Real>&) { ++nReal; });
		d["realFields"] = nReal;
		return d;
	}
	static void setResumeState(S& s, bp::dict d)
	{
		typename S::ResumeState r;
		r.steps        = bp::extract<long>(d["steps"]);
		r.time         = bp::extract<double>(d["time"]);
		r.lastDt       = bp::extract<double>(d["lastDt"]);
		r.externalWork = bp::extract<double>(d["externalWork"]);
		r.vmax         = bp::extract<double>(d["vmax"]);
		r.rhoMin       = bp::extract<double>(d["rhoMin"]);
		r.massFloor    = bp::extract<double>(d["massFloor"]);
		r.needSort     = bp::extract<bool>(d["needSort"]);
		r.needCheck    = bp::extract<bool>(d["needCheck"]);
		np::ndarray a  = np::from_object(d["blockStart"], np::dtype::get_builtin<uint32_t>(), np::ndarray::C_CONTIGUOUS);
		if (a.get_nd() != 1) throw InputError("checkpoint: blockStart must be a 1-D array");
		auto* p = reinterpret_cast<uint32_t*>(a.get_data());
		s.setResumeState(r, std::vector<uint32_t>(p, p + a.shape(0)));
	}
	static void setNodeExcluded(S& s, size_t i, bool ex) { s.grid.setExcluded(i, ex); }
	static int materialKind(S& s) { return int(s.materialKind()); }

	// Settings are routed through one validating setter so every bad value raises ValueError.
	template <Real S::*field>
	static Real getR(S& s) { return s.*field; }
	static void setDamping(S& s, double v) { s.setSetting("damping", v); }
	static void setCourant(S& s, double v) { s.setSetting("courant", v); }
	static void setFixedDt(S& s, double v) { s.setSetting("fixedDt", v); }
	static void setRamp(S& s, double v) { s.setSetting("tractionRampTime", v); }
	static int  getSortPeriod(S& s) { return s.sortPeriod; }
	static void setSortPeriod(S& s, int v) { s.setSetting("sortPeriod", v); }

	static void expose(const char* name)
	{
		bp::class_<S, std::shared_ptr<S>, boost::noncopyable>(name, "Explicit WLS-MPM solver (MUSL) on a fixed regular grid.", bp::no_init)
		        .def("__init__", bp::make_constructor(&make, bp::default_call_policies(), (bp::arg("origin"), bp::arg("spacing"), bp::arg("cells"))))
		        .def("addParticles", &addParticles, (bp::arg("positions"), bp::arg("volumes"), bp::arg("masses")))
		        .def("setMaterial", static_cast<void (S::*)(const ElasticMat&)>(&S::setMaterial))
		        .def("setMaterial", static_cast<void (S::*)(const DpGkMat&)>(&S::setMaterial))
		        .def("addBoundaryPlane", &addPlane, (bp::arg("axis"), bp::arg("side"), bp::arg("position"), bp::arg("kind")))
		        .def("setParticleForces", &setForces, (bp::arg("indices"), bp::arg("forces")))
		        .def("step", static_cast<void (S::*)()>(&S::step))
		        .def("advance", &S::advance, bp::arg("dt"))
		        .def("run", &run, bp::arg("steps"))
		        .def("stableDt", &S::stableDt)
		        .def("waveSpeed", &S::waveSpeed)
		        .def("view", &view, bp::arg("name"))
		        .def("effectiveStress", &effectiveStress)
		        .def("maxPrincipalStress", &maxPrincipalStress)
		        .def("kineticEnergy", &S::kineticEnergy)
		        .def("elasticEnergy", &S::elasticEnergy)
		        .def("shapeFunctions", &shapeFunctions, bp::arg("point"))
		        .def("nodePositions", &nodePositions)
		        .def("nodeState", &nodeState)
		        .def("setNodeExcluded", &setNodeExcluded, (bp::arg("node"), bp::arg("excluded")))
		        .def("phaseTimes", &phaseTimes)
		        .def("resetPhaseTimes", &resetPhaseTimes)
		        .def("requestSort", &S::requestSort)
		        .def("getResumeState", &getResumeState)
		        .def("setResumeState", &setResumeState, bp::arg("state"))
		        .def("elasticParameters", &S::elasticParameters, bp::return_value_policy<bp::copy_const_reference>())
		        .def("dpgkParameters", &S::dpgkParameters, bp::return_value_policy<bp::copy_const_reference>())
		        .def("loadScale", &S::loadScale)
		        .add_property("numParticles", &numParticles)
		        .add_property("bytesPerParticle", &bytesPerParticle)
		        .add_property("materialKind", &materialKind)
		        .add_property("spacing", &getSpacing)
		        .add_property("origin", &getOrigin)
		        .add_property("cells", &getCells)
		        .add_property("storedNodes", &getStored)
		        .add_property("gravity", &getGravity, &setGravity)
		        .add_property("damping", &getR<&S::damping>, &setDamping)
		        .add_property("courant", &getR<&S::courant>, &setCourant)
		        .add_property("fixedDt", &getR<&S::fixedDt>, &setFixedDt)
		        .add_property("tractionRampTime", &getR<&S::tractionRampTime>, &setRamp)
		        .add_property("sortPeriod", &getSortPeriod, &setSortPeriod)
		        .def_readwrite("autoDt", &S::autoDt)
		        .def_readwrite("trackEnergy", &S::trackEnergy)
		        .def_readwrite("time", &S::time)
		        .def_readonly("steps", &S::steps)
		        .def_readonly("lastDt", &S::lastDt)
		        .def_readwrite("externalWork", &S::externalWork)
		        .add_property("maxSpeed", &S::maxSpeed);
	}
};

// Single material point DP–GK update, for tests and for checking the return map by hand.
template <int D>
bp::tuple dpgkPointUpdate(const DpGkMat& m, bp::object stress, bp::object strainInc, double epsP, double damage, double eps0, double dt)
{
	m.validate();
	constexpr int NS = Dim<D>::nSym;
	if (bp::len(stress) != NS || bp::len(strainInc) != NS) throw InputError("stress and strainInc need " + std::to_string(NS) + " components");
	DruckerPragerGradyKipp<D> mat(m);
	Sym<D>                    s, de;
	for (int k = 0; k < NS; ++k) {
		s.c[k]  = bp::extract<double>(stress[k]);
		de.c[k] = bp::extract<double>(strainInc[k]);
	}
	elasticTrial(s, de, mat.K, mat.G);
	ReturnInfo r;
	if (m.plasticity) r = mat.plasticReturn(s, epsP);
	if (m.damage) mat.damageGrowth(s, damage, eps0, dt);
	Sym<D>    eff = DruckerPragerGradyKipp<D>::damaged(s, damage);
	bp::list  ls, le;
	for (int k = 0; k < NS; ++k) ls.append(s.c[k]), le.append(eff.c[k]);
	return bp::make_tuple(ls, le, epsP, damage, r.mode, r.dLambda);
}

void setThreads(int n)
{
	if (n < 1) throw InputError("threads must be ≥ 1");
	omp_set_num_threads(n);
}
int getThreads() { return omp_get_max_threads(); }

} // namespace

BOOST_PYTHON_MODULE(_core)
{
	Py_Initialize();
	np::initialize();
	simulationErrorType = PyErr_NewException("yade_mpm._core.MpmSimulationError", PyExc_RuntimeError, nullptr);
	bp::scope().attr("MpmSimulationError") = bp::handle<>(bp::borrowed(simulationErrorType));
	bp::register_exception_translator<InputError>(&translateInput);
	bp::register_exception_translator<SimulationError>(&translateSimulation);

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

	SolverWrap<2>::expose("Solver2D");
	SolverWrap<3>::expose("Solver3D");
	bp::def("dpgkPointUpdate2D", &dpgkPointUpdate<2>);
	bp::def("dpgkPointUpdate3D", &dpgkPointUpdate<3>);
	bp::def("setThreads", &setThreads);
	bp::def("getThreads", &getThreads);
}
