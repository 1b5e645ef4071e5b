// Boost.Python binding of the MPM core (module yade_mpm._core): the same binding layer YADE uses.
// Particle fields are exposed as NumPy views on the solver's own arrays (no copy); the views keep
// the solver alive and stay valid while stepping (arrays are never reallocated during a step).
#include "../pkg-mpm/Solver.hpp"
#include "param_binding.hpp"
#include <boost/python.hpp>
#include <boost/python/numpy.hpp>
#include <unistd.h>

namespace bp = boost::python;
namespace np = boost::python::numpy;
using namespace mpm;

namespace {

PyObject* simulationErrorType = nullptr;

void translateInput(const InputError& e) { PyErr_SetString(PyExc_ValueError, e.what()); }
void translateSimulation(const SimulationError& e) { PyErr_SetString(simulationErrorType, e.what()); }

template <int D>
typename Dim<D>::Vec toVec(const bp::object& o, const std::string& name, const char* unit = "m")
{
	auto                 c = argReals(o, name, D, unit);
	typename Dim<D>::Vec v;
	for (int a = 0; a < D; ++a) v[a] = c[a];
	return v;
}
inline std::string solverName(int D) { return D == 2 ? "Solver2D" : "Solver3D"; }
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

	static std::string who(const char* what) { return solverName(D) + ": " + what; }

	static std::shared_ptr<S> make(bp::object origin, bp::object spacing, bp::object cells)
	{
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
		// Refuse a grid the machine cannot hold, with the numbers (was an empty MemoryError).
		const double bytes = nodes * (sizeof(Node<D>) + 2), phys = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
		if (bytes > phys)
			throw InputError(who("cells") + ": a grid of " + ParamInfo::num(nodes) + " nodes needs " + ParamInfo::num(bytes / 1e9) + " GB, more than this machine's "
			                 + ParamInfo::num(phys / 1e9) + " GB of memory; use fewer cells or a larger spacing");
		return std::make_shared<S>(o, h, n);
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
		if (s.materialSet().size() == 0) throw InputError(who(what) + ": this solver has no material yet (setMaterial or addMaterial first)");
		return size_t(argInt(i, who(what), 0, double(s.materialSet().size() - 1)));
	}
	// Copy of material i as the Python object it was given as (ElasticMat or DpGkMat).
	static bp::object material(S& s, bp::object i)
	{
		const auto& e = s.materialSet()[materialIndex(s, i, "material: index")];
		if (e.kind == MaterialKind::DruckerPragerGradyKipp) return bp::object(std::make_shared<DpGkMat>(e.dpgk));
		return bp::object(std::make_shared<ElasticMat>(e.elastic));
	}
	static ElasticMat elasticParameters(S& s, bp::object i) { return s.materialSet()[materialIndex(s, i, "elasticParameters: material")].elastic; }
	static DpGkMat    dpgkParameters(S& s, bp::object i)
	{
		const auto& e = s.materialSet()[materialIndex(s, i, "dpgkParameters: material")];
		if (e.kind != MaterialKind::DruckerPragerGradyKipp) throw InputError(who("dpgkParameters") + ": material is not a DpGkMat (use material(index))");
		return e.dpgk;
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

	// NumPy view on one particle array. The owner reference keeps the solver alive.
	static np::ndarray view(bp::object self, bp::object nameO)
	{
		const std::string name = argStr(nameO, who("view: name"));
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
		if (name == "material") { // read-only: setParticleMaterial changes it with the damage threshold ε_D⁰
			np::ndarray m = np::from_data(P.mat.data(), np::dtype::get_builtin<uint8_t>(), bp::make_tuple(P.n), bp::make_tuple(sizeof(uint8_t)), viewOwner(self));
			m.attr("setflags")(false);
			return m;
		}
		if (name == "nFlaw") f = &P.nFlaw;
		if (name == "id")
			return np::from_data(P.id.data(), np::dtype::get_builtin<int64_t>(), bp::make_tuple(P.n), bp::make_tuple(sizeof(int64_t)), viewOwner(self));
		if (!f) throw InputError("unknown particle field '" + name + "'");
		if (f->size() != P.n) throw InputError("particle field '" + name + "' is not allocated in this scene");
		return np::from_data(f->data(), np::dtype::get_builtin<double>(), bp::make_tuple(P.n), bp::make_tuple(sizeof(double)), viewOwner(self));
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
		auto       x = toVec<D>(point, who("shapeFunctions: point"));
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
		d["contact"] = s.phase.contact;
		d["g2p"]    = s.phase.g2p;
		d["stress"] = s.phase.stress;
		return d;
	}
	static void resetPhaseTimes(S& s) { s.phase = PhaseTimes {}; }
	static void run(S& s, bp::object steps)
	{
		const long long n = argInt(steps, who("run: steps"), 0, 9.2e18);
		for (long long k = 0; k < n; ++k) s.step();
	}
	// Settings (SolverSettings.hpp) as a dict, and written back all or nothing.
	static bp::dict settings(const S& s)
	{
		bp::dict d, all = ParamBinding<S>::toDict(s);
		for (const char* n : settingNames()) d[n] = all[n];
		return d;
	}
	static void setSettings(S& s, bp::dict d)
	{
		const bp::dict old = settings(s);
		bp::list       keys = d.keys();
		for (long i = 0; i < bp::len(keys); ++i) {
			std::string k = bp::extract<std::string>(bp::str(keys[i]));
			bool        known = false;
			for (const char* n : settingNames()) known = known || k == n;
			if (!known) throw InputError(who("setSettings") + ": unknown setting '" + k + "'; known: " + bp::extract<std::string>(bp::str(", ").join(old.keys()))());
		}
		try {
			for (long i = 0; i < bp::len(keys); ++i) ParamBinding<S>::set(s, bp::extract<std::string>(keys[i]), d[keys[i]]);
		} catch (...) {
			bp::list ok = old.keys();
			for (long i = 0; i < bp::len(ok); ++i) ParamBinding<S>::set(s, bp::extract<std::string>(ok[i]), old[ok[i]]);
			throw;
		}
	}
	static const std::vector<const char*>& settingNames()
	{
#define MPM_NAME_(T, name, ...) #name,
		static const std::vector<const char*> n { MPM_SOLVER_SETTINGS(MPM_NAME_) };
#undef MPM_NAME_
		return n;
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
	static void setNodeExcluded(S& s, bp::object i, bp::object ex)
	{
		s.grid.setExcluded(size_t(argInt(i, who("setNodeExcluded: node"), 0, double(s.grid.size() - 1))), argBool(ex, who("setNodeExcluded: excluded")));
	}
	// ---- rigid bodies for PTS contact (Sec. 2.3); the YADE adapter is py/yade_mpm/bodies.py
	using MatD = typename Dim<D>::Mat;
	using Spin = SpinOf<D>;
	static MatD toMat(const bp::object& o, const char* name)
	{
		np::ndarray a = asDoubleArray(o, name, D, D);
		MatD        m;
		auto*       p = reinterpret_cast<double*>(a.get_data());
		for (int i = 0; i < D; ++i)
			for (int j = 0; j < D; ++j) m(i, j) = p[i * D + j];
		return m;
	}
	static Spin toSpin(const bp::object& o, const char* name)
	{
		Spin w;
		if constexpr (D == 2) {
			w[0] = argReal(o, who(name) + " (ω_z)", "rad/s");
		} else {
			auto v = argReals(o, who(name), 3, "rad/s");
			for (int a = 0; a < 3; ++a) w[a] = v[a];
		}
		return w;
	}
	static bp::object fromSpin(const Spin& w)
	{
		if constexpr (D == 2) return bp::object(w[0]);
		else return bp::make_tuple(w[0], w[1], w[2]);
	}
	static int addRigidPart(S& s) { return s.contact.addPart(); }
	static int addContactGroup(S& s, bp::object parts, bp::object mu, bp::object cohesion, bp::object chi, bp::object d0)
	{
		std::vector<int> ps;
		for (long k = 0; k < bp::len(parts); ++k) ps.push_back(int(argInt(parts[k], who("addContactGroup: parts"), 0, 2147483647.0)));
		ContactParams prm; // ranges checked by ContactParams::validate (one declaration)
		prm.mu       = argReal(mu, who("addContactGroup: mu"), "-");
		prm.cohesion = argReal(cohesion, who("addContactGroup: cohesion"), "Pa");
		prm.chi      = argReal(chi, who("addContactGroup: chi"), "-");
		bp::extract<std::string> word(d0);
		if (word.check()) {
			if (word() != "initial")
				throw InputError(who("addContactGroup: d0") + " = '" + word() + "' must be a number >= 0 [m], None (half the particle edge) or 'initial'");
			prm.initialD0 = true; // first layer: d0_p = initial distance (captureContactD0); the rest: half the particle edge
		}
		prm.autoD0 = d0.is_none() || prm.initialD0;
		if (!prm.autoD0) prm.d0 = argReal(d0, who("addContactGroup: d0"), "m");
		return s.contact.addGroup(prm, ps);
	}
	// d0 = 'initial': capture d0_p = d_p(0) of the first particle layer at the group's current pose (registration).
	static void captureContactD0(S& s, int g) { s.contact.captureInitialD0(g, s.P); }
	static void removeLastContactGroup(S& s) { s.contact.removeLastGroup(); }
	// Captured d0 [m] per stable particle id (NaN: the default half edge); empty unless d0 = 'initial'.
	static np::ndarray contactInitialD0(S& s, int g)
	{
		const auto& v   = s.contact.group(g).d0Initial;
		np::ndarray out = np::empty(bp::make_tuple(v.size()), np::dtype::get_builtin<double>());
		std::copy(v.begin(), v.end(), reinterpret_cast<double*>(out.get_data()));
		return out;
	}
	static void addContactBox(S& s, int g, int part, bp::object centre, bp::object rot, bp::object half)
	{
		s.contact.addBox(g, part, toVec<D>(centre, "box centre"), toMat(rot, "box rotation"), toVec<D>(half, "box half extents"));
	}
	static void addContactPlane(S& s, int g, int part, bp::object point, bp::object normal, bool twoSided)
	{
		s.contact.addPlane(g, part, toVec<D>(point, "plane point"), toVec<D>(normal, "plane normal"), twoSided);
	}
	static void addContactElement(S& s, int g, int part, bp::object verts)
	{
		np::ndarray a = asDoubleArray(verts, "element vertices", D, D);
		auto*       p = reinterpret_cast<double*>(a.get_data());
		typename Dim<D>::Vec v[D];
		for (int k = 0; k < D; ++k)
			for (int j = 0; j < D; ++j) v[k][j] = p[k * D + j];
		s.contact.addElement(g, part, v);
	}
	static void setRigidPartState(S& s, int part, bp::object pos, bp::object rot, bp::object vel, bp::object angVel)
	{
		s.contact.part(part).setState(toVec<D>(pos, "rigid body position"), toMat(rot, "rigid body orientation"), toVec<D>(vel, "rigid body velocity"),
		                              toSpin(angVel, "rigid body angular velocity"));
	}
	// Mass [kg] / a moment of inertia [kg m²] of a rigid part (2D: per metre), in (0, inf]; inf = immovable along it.
	static Real massArg(const bp::object& o, const std::string& name, const char* unit)
	{
		bp::extract<double> x(o);
		if (!PyBool_Check(o.ptr()) && x.check() && std::isinf(x()) && x() > 0) return INFINITY;
		return argReal(o, name + " (or inf: immovable)", unit, 0, INFINITY, OO);
	}
	static Spin inertiaArg(const bp::object& o, const std::string& name)
	{
		const char* unit = D == 2 ? "kg m^2/m" : "kg m^2";
		Spin        I;
		if constexpr (D == 2) I[0] = massArg(o, name + " (I_z)", unit);
		else {
			PyObject* q = o.ptr();
			if (!(PySequence_Check(q) && !PyUnicode_Check(q) && PySequence_Size(q) == 3)) {
				PyErr_Clear();
				throw InputError(name + " must be a sequence of 3 principal moments [kg m^2] (got " + pyTypeName(q) + " " + pyRepr(o) + ")");
			}
			for (int a = 0; a < 3; ++a) I[a] = massArg(o[a], name + "[" + std::to_string(a) + "]", unit);
		}
		return I;
	}
	// Mass and principal moments of inertia (axes of the part's rotation) for the stick step's body share.
	static void setRigidPartMass(S& s, int part, bp::object mass, bp::object inertia)
	{
		auto& q = s.contact.part(part);
		q.setMass(massArg(mass, who("setRigidPartMass: mass"), D == 2 ? "kg/m" : "kg"), inertiaArg(inertia, who("setRigidPartMass: inertia")));
	}
	static bp::tuple rigidPartMass(S& s, int part)
	{
		const auto& q = s.contact.part(part);
		return bp::make_tuple(q.mass, fromSpin(q.inertia));
	}
	static void addContactSphere(S& s, int g, int part, bp::object centre, double radius)
	{
		s.contact.addSphere(g, part, toVec<D>(centre, "sphere centre"), radius);
	}
	// ---- many DEM spheres at once (py/yade_mpm/spheres.py): one call per step, not one per body
	static std::vector<int> intList(const bp::object& o, const char* name)
	{
		np::ndarray a = np::from_object(o, np::dtype::get_builtin<int64_t>(), np::ndarray::C_CONTIGUOUS);
		if (a.get_nd() != 1) throw InputError(std::string(name) + " must be a 1-D integer array");
		auto* p = reinterpret_cast<int64_t*>(a.get_data());
		return std::vector<int>(p, p + a.shape(0));
	}
	static void setContactGroupsEnabled(S& s, bp::object groups, bool on)
	{
		for (int g : intList(groups, "groups")) s.contact.setEnabled(g, on);
	}
	// Position, velocity and angular velocity of parts (orientation kept): pos, vel (n, D); angVel (n, 1) in 2D, (n, 3) in 3D.
	static void setRigidPartMotions(S& s, bp::object parts, bp::object pos, bp::object vel, bp::object angVel)
	{
		const auto  ps = intList(parts, "parts");
		const size_t n = ps.size();
		constexpr int NS = D == 2 ? 1 : 3;
		np::ndarray x = asDoubleArray(pos, "positions", D, n), v = asDoubleArray(vel, "velocities", D, n),
		            w = asDoubleArray(angVel, "angular velocities", NS, n);
		auto *xp = reinterpret_cast<double*>(x.get_data()), *vp = reinterpret_cast<double*>(v.get_data()), *wp = reinterpret_cast<double*>(w.get_data());
		for (size_t k = 0; k < n; ++k) {
			auto& q = s.contact.part(ps[k]);
			typename Dim<D>::Vec c, u;
			Spin om;
			for (int a = 0; a < D; ++a) c[a] = xp[k * D + a], u[a] = vp[k * D + a];
			for (int a = 0; a < NS; ++a) om[a] = wp[k * NS + a];
			q.setState(c, q.R, u, om);
		}
	}
	// Masses (n,) and principal moments of inertia (n, 1 | 3) of parts, each in (0, inf] (inf: immovable along it).
	static void setRigidPartMasses(S& s, bp::object parts, bp::object mass, bp::object inertia)
	{
		const auto  ps = intList(parts, "parts");
		const size_t n = ps.size();
		constexpr int NS = D == 2 ? 1 : 3;
		np::ndarray m = asDoubleArray(mass, "masses", 0, n), I = asDoubleArray(inertia, "moments of inertia", NS, n);
		auto *mp = reinterpret_cast<double*>(m.get_data()), *ip = reinterpret_cast<double*>(I.get_data());
		for (int pass = 0; pass < 2; ++pass) // every entry checked before any is changed
			for (size_t k = 0; k < n; ++k) {
				Spin J;
				for (int a = 0; a < NS; ++a) J[a] = ip[k * NS + a];
				RigidPart<D> probe;                         // pass 0: validate on a copy
				auto&        q = s.contact.part(ps[k]);     // checks the index
				(pass ? q : probe).setMass(mp[k], J);
			}
	}
	// Reaction forces (n, D) and torques (n, 1 | 3) of parts from the last step.
	static bp::tuple rigidPartReactions(S& s, bp::object parts)
	{
		const auto  ps = intList(parts, "parts");
		const size_t n = ps.size();
		constexpr int NS = D == 2 ? 1 : 3;
		np::ndarray f = np::zeros(bp::make_tuple(n, D), np::dtype::get_builtin<double>());
		np::ndarray m = np::zeros(bp::make_tuple(n, NS), np::dtype::get_builtin<double>());
		auto *fp = reinterpret_cast<double*>(f.get_data()), *mp = reinterpret_cast<double*>(m.get_data());
		for (size_t k = 0; k < n; ++k) {
			const auto& q = s.contact.part(ps[k]);
			for (int a = 0; a < D; ++a) fp[k * D + a] = q.force[a];
			for (int a = 0; a < NS; ++a) mp[k * NS + a] = q.torque[a];
		}
		return bp::make_tuple(f, m);
	}
	static bp::tuple rigidPartForce(S& s, int part) { return fromVec<D>(s.contact.part(part).force); }
	static bp::object rigidPartTorque(S& s, int part) { return fromSpin(s.contact.part(part).torque); }
	// Signed distance, outward normal and owning part of a contact group at a point (for tests and inspection).
	static bp::tuple contactQuery(S& s, int g, bp::object point)
	{
		auto& grp = s.contact.group(g);
		grp.update(s.contact.parts);
		auto h = grp.query(toVec<D>(point, "point"));
		return bp::make_tuple(h.d, fromVec<D>(h.n), h.part);
	}
	static bool contactGroupClosed(S& s, int g)
	{
		auto& grp = s.contact.group(g);
		grp.update(s.contact.parts);
		return grp.closed;
	}
	// Contact force each node received from the last group processed in the last step, (nodes, D) [N].
	static np::ndarray contactNodeForces(S& s)
	{
		size_t      n   = s.grid.size();
		np::ndarray out = np::zeros(bp::make_tuple(n, D), np::dtype::get_builtin<double>());
		auto*       o   = reinterpret_cast<double*>(out.get_data());
		if (s.contact.nodeArr.size() == n)
			for (size_t i = 0; i < n; ++i)
				for (int a = 0; a < D; ++a) o[i * D + a] = s.contact.nodeArr.force[a][i];
		return out;
	}
	static np::ndarray excludedNodes(S& s)
	{
		size_t      n   = s.grid.size();
		np::ndarray out = np::empty(bp::make_tuple(n), np::dtype::get_builtin<uint8_t>());
		std::copy(s.grid.excluded.begin(), s.grid.excluded.end(), reinterpret_cast<uint8_t*>(out.get_data()));
		return out;
	}
	static bool contactActive(S& s) { return s.contact.active(); }

	static int materialKind(S& s) { return int(s.materialKind()); }

	static void reserve(S& s, bp::object n) { s.reserve(size_t(argInt(n, who("reserve: particles"), 0, 4e9))); }

	// Owner of NumPy views: counts the live views of a solver so that addParticles can refuse to move
	// arrays under them (Solver::liveViews).
	struct ViewOwner {
		std::shared_ptr<S> s;
		explicit ViewOwner(std::shared_ptr<S> solver) : s(std::move(solver)) { s->viewOpened(); }
		~ViewOwner() { s->viewClosed(); }
	};
	static bp::object viewOwner(bp::object self) { return bp::object(std::make_shared<ViewOwner>(bp::extract<std::shared_ptr<S>>(self)())); }

	static void expose(const char* name)
	{
		ParamBinding<S>::declare(name);
		bp::class_<ViewOwner, std::shared_ptr<ViewOwner>, boost::noncopyable>((std::string("_ViewOwner") + name).c_str(), bp::no_init);
		bp::class_<S, std::shared_ptr<S>, boost::noncopyable> cls(name, "Explicit WLS-MPM solver (MUSL) on a fixed regular grid.", bp::no_init);
		ParamBinding<S>::exposeProperties(cls); // settings and writable state, checked (SolverSettings.hpp)
		cls.def("settings", &settings, "The settings (SolverSettings.hpp) as a dict {name: value}.")
		        .def("setSettings", &setSettings, bp::arg("settings"), "Write settings from a dict (all or nothing; unknown names refused).")
		        .def("__init__", bp::make_constructor(&make, bp::default_call_policies(), (bp::arg("origin"), bp::arg("spacing"), bp::arg("cells"))))
		        .def("addParticles", &addParticles, (bp::arg("positions"), bp::arg("volumes"), bp::arg("masses"), bp::arg("material") = 0),
		             "Adds particles (positions (N, D) [m], volumes [m³], masses [kg]) of material index `material` (addMaterial's return value).")
		        .def("addMaterial", &addMaterial, bp::arg("material"), "Adds an ElasticMat or DpGkMat to the scene; returns its index for addParticles.")
		        .def("material", &material, bp::arg("index"), "Copy of material `index` (ElasticMat or DpGkMat).")
		        .def("cohesion", &cohesion, "Current cohesion per particle (Eq. 34) [Pa], storage order; NaN for non-DP–GK particles.")
		        .def("setMaterial", &setMaterial, bp::arg("material"))
		        .def("addBoundaryPlane", &addPlane, (bp::arg("axis"), bp::arg("side"), bp::arg("position"), bp::arg("kind")))
		        .def("setParticleForces", &setForces, (bp::arg("indices"), bp::arg("forces")))
		        .def("setParticleMaterial", &setParticleMaterial, (bp::arg("indices"), bp::arg("material")),
		             "Particle slots `indices` (storage order, as the views) take material index `material` (addMaterial's return value, "
		             "range [0, numMaterials - 1]) and that material's damage threshold eps0 (Eq. 37; 0 without damage), with no activated "
		             "flaws; damage and plastic strain stay. The view 'material' is read-only: use this.")
		        .def("step", static_cast<void (S::*)()>(&S::step))
		        .def("advance", &advance, bp::arg("dt"))
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
		        .def("addRigidPart", &addRigidPart, "new rigid part (one YADE body or clump); returns its index")
		        .def("addContactGroup", &addContactGroup, (bp::arg("parts"), bp::arg("mu"), bp::arg("cohesion"), bp::arg("chi"), bp::arg("d0")),
		             "contact group over rigid parts with μ [-], c [Pa], χ [-], d0 [m] (None = ½ particle edge; 'initial' = the first "
		             "particle layer's initial distance, see captureContactD0); returns its index")
		        .def("captureContactD0", &captureContactD0, (bp::arg("group")),
		             "d0 = 'initial': d0_p := initial distance of the first particle layer next to the group at its current pose")
		        .def("removeLastContactGroup", &removeLastContactGroup,
		             "undo the last addContactGroup and its rigid parts (a registration refused half-way)")
		        .def("contactInitialD0", &contactInitialD0, (bp::arg("group")),
		             "captured d0 [m] per particle id (NaN = default half edge); empty unless d0 = 'initial'")
		        .def("addContactBox", &addContactBox, (bp::arg("group"), bp::arg("part"), bp::arg("centre"), bp::arg("rotation"), bp::arg("half")))
		        .def("addContactPlane", &addContactPlane, (bp::arg("group"), bp::arg("part"), bp::arg("point"), bp::arg("normal"), bp::arg("twoSided")))
		        .def("addContactElement", &addContactElement, (bp::arg("group"), bp::arg("part"), bp::arg("vertices")))
		        .def("setRigidPartState", &setRigidPartState, (bp::arg("part"), bp::arg("pos"), bp::arg("rot"), bp::arg("vel"), bp::arg("angVel")))
		        .def("addContactSphere", &addContactSphere, (bp::arg("group"), bp::arg("part"), bp::arg("centre"), bp::arg("radius")),
		             "sphere (3D) / circle (2D) of radius [m] at centre (part frame) in a contact group")
		        .def("setContactGroupsEnabled", &setContactGroupsEnabled, (bp::arg("groups"), bp::arg("enabled")),
		             "switch contact groups on/off (off: skipped entirely)")
		        .def("setRigidPartMotions", &setRigidPartMotions, (bp::arg("parts"), bp::arg("pos"), bp::arg("vel"), bp::arg("angVel")),
		             "positions, velocities, angular velocities of many parts (orientation unchanged)")
		        .def("setRigidPartMass", &setRigidPartMass, (bp::arg("part"), bp::arg("mass"), bp::arg("inertia")),
		             "mass [kg] (2D: kg/m) and principal moments of inertia about the centre along the part's axes [kg m^2] (2D: I_z, "
		             "kg m^2/m) of a part, each in (0, inf]; inf (the default) = immovable along it (the paper's stick step). For a free "
		             "part every contact node sticks to the part's motion after the step, from its momentum balance (doc/contact.md)")
		        .def("rigidPartMass", &rigidPartMass, bp::arg("part"), "(mass, inertia) of a part as set by setRigidPartMass")
		        .def("setRigidPartMasses", &setRigidPartMasses, (bp::arg("parts"), bp::arg("mass"), bp::arg("inertia")),
		             "masses (n,) and principal moments of inertia (n, 1|3) of many parts, as setRigidPartMass")
		        .def("rigidPartReactions", &rigidPartReactions, bp::arg("parts"), "(forces (n, D), torques (n, 1|3)) of parts")
		        .def("rigidPartForce", &rigidPartForce, bp::arg("part"))
		        .def("rigidPartTorque", &rigidPartTorque, bp::arg("part"))
		        .def("contactQuery", &contactQuery, (bp::arg("group"), bp::arg("point")))
		        .def("contactGroupClosed", &contactGroupClosed, bp::arg("group"))
		        .def("contactNodeForces", &contactNodeForces)
		        .def("excludedNodes", &excludedNodes)
		        .add_property("contactActive", &contactActive)
		        .def("phaseTimes", &phaseTimes)
		        .def("resetPhaseTimes", &resetPhaseTimes)
		        .def("requestSort", &S::requestSort)
		        .def("getResumeState", &getResumeState)
		        .def("setResumeState", &setResumeState, bp::arg("state"))
		        .def("elasticParameters", &elasticParameters, bp::arg("index") = 0)
		        .def("dpgkParameters", &dpgkParameters, bp::arg("index") = 0)
		        .def("loadScale", &loadScale, bp::arg("t"))
		        .add_property("numParticles", &numParticles)
		        .add_property("bytesPerParticle", &bytesPerParticle)
		        .add_property("materialKind", &materialKind, "kind of material 0: 0 elastic, 1 DP–GK, -1 none (see materialKinds)")
		        .add_property("materialKinds", &materialKinds, "kind of every material, by index: 0 elastic, 1 DP–GK")
		        .add_property("numMaterials", &numMaterials)
		        .add_property("spacing", &getSpacing)
		        .add_property("origin", &getOrigin)
		        .add_property("cells", &getCells)
		        .add_property("storedNodes", &getStored)
		        .def("reserve", &reserve, bp::arg("particles"),
		             "Room for this many particles: later addParticles up to that count keep the arrays (and live views) in place.")
		        .def_readonly("lastDt", &S::lastDt)
		        .add_property("maxSpeed", &S::maxSpeed);
	}
};

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

// More threads than 4 per processor only add barrier overhead; far more crashed the process
// (100000: a step segfaulted; 1000: libgomp aborted).
int maxThreads() { return std::max(16, 4 * omp_get_num_procs()); }
void setThreads(bp::object n) { omp_set_num_threads(int(argInt(n, "setThreads: threads", 1, maxThreads()))); }
// Defaults of the contact parameters (one declaration: ContactParams in RigidSurface.hpp); d0 None = ½ particle edge.
bp::dict contactDefaults()
{
	ContactParams p;
	bp::dict      d;
	d["mu"]       = p.mu;
	d["cohesion"] = p.cohesion;
	d["chi"]      = p.chi;
	d["d0"]       = p.autoD0 ? bp::object() : bp::object(p.d0);
	return d;
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
	// Node exclusion bits (Grid.hpp; Solver.excludedNodes() returns them per stored node)
	bp::dict bits;
	bits["ghost"] = int(ExGhost), bits["beyond"] = int(ExBeyond), bits["gap"] = int(ExGap), bits["contact"] = int(ExContact);
	bp::scope().attr("exclusionBits") = bits;

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
	bp::def("setThreads", &setThreads, bp::arg("threads"), "Number of OpenMP threads, in [1, max(16, 4 × processors)].");
	bp::def("contactDefaults", &contactDefaults, "Defaults of the contact parameters mu [-], cohesion [Pa], chi [-], d0 [m] (None = half the particle edge).");
	bp::def("getThreads", &getThreads);
}
