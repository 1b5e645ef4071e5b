// Solver2D/3D: settings and writable state from the one declaration (SolverSettings.hpp), the resume state
// of a checkpoint (py/yade_mpm/checkpoint.py) and the phase timers. Part of yade_mpm._core (bindings.cpp).
#include "binding_common.hpp"

namespace mpm {
namespace {

template <int D>
struct StateWrap {
	using S = Solver<D>;
	static std::string who(const char* what) { return solverName(D) + ": " + what; }

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
	// Checkpoint (py/yade_mpm/checkpoint.py): the solver state that is not in the particle views.
	static bp::dict getResumeState(S& s)
	{
		const auto r = s.resumeState();
		bp::dict   d;
		d["steps"] = r.steps, d["time"] = r.time, d["lastDt"] = r.lastDt, d["externalWork"] = r.externalWork;
		d["vmax"] = r.vmax, d["rhoMin"] = r.dtDensityMin, d["massFloor"] = r.massFloor;
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
		r.dtDensityMin = bp::extract<double>(d["rhoMin"]); // the checkpoint key keeps its name
		r.massFloor    = bp::extract<double>(d["massFloor"]);
		r.needSort     = bp::extract<bool>(d["needSort"]);
		r.needCheck    = bp::extract<bool>(d["needCheck"]);
		np::ndarray a  = np::from_object(d["blockStart"], np::dtype::get_builtin<uint32_t>(), np::ndarray::C_CONTIGUOUS);
		if (a.get_nd() != 1) throw InputError("checkpoint: blockStart must be a 1-D array");
		auto* p = reinterpret_cast<uint32_t*>(a.get_data());
		s.setResumeState(r, std::vector<uint32_t>(p, p + a.shape(0)));
	}

	// ---- material that left the grid (Solver.outside; pkg-mpm/step/Removal.hpp) ----
	template <class T>
	static np::ndarray column(const std::vector<RemovedParticle<D>>& rs, T (*get)(const RemovedParticle<D>&))
	{
		np::ndarray a = np::empty(bp::make_tuple(rs.size()), np::dtype::get_builtin<T>());
		T*          d = reinterpret_cast<T*>(a.get_data());
		for (size_t k = 0; k < rs.size(); ++k) d[k] = get(rs[k]);
		return a;
	}
	static np::ndarray vectors(const std::vector<RemovedParticle<D>>& rs, bool vel)
	{
		np::ndarray a = np::empty(bp::make_tuple(rs.size(), D), np::dtype::get_builtin<double>());
		double*     d = reinterpret_cast<double*>(a.get_data());
		for (size_t k = 0; k < rs.size(); ++k)
			for (int c = 0; c < D; ++c) d[k * D + c] = vel ? rs[k].v[c] : rs[k].x[c];
		return a;
	}
	// The removed particles of this solver (MPI: of this rank), in removal order, as arrays.
	static bp::dict removedParticles(const S& s)
	{
		const auto& rs = s.removedParticles();
		bp::dict    d;
		d["id"]       = column<int64_t>(rs, [](const RemovedParticle<D>& r) { return r.id; });
		d["step"]     = column<int64_t>(rs, [](const RemovedParticle<D>& r) { return int64_t(r.step); });
		d["time"]     = column<double>(rs, [](const RemovedParticle<D>& r) { return r.time; });
		d["pos"]      = vectors(rs, false);
		d["vel"]      = vectors(rs, true);
		d["mass"]     = column<double>(rs, [](const RemovedParticle<D>& r) { return r.mass; });
		d["damage"]   = column<double>(rs, [](const RemovedParticle<D>& r) { return r.damage; });
		d["face"]     = column<int32_t>(rs, [](const RemovedParticle<D>& r) { return int32_t(r.face); });
		d["material"] = column<uint8_t>(rs, [](const RemovedParticle<D>& r) { return r.material; });
		d["reason"]   = column<int32_t>(rs, [](const RemovedParticle<D>& r) { return int32_t(r.reason); });
		return d;
	}
	static void restoreRemoved(S& s, bp::dict d, long n)
	{
		if (n < 0) throw InputError("checkpoint: particles = " + std::to_string(n) + " must be ≥ 0");
		const long k = long(bp::len(d["id"]));
		auto col = [&](const char* name, int cols) { return asDoubleArray(d[name], name, cols, size_t(k)); };
		np::ndarray id = np::from_object(d["id"], np::dtype::get_builtin<int64_t>(), np::ndarray::C_CONTIGUOUS);
		np::ndarray x = col("pos", D), v = col("vel", D), t = col("time", 0), m = col("mass", 0), dmg = col("damage", 0);
		np::ndarray st = col("step", 0), f = col("face", 0), mt = col("material", 0), rs = col("reason", 0);
		std::vector<RemovedParticle<D>> recs; recs.resize(size_t(k));
		auto at = [](const np::ndarray& a, long i) { return reinterpret_cast<const double*>(a.get_data())[i]; };
		for (long i = 0; i < k; ++i) {
			auto& r = recs[size_t(i)];
			r.id = reinterpret_cast<const int64_t*>(id.get_data())[i];
			r.step = long(at(st, i)), r.time = at(t, i), r.mass = at(m, i), r.damage = at(dmg, i);
			r.face = int(at(f, i)), r.material = uint8_t(at(mt, i)), r.reason = int(at(rs, i));
			for (int c = 0; c < D; ++c) r.x[c] = at(x, i * D + c), r.v[c] = at(v, i * D + c);
		}
		s.restoreRemoved(recs, size_t(n));
	}
	// The running account of the removed particles (MPI: over every rank, a collective).
	static bp::dict removedAccount(const S& s, bool allRanks)
	{
		(void)allRanks;
		const auto& a = s.removedAccount();
		constexpr int nv = 3 + D + 2 * D;
		double v[nv], last[2] = { a.lastTime, double(a.lastStep) };
		v[0] = double(a.count), v[1] = a.mass, v[2] = a.kinetic;
		for (int c = 0; c < D; ++c) v[3 + c] = a.momentum[c];
		for (int f = 0; f < 2 * D; ++f) v[3 + D + f] = double(a.faces[f]);
#ifdef MPM_MPI
		std::vector<double> scratch;
		if (allRanks) Comm::sumInRankOrder(v, nv, scratch), Comm::max(last, 2);
#endif
		bp::dict d, faces;
		d["count"] = long(v[0]), d["mass"] = v[1], d["kinetic_energy"] = v[2];
		bp::list mom;
		for (int c = 0; c < D; ++c) mom.append(v[3 + c]);
		d["momentum"] = bp::tuple(mom);
		for (int f = 0; f < 2 * D; ++f) faces[faceName(f)] = long(v[3 + D + f]);
		d["faces"] = faces;
		d["last_time"] = long(v[0]) ? bp::object(last[0]) : bp::object();
		d["last_step"] = long(v[0]) ? bp::object(long(last[1])) : bp::object();
		return d;
	}

	// The settings' declarations (name, unit, range or choices, default, doc), as the materials' paramTable().
	static bp::list settingsTable(const S&) { return ParamBinding<S>::table(); }

	static void expose(SolverClass<D>& cls, const char* name)
	{
		ParamBinding<S>::exposeProperties(cls); // settings and writable state, checked (SolverSettings.hpp)
		cls.def("settings", &settings, "The settings (SolverSettings.hpp) as a dict {name: value}.")
		        .def("setSettings", &setSettings, bp::arg("settings"), "Write settings from a dict (all or nothing; unknown names refused).")
		        .def("settingsTable", &settingsTable, "The settings' declarations (SolverSettings.hpp): a list of dicts with name, unit, "
		                                              "range (lo, hi) or choices, default, doc and equation.")
		        .def("_phaseTimes", &phaseTimes)
		        .def("_resetPhaseTimes", &resetPhaseTimes)
		        .def("_getResumeState", &getResumeState)
		        .def("_setResumeState", &setResumeState, bp::arg("state"))
		        .def("_removedAccount", &removedAccount, (bp::arg("allRanks") = true),
		             "What left the grid and was removed (Solver.outside): {count, mass [kg], momentum (Σ m v) [kg·m/s], kinetic_energy [J], "
		             "last_time [s], last_step, faces: {'x-': n, 'x+': n, …}}; MPI: over every rank (a collective), or this rank's with allRanks=False.")
		        .def("_removedParticles", &removedParticles,
		             "The removed particles in removal order as arrays: id, step, time [s], pos [m], vel [m/s] (at removal), mass [kg], damage, "
		             "face (2·axis + 1 for the upper end), material, reason (0 outside = 'remove', 1 fully damaged, 2 detached); MPI: this rank's.")
		        .def("_restoreRemoved", &restoreRemoved, (bp::arg("removed"), bp::arg("particles")),
		             "Checkpoint resume: the removed particles, and the particle arrays cut to the saved count (yade_mpm.checkpoint).");
	}
};
} // namespace

MPM_EXPOSE_SOLVER_PART(exposeState, StateWrap)
} // namespace mpm
