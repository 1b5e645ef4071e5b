// Boost.Python binding of the MPM core (module yade_mpm._core): the same binding layer YADE uses.
// Particle fields are exposed as NumPy views on the solver's own arrays (no copy); the views keep
// the solver alive and stay valid while stepping (arrays are never reallocated during a step).
// One file per concern: bind_materials.cpp (parameter classes), bind_solver.cpp (the solver class:
// construction, materials, particles, stepping), bind_views.cpp (views, fields, nodes), bind_state.cpp
// (settings, resume state, phase times), bind_contact.cpp (rigid bodies and contact groups),
// bind_point.cpp (single-point DP–GK update); shared helpers in binding_common.hpp.
#include "binding_common.hpp"

using namespace mpm;

namespace {

PyObject* simulationErrorType = nullptr;

void translateInput(const InputError& e) { PyErr_SetString(PyExc_ValueError, e.what()); }
void translateSimulation(const SimulationError& e) { PyErr_SetString(simulationErrorType, e.what()); }

// At most max(16, 4 × processors) threads (more only add barrier overhead; doc/developer/core_notes.md).
int maxThreads() { return std::max(16, 4 * omp_get_num_procs()); }
void setThreads(bp::object n) { omp_set_num_threads(int(argInt(n, "setThreads: threads", 1, maxThreads()))); }

int getThreads() { return omp_get_max_threads(); }

} // namespace

#ifdef MPM_MPI
#define MPM_MODULE _core_mpi // the MPI build of the same sources (doc/developer/scaling.md)
#else
#define MPM_MODULE _core
#endif
BOOST_PYTHON_MODULE(MPM_MODULE)
{
	Py_Initialize();
	np::initialize();
	MPM_IF_MPI(initMpi();)
	simulationErrorType = PyErr_NewException("yade_mpm._core.MpmSimulationError", PyExc_RuntimeError, nullptr);
	bp::scope().attr("MpmSimulationError") = bp::handle<>(bp::borrowed(simulationErrorType));
	bp::register_exception_translator<InputError>(&translateInput);
	bp::register_exception_translator<SimulationError>(&translateSimulation);
	// Node exclusion bits (Grid.hpp; Solver.excludedNodes() returns them per stored node)
	bp::dict bits;
	bits["ghost"] = int(ExGhost), bits["beyond"] = int(ExBeyond), bits["gap"] = int(ExGap), bits["contact"] = int(ExContact);
	bp::scope().attr("exclusionBits") = bits;

	exposeMaterials();
	exposeSolver<2>("Solver2D");
	exposeSolver<3>("Solver3D");
	exposePointUpdate();
	bp::def("setThreads", &setThreads, bp::arg("threads"), "Number of OpenMP threads, in [1, max(16, 4 × processors)].");
	bp::def("getThreads", &getThreads);
}
