// Solver2D/3D: construction, materials of a scene, particles, boundary planes, stepping and the grid's
// geometry; the class is created here and the other binding files add their methods to it.
#include "binding_common.hpp"
#include <unistd.h>

namespace mpm {
namespace {

template <int D>
struct SolverWrap {
	using S = Solver<D>;
	static std::string who(const char* what) { return solverName(D) + ": " + what; }

	// distribute (MPI, > 1 rank): the grid starts with one node layer and Decomposition::distribute gives it this
	// rank's window at once, so no rank ever allocates the whole grid (yade_mpm.make_solver(…, distribute=True)).
	static std::shared_ptr<S> make(bp::object origin, bp::object spacing, bp::object cells, bp::object distribute)
	{
#ifdef MPM_MPI
		const bool dist = argBool(distribute, who("distribute")) && Comm::size() > 1;
#else
		const bool dist = argBool(distribute, who("distribute")) && false; // the serial core: 1 process, the whole grid
#endif
		const auto o = toVec<D>(origin, who("origin"));
		const Real h = argReal(spacing, who("spacing"), "m", 0, INFINITY, OO);
		PyObject*  q = cells.ptr();
		if (!(PySequence_Check(q) && !PyUnicode_Check(q) && PySequence_Size(q) == D)) {
			PyErr_Clear();
			throw InputError(who("cells") + " must be a sequence of " + std::to_string(D) + " integers ≥ 1 (got " + pyTypeName(q) + " " + pyRepr(cells) + ")");
		}
		typename Dim<D>::IVec n;
		double nodes = 1;
		for (int a = 0; a < D; ++a) {
			n[a] = int(argInt(cells[a], who("cells") + "[" + std::to_string(a) + "]", 1, 1 << 24));
			if (!std::isfinite(o[a] + n[a] * h))
				throw InputError(who("origin") + " + cells·spacing along axis " + std::to_string(a) + " is not a finite coordinate (origin "
				                 + ParamInfo::num(o[a]) + " m, spacing " + ParamInfo::num(h) + " m)");
			nodes *= n[a] + 1 + 2 * Grid<D>::ghost;
		}
		// Refuse a grid the machine cannot hold, with the numbers.
		const double bytes = nodes * (sizeof(Node<D>) + 2), phys = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
		if (bytes > phys && !dist)
			throw InputError(who("cells") + ": a grid of " + ParamInfo::num(nodes) + " nodes needs " + ParamInfo::num(bytes / 1e9) + " GB, more than this machine's "
			                 + ParamInfo::num(phys / 1e9) + " GB of memory; use fewer cells or a larger spacing");
		if (!dist) return std::make_shared<S>(o, h, n);
		auto s = std::make_shared<S>(o, h, n, 0, 1);
		MPM_IF_MPI(s->dd.distribute(s->grid, 0);)
		return s;
	}
	// Calls f(material) with the ElasticMat or DpGkMat inside m, or refuses m naming `what`.
	template <class F>
	static auto withMat(bp::object m, const char* what, F&& f)
	{
		bp::extract<const DpGkMat&> dp(m);
		if (dp.check()) return f(dp());
		bp::extract<const ElasticMat&> el(m);
		if (el.check()) return f(el());
		throw InputError(who(what) + " must be an ElasticMat or a DpGkMat (got " + pyTypeName(m.ptr()) + ")");
	}
	static void setMaterial(S& s, bp::object m)
	{
		withMat(m, "setMaterial: material", [&](const auto& mat) { s.setMaterial(mat); });
	}
	static size_t addMaterial(S& s, bp::object m)
	{
		return withMat(m, "addMaterial: material", [&](const auto& mat) { return s.addMaterial(mat); });
	}
	static size_t materialIndex(S& s, bp::object i, const char* what)
	{
		if (s.materialSet().size() == 0) throw InputError(who(what) + ": this solver has no material yet (add_region adds one)");
		return size_t(argInt(i, who(what), 0, double(s.materialSet().size() - 1)));
	}
	// Copy of material i as the Python object it was given as (ElasticMat or DpGkMat).
	static bp::object material(S& s, bp::object i)
	{
		const auto& e = s.materialSet()[materialIndex(s, i, "material: index")];
		if (e.kind == MaterialKind::DruckerPragerGradyKipp) return bp::object(std::make_shared<DpGkMat>(e.dpgk));
		return bp::object(std::make_shared<ElasticMat>(e.elastic));
	}
	static size_t    numMaterials(S& s) { return s.materialSet().size(); }
	static bp::tuple materialKinds(S& s)
	{
		bp::list l;
		for (size_t i = 0; i < s.materialSet().size(); ++i) l.append(int(s.materialSet()[i].kind));
		return bp::tuple(l);
	}
	static np::ndarray cohesion(S& s)
	{
		np::ndarray out = np::empty(bp::make_tuple(s.P.n), np::dtype::get_builtin<double>());
		auto*       o   = reinterpret_cast<double*>(out.get_data());
		for (size_t p = 0; p < s.P.n; ++p) o[p] = s.cohesion(p);
		return out;
	}
	static void advance(S& s, bp::object dt) { s.advance(argReal(dt, who("advance: dt"), "s", 0, INFINITY, OO)); }
	static Real loadScale(S& s, bp::object t) { return s.loadScale(argReal(t, who("loadScale: t"), "s")); }
	static void addParticles(S& s, bp::object pos, bp::object vol, bp::object mass, bp::object matO)
	{
		const long mat = long(argInt(matO, who("addParticles: material (index from addMaterial)"), 0, 255));
		s.materialSet().checkIndex(mat);
		np::ndarray x = asDoubleArray(pos, "positions", D);
		size_t      n = x.shape(0);
		np::ndarray v = asDoubleArray(vol, "volumes", 0, n);
		np::ndarray m = asDoubleArray(mass, "masses", 0, n);
		s.addParticles(reinterpret_cast<double*>(x.get_data()), reinterpret_cast<double*>(v.get_data()), reinterpret_cast<double*>(m.get_data()), n, mat);
	}
	// A 1-D array of particle slots (storage order), each in [0, n), checked before the caller changes anything.
	static std::vector<size_t> slotsArg(bp::object idx, const char* what, size_t n)
	{
		bp::object  raw  = bp::import("numpy").attr("asarray")(idx);
		std::string kind = bp::extract<std::string>(raw.attr("dtype").attr("kind"));
		if (bp::len(raw.attr("shape")) != 1 || (kind != "i" && kind != "u" && bp::len(raw) > 0))
			throw InputError(who(what) + " must be a 1-D array of integer particle slots (got " + pyTypeName(idx.ptr()) + " " + pyRepr(idx) + ")");
		if (bp::len(raw) == 0) raw = raw.attr("astype")("int64"); // [] is float64 to NumPy
		np::ndarray i  = np::from_object(raw, np::dtype::get_builtin<int64_t>(), np::ndarray::C_CONTIGUOUS);
		auto*       ip = reinterpret_cast<int64_t*>(i.get_data());
		std::vector<size_t> slots(size_t(i.shape(0)));
		for (size_t k = 0; k < slots.size(); ++k) {
			if (ip[k] < 0) throw InputError("particle index " + std::to_string(ip[k]) + " is negative");
			if (size_t(ip[k]) >= n)
				throw InputError(who(what) + ": particle index " + std::to_string(ip[k]) + " is outside the allowed range [0, " + std::to_string(n) + ")");
			slots[k] = size_t(ip[k]);
		}
		return slots;
	}
	static void setForces(S& s, bp::object idx, bp::object forces)
	{
		const auto  slots = slotsArg(idx, "setParticleForces: indices", s.P.n);
		np::ndarray f     = asDoubleArray(forces, "forces", D, slots.size());
		auto*       fp    = reinterpret_cast<double*>(f.get_data());
		for (size_t k = 0; k < slots.size() * D; ++k) requireFinite(fp[k], "particle surface force"); // all or nothing
		for (size_t k = 0; k < slots.size(); ++k) {
			typename Dim<D>::Vec fv;
			for (int a = 0; a < D; ++a) fv[a] = fp[k * D + a];
			s.setParticleForce(slots[k], fv);
		}
	}
	static void setParticleMaterial(S& s, bp::object idx, bp::object material)
	{
		const auto slots = slotsArg(idx, "setParticleMaterial: indices", s.P.n);
		s.setParticleMaterial(slots, argInt(material, who("setParticleMaterial: material"), 0, 255));
	}
	static void addPlane(S& s, bp::object axisO, bp::object sideO, bp::object posO, bp::object kindO)
	{
		const int         axis = int(argInt(axisO, who("addBoundaryPlane: axis"), 0, D - 1));
		const int         side = int(argInt(sideO, who("addBoundaryPlane: side (-1 lower, +1 upper)"), -1, 1));
		const Real        pos  = argReal(posO, who("addBoundaryPlane: position"), "m");
		const std::string kind = argStr(kindO, who("addBoundaryPlane: kind ('fixed' or 'slip')"));
		BoundaryKind k;
		if (kind == "fixed") k = BoundaryKind::Fixed;
		else if (kind == "slip") k = BoundaryKind::Slip;
		else if (kind == "slip-onesided") k = BoundaryKind::SlipOneSided;
		else throw InputError("boundary kind must be 'fixed', 'slip' or 'slip-onesided' (got '" + kind + "')");
		s.addBoundaryPlane(axis, side, pos, k);
	}

	static void run(S& s, bp::object steps)
	{
		const long long n = argInt(steps, who("run: steps"), 0, 9.2e18);
		for (long long k = 0; k < n; ++k) s.step();
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
	static void setNodeExcluded(S& s, bp::object i, bp::object ex)
	{
		s.grid.setExcluded(size_t(argInt(i, who("setNodeExcluded: node"), 0, double(s.grid.size() - 1))), argBool(ex, who("setNodeExcluded: excluded")));
	}
	static int materialKind(S& s) { return int(s.materialKind()); }

	static void reserve(S& s, bp::object n) { s.reserve(size_t(argInt(n, who("reserve: particles"), 0, 4e9))); }

	static void expose(SolverClass<D>& cls, const char* name)
	{
		cls.def("__init__", bp::make_constructor(&make, bp::default_call_policies(), (bp::arg("origin"), bp::arg("spacing"), bp::arg("cells"), bp::arg("distribute") = false)))
		        .def("_addParticles", &addParticles, (bp::arg("positions"), bp::arg("volumes"), bp::arg("masses"), bp::arg("material") = 0),
		             "Adds particles (positions (N, D) [m], volumes [m³], masses [kg]) of material index `material` (addMaterial's return value).")
		        .def("_addMaterial", &addMaterial, bp::arg("material"), "Adds an ElasticMat or DpGkMat to the scene; returns its index for addParticles.")
		        .def("material", &material, bp::arg("index"), "Copy of material `index` (ElasticMat or DpGkMat).")
		        .def("_cohesion", &cohesion, "Current cohesion per particle (Eq. 34) [Pa], storage order; NaN for non-DP–GK particles.")
		        .def("_setMaterial", &setMaterial, bp::arg("material"))
		        .def("addBoundaryPlane", &addPlane, (bp::arg("axis"), bp::arg("side"), bp::arg("position"), bp::arg("kind")))
		        .def("_setParticleForces", &setForces, (bp::arg("indices"), bp::arg("forces")))
		        .def("setParticleMaterial", &setParticleMaterial, (bp::arg("indices"), bp::arg("material")),
		             "Particle slots `indices` (storage order, as the views) take material index `material` (material(i) reads it back, "
		             "range [0, numMaterials - 1]) and that material's damage threshold eps0 (Eq. 37; 0 without damage), with no activated "
		             "flaws; damage and plastic strain stay. The view 'material' is read-only: use this.")
		        .def("_advance", &advance, bp::arg("dt"))
		        .def("run", &run, bp::arg("steps"))
		        .def("stableDt", &S::stableDt)
		        .def("waveSpeed", &S::waveSpeed)
		        .def("kineticEnergy", &S::kineticEnergy)
		        .def("elasticEnergy", &S::elasticEnergy)
		        .def("_setNodeExcluded", &setNodeExcluded, (bp::arg("node"), bp::arg("excluded")))
		        .def("requestSort", &S::requestSort)
		        .def("_loadScale", &loadScale, bp::arg("t"))
		        .add_property("numParticles", &numParticles)
		        .add_property("_bytesPerParticle", &bytesPerParticle)
		        .add_property("_materialKind", &materialKind, "kind of material 0: 0 elastic, 1 DP–GK, -1 none (see materialKinds)")
		        .add_property("_materialKinds", &materialKinds, "kind of every material, by index: 0 elastic, 1 DP–GK")
		        .add_property("numMaterials", &numMaterials)
		        .add_property("spacing", &getSpacing)
		        .add_property("origin", &getOrigin)
		        .add_property("cells", &getCells)
		        .add_property("_storedNodes", &getStored)
		        .def("reserve", &reserve, bp::arg("particles"),
		             "Room for this many particles: later addParticles up to that count keep the arrays (and live views) in place.")
		        .def_readonly("lastDt", &S::lastDt)
		        .add_property("maxSpeed", &S::maxSpeed);
	}
};
} // namespace

MPM_EXPOSE_SOLVER_PART(exposeSolverCore, SolverWrap)
// The class: created here, the other binding files add their methods.
template <int D>
void exposeSolver(const char* name)
{
	ParamBinding<Solver<D>>::declare(name);
	SolverClass<D> cls(name, "Explicit WLS-MPM solver (MUSL) on a fixed regular grid.", bp::no_init);
	exposeSolverCore<D>(cls, name);
	exposeState<D>(cls, name);
	exposeViews<D>(cls, name);
	exposeContact<D>(cls, name);
	MPM_IF_MPI(exposeMpi<D>(cls, name);)
}
template void exposeSolver<2>(const char*);
template void exposeSolver<3>(const char*);
} // namespace mpm
