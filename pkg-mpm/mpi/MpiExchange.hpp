// The exchange policy of the MPI build (core/Exchange.hpp) over the ranks of the Solver's decomposition: shared
// node bands summed like P2G's (HaloExchange), each node counted on its owner rank in sums over nodes, per-body sums
// added in rank order: every rank gets the same bits (doc/developer/core_notes.md, "The exchange policy").
#pragma once
#include "../core/Exchange.hpp"
#include "Decomposition.hpp"
#include <cstring>

#ifdef MPM_MPI
namespace mpm {

template <int D>
struct MpiExchange {
	Decomposition<D>* dd = nullptr;

	bool distributed() const { return dd && dd->distributed(); }
	bool owns(size_t i) const { return !dd || dd->ownsNode(i); }
	template <class E>
	void sumShared(const Grid<D>& grid, std::vector<E>& field, ErrorRecord& err, const char* phase) const
	{
		if (distributed()) dd->halo.sum(dd->layout, grid, dd->rank, field, err, phase);
	}
	void sumSharedArrays(const Grid<D>& grid, Real* const* arrays, int n, ErrorRecord& err, const char* phase) const
	{
		if (!distributed()) return;
		typename HaloExchange<D>::Span sp[8]; // n ≤ 8 (Exchange.hpp)
		for (int k = 0; k < n; ++k) sp[k] = { arrays[k], 1 };
		dd->halo.sumSpans(dd->layout, grid, dd->rank, sp, n, err, phase);
	}
	void sumInOrder(double* v, int n) const { dd->sumInRankOrder(v, n); }
	template <class T>
	size_t gatherInOrder(std::vector<T>& v) const
	{
		if (!distributed()) return 0;
		const size_t at = Comm::gatherBytes(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T), gathered, counts);
		v.resize(gathered.size() / sizeof(T));
		std::memcpy(static_cast<void*>(v.data()), gathered.data(), gathered.size());
		return at / sizeof(T);
	}
	void agree(ErrorRecord& err, const char* phase) const
	{
		if (distributed()) Comm::agree(err, phase);
	}

	// MPI is called by the master thread only (MPI_THREAD_FUNNELED), hence master and a barrier, not `single`.
	template <class F>
	static void oneThread(F&& f)
	{
#pragma omp master
		f();
#pragma omp barrier
	}

private:
	mutable std::vector<char> gathered; // scratch of gatherInOrder (capacity kept between steps)
	mutable std::vector<int>  counts;
};

} // namespace mpm
#endif
