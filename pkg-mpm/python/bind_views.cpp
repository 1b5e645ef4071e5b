// Solver2D/3D: NumPy views on the particle arrays (storage order, no copy), derived per-particle fields, grid
// nodes and shape functions (for inspection and tests). Part of the module yade_mpm._core (bindings.cpp).
#include "binding_common.hpp"

namespace mpm {
namespace {

template <int D>
struct ViewsWrap {
	using S = Solver<D>;
	static std::string who(const char* what) { return solverName(D) + ": " + what; }

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
	// Velocity of each material point, v_p + C_p (x_p − x̄_p) (Transfer::materialVelocity), shape (N, D), copied.
	static np::ndarray materialVelocity(S& s)
	{
		np::ndarray out = np::empty(bp::make_tuple(s.P.n, D), np::dtype::get_builtin<double>());
		auto*       o   = reinterpret_cast<double*>(out.get_data());
		for (size_t p = 0; p < s.P.n; ++p) {
			Real v[D];
			if (!s.materialVelocity(p, v)) throw SimulationError("materialVelocity: particle " + std::to_string(s.P.id[p]) + " " + noActiveNodeMessage);
			for (int a = 0; a < D; ++a) o[p * D + a] = v[a];
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
		if (!computeStencil(s.grid, so, xa, st)) throw SimulationError("no active grid node in the WLS stencil of this point (every node excluded)");
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
			for (int a = 0; a < D; ++a) reinterpret_cast<double*>(v.get_data())[i * D + a] = s.grid.vmusl[i].c[a];
		}
		return bp::make_tuple(m, mw, v);
	}
	static np::ndarray excludedNodes(S& s)
	{
		size_t      n   = s.grid.size();
		np::ndarray out = np::empty(bp::make_tuple(n), np::dtype::get_builtin<uint8_t>());
		std::copy(s.grid.excluded.begin(), s.grid.excluded.end(), reinterpret_cast<uint8_t*>(out.get_data()));
		return out;
	}

	// Owner of NumPy views: counts the live views of a solver so that addParticles can refuse to move
	// arrays under them (Solver::liveViews).
	struct ViewOwner {
		std::shared_ptr<S> s;
		explicit ViewOwner(std::shared_ptr<S> solver) : s(std::move(solver)) { s->viewOpened(); }
		~ViewOwner() { s->viewClosed(); }
	};
	static bp::object viewOwner(bp::object self) { return bp::object(std::make_shared<ViewOwner>(bp::extract<std::shared_ptr<S>>(self)())); }

	static void expose(SolverClass<D>& cls, const char* name)
	{
		bp::class_<ViewOwner, std::shared_ptr<ViewOwner>, boost::noncopyable>((std::string("_ViewOwner") + name).c_str(), bp::no_init);
		cls.def("view", &view, bp::arg("name"))
		        .def("_effectiveStress", &effectiveStress)
		        .def("_maxPrincipalStress", &maxPrincipalStress)
		        .def("_materialVelocity", &materialVelocity, "Velocity of each material point [m/s], (N, D), storage order: v + C (x − x̄), x̄ the centroid of a cut stencil's lumping weights.")
		        .def("_shapeFunctions", &shapeFunctions, bp::arg("point"))
		        .def("_nodePositions", &nodePositions)
		        .def("_nodeState", &nodeState)
		        .def("_excludedNodes", &excludedNodes);
	}
};
} // namespace

MPM_EXPOSE_SOLVER_PART(exposeViews, ViewsWrap)
} // namespace mpm
