// Shared by the binding files of the module yade_mpm._core (bindings.cpp and bind_*.cpp in pkg-mpm/python): the same
// Boost.Python layer YADE uses. Each file exposes one concern; the Solver2D/3D class is created in
// bind_solver.cpp and the others add their methods to it.
#pragma once
#include "../step/Solver.hpp"
#include "param_binding.hpp"
#include <boost/python.hpp>
#include <boost/python/numpy.hpp>

namespace mpm {
namespace bp = boost::python;
namespace np = boost::python::numpy;

template <int D>
using SolverClass = bp::class_<Solver<D>, std::shared_ptr<Solver<D>>, boost::noncopyable>;

inline std::string solverName(int D) { return D == 2 ? "Solver2D" : "Solver3D"; }

template <int D>
typename Dim<D>::Vec toVec(const bp::object& o, const std::string& name, const char* unit = "m")
{
	auto                 c = argReals(o, name, D, unit);
	typename Dim<D>::Vec v;
	for (int a = 0; a < D; ++a) v[a] = c[a];
	return v;
}
template <int D>
bp::tuple fromVec(const typename Dim<D>::Vec& v)
{
	if constexpr (D == 2) return bp::make_tuple(v[0], v[1]);
	else return bp::make_tuple(v[0], v[1], v[2]);
}

// A contiguous float64 array of the given shape, copied (asarray semantics), or an error naming `name`.
inline np::ndarray asDoubleArray(const bp::object& o, const char* name, int cols, size_t rows = size_t(-1))
{
	np::ndarray a = np::from_object(o, np::dtype::get_builtin<double>(), np::ndarray::C_CONTIGUOUS);
	const int   nd = a.get_nd();
	if ((cols == 0 && nd != 1) || (cols > 0 && (nd != 2 || a.shape(1) != cols)))
		throw InputError(std::string(name) + (cols == 0 ? " must be a 1-D array" : " must be an (N, " + std::to_string(cols) + ") array"));
	if (rows != size_t(-1) && size_t(a.shape(0)) != rows)
		throw InputError(std::string(name) + " has " + std::to_string(a.shape(0)) + " rows, expected " + std::to_string(rows));
	return a;
}

// bind_solver.cpp: the class Solver2D/3D (construction, materials, particles, stepping) and the calls below.
template <int D>
void exposeSolver(const char* name);
template <int D>
void exposeSolverCore(SolverClass<D>& cls, const char* name);
template <int D>
void exposeViews(SolverClass<D>& cls, const char* name);   // bind_views.cpp: particle views, fields, nodes
template <int D>
void exposeState(SolverClass<D>& cls, const char* name);   // bind_state.cpp: settings, resume state, phase times
template <int D>
void exposeContact(SolverClass<D>& cls, const char* name); // bind_contact.cpp: rigid parts and contact groups
void exposeMaterials();                                    // bind_materials.cpp: ElasticMat, DpGkMat, ContactParams
void exposePointUpdate();                                  // bind_point.cpp: single-point DP–GK update, thresholds
#ifdef MPM_MPI
template <int D>
void exposeMpi(SolverClass<D>& cls, const char* name); // bind_mpi.cpp (MPI build): decomposition info
void initMpi();                                        // bind_mpi.cpp: MPI_Init_thread, finalize at exit
#endif

// Defines one of the exposeX above in its file: exposeX<D>(cls, name) calls Wrap<D>::expose(cls, name),
// the file's struct of static methods, for D = 2 and 3.
#define MPM_EXPOSE_SOLVER_PART(exposeX, Wrap)                                                               \
	template <int D>                                                                                        \
	void exposeX(SolverClass<D>& cls, const char* name)                                                     \
	{                                                                                                       \
		Wrap<D>::expose(cls, name);                                                                         \
	}                                                                                                       \
	template void exposeX<2>(SolverClass<2>&, const char*);                                                 \
	template void exposeX<3>(SolverClass<3>&, const char*);

} // namespace mpm
