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

	static void expose(SolverClass<D>& cls, const char* name)
	{
		ParamBinding<S>::exposeProperties(cls); // settings and writable state, checked (SolverSettings.hpp)
		cls.def("settings", &settings, "The settings (SolverSettings.hpp) as a dict {name: value}.")
		        .def("setSettings", &setSettings, bp::arg("settings"), "Write settings from a dict (all or nothing; unknown names refused).")
		        .def("phaseTimes", &phaseTimes)
		        .def("resetPhaseTimes", &resetPhaseTimes)
		        .def("getResumeState", &getResumeState)
		        .def("setResumeState", &setResumeState, bp::arg("state"));
	}
};
} // namespace

MPM_EXPOSE_SOLVER_PART(exposeState, StateWrap)
} // namespace mpm
