// MPI build only (module yade_mpm._core_mpi, -DMPM_MPI): start-up of MPI and what Python may ask about
// the decomposition (pkg-mpm/mpi/Decomposition.hpp, doc/developer/scaling.md).
#include "binding_common.hpp"
#include <cstdlib>
#include <fstream>

#ifdef MPM_MPI
namespace mpm {
namespace {

bool startedHere = false;
void finalize()
{
	int done = 0;
	MPI_Finalized(&done);
	if (startedHere && !done) MPI_Finalize();
}

// Peak resident set size of this process [B] (VmHWM of /proc/self/status; 0 where unavailable).
double peakRss()
{
	std::ifstream f("/proc/self/status");
	std::string   line;
	while (std::getline(f, line))
		if (line.rfind("VmHWM:", 0) == 0) return 1024.0 * std::atof(line.c_str() + 6);
	return 0;
}
template <int D>
double particleBytes(Particles<D>& P)
{
	double b = double(P.id.capacity() * sizeof(int64_t) + P.mat.capacity());
	P.forEachRealField([&](std::vector<Real>& f) { b += double(f.capacity() * sizeof(Real)); });
	return b;
}

template <int D>
bp::dict mpiInfo(Solver<D>& s)
{
	bp::dict d;
	d["rank"] = s.dd.rank, d["size"] = s.dd.R, d["decomposed"] = s.dd.decomposed;
	bp::list first;
	for (int f : s.dd.layout.first) first.append(f);
	d["firstLayers"]   = first; // block layers (8 cells) along the last axis owned by rank r: [first[r], first[r+1])
	d["particles"]     = s.P.n;  // on this rank
	d["migrated"]      = s.dd.migrated;
	d["rebalances"]    = s.dd.rebalances; // re-cuts of the slabs (Solver.mpiRebalance)
	d["imbalance"]     = s.dd.imbalance;  // max/mean of the per-rank particle counts at the last re-sort (after any re-cut)
	d["haloBytesSent"] = s.dd.halo.bytesLastStep; // per shared-node exchange (two per step)
	// memory of this rank (doc/developer/scaling.md): the node layers held along the last axis, the node and
	// particle arrays' bytes (capacity), and the process's peak resident set so far (VmHWM)
	bp::list held;
	held.append(s.grid.layer0), held.append(s.grid.layerEnd);
	d["heldLayers"]    = held;
	d["gridNodes"]     = s.grid.size();
	d["gridBytes"]     = s.grid.bytes();
	d["particleBytes"] = particleBytes(s.P);
	d["peakRSS"]       = peakRss();
	d["distributedBuild"] = s.dd.building; // mpiDistribute: each rank built only its slab's particles
	d["builtParticles"]   = s.dd.builtIds; // particles added over all ranks under distributed construction
	return d;
}

int rank() { return Comm::rank(); }
int size() { return Comm::size(); }
double sum(double v) // over the ranks (also a barrier): checkpoint agreement and counts
{
	Comm::sum(&v, 1);
	return v;
}
// Element-wise max of a list of floats over the ranks (every rank passes the same length): exact, the same
// bits on every rank. DemSpheres' broad phase takes the global particle box from it (min as max of −x).
bp::list maxList(bp::object values)
{
	std::vector<double> v(size_t(bp::len(values)));
	for (size_t k = 0; k < v.size(); ++k) v[k] = bp::extract<double>(values[k]);
	Comm::max(v.data(), int(v.size()));
	bp::list out;
	for (double x : v) out.append(x);
	return out;
}

// Checkpoint resume (py/yade_mpm/checkpoint.py): the saved slab layout and the rank's particle count; the
// particle arrays are sized to n (cut, or grown in a distributed build; no NumPy view may be alive) with the
// piece's optional fields, then Python writes the saved values into them.
template <int D>
void mpiRestoreSlab(Solver<D>& s, bp::object first, long n, bool traction, bool damageState, bool flaws)
{
	if (s.liveViews) throw InputError("MPI checkpoint resume: delete the NumPy views of the particle arrays first");
	if (n < 0) throw InputError("MPI checkpoint resume: particles = " + std::to_string(n) + " must be ≥ 0");
	std::vector<int> f;
	for (long k = 0; k < bp::len(first); ++k) f.push_back(bp::extract<int>(first[k]));
	const double opt[3] = { double(traction), double(damageState), double(flaws) };
	s.dd.restore(s.grid, s.P, f, size_t(n), opt);
	s.requestSort();
}

// Distributed construction (Decomposition::distribute), before any particle is added.
template <int D>
void mpiDistribute(Solver<D>& s)
{
	s.dd.distribute(s.grid, s.P.n);
}

// Particles of the positions (N, D) per block layer along the slab axis (non-finite: layer 0, rank 0's, as
// Decomposition::appendOwn keeps them): the counts of a region before it is added (yade_mpm.add_region).
template <int D>
bp::list mpiLayerCounts(Solver<D>& s, bp::object pos)
{
	np::ndarray         x = asDoubleArray(pos, "positions", D);
	const double*       p = reinterpret_cast<const double*>(x.get_data());
	std::vector<double> count(size_t(SlabLayout<D>::layers(s.grid)), 0.0);
	for (size_t k = 0, n = size_t(x.shape(0)); k < n; ++k) {
		const double z = p[k * D + D - 1];
		count[std::isfinite(z) ? size_t(SlabLayout<D>::layerOf(s.grid, z)) : 0] += 1;
	}
	bp::list out;
	for (double c : count) out.append(c);
	return out;
}
template <int D>
void mpiPlan(Solver<D>& s, bp::object counts)
{
	std::vector<double> c(size_t(bp::len(counts)));
	for (size_t k = 0; k < c.size(); ++k) c[k] = bp::extract<double>(counts[k]);
	s.dd.plan(s.grid, s.P, c, s.liveViews);
}

} // namespace

// MPI_Init_thread at import (one thread per rank calls MPI: FUNNELED); MPI_Finalize when Python exits.
void initMpi()
{
	int on = 0;
	MPI_Initialized(&on);
	if (!on) {
		int provided = 0;
		MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
		startedHere = true;
		if (provided < MPI_THREAD_FUNNELED) throw SimulationError("MPI: the library does not provide MPI_THREAD_FUNNELED (needed with OpenMP threads)");
		Py_AtExit(&finalize);
	}
	bp::def("mpiRank", &rank, "This process's rank in MPI_COMM_WORLD.");
	bp::def("mpiSize", &size, "Number of MPI ranks.");
	bp::def("mpiSum", &sum, "Sum of a float over the MPI ranks (every rank must call it: a collective).");
	bp::def("mpiMax", &maxList, "Element-wise max of a list of floats over the MPI ranks (a collective; the same length on every rank).");
}

template <int D>
void exposeMpi(SolverClass<D>& cls, const char*)
{
	cls.def("mpiInfo", &mpiInfo<D>, "MPI decomposition of this solver: rank, size, firstLayers, local particles, migrated, rebalances, imbalance, haloBytesSent; memory: heldLayers, gridNodes, gridBytes, particleBytes, peakRSS [B].");
	cls.def("_mpiDistribute", &mpiDistribute<D>,
	        "Distributed construction (yade_mpm.parallel.distribute): from now on each rank keeps only the particles of its slab; before adding any.");
	cls.def("_mpiLayerCounts", &mpiLayerCounts<D>, "Distributed construction: particles of the positions (N, D) per block layer along the slab axis.");
	cls.def("_mpiPlan", &mpiPlan<D>,
	        "Distributed construction, before adding a region: its particle counts per block layer (the same on every rank); the first region sets the "
	        "start layout and the grid window from them, every region reserves this rank's share.");
	cls.def("_mpiRestoreSlab", &mpiRestoreSlab<D>, (bp::arg("firstLayers"), bp::arg("particles"), bp::arg("traction") = false, bp::arg("damageState") = false, bp::arg("flaws") = false),
	        "Checkpoint resume: the saved slab layout, the rank's particle count and the optional fields of its piece (yade_mpm.checkpoint).");
}
template void exposeMpi<2>(SolverClass<2>&, const char*);
template void exposeMpi<3>(SolverClass<3>&, const char*);

} // namespace mpm
#endif
