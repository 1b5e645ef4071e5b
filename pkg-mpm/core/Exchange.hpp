// The exchange policy of a step: the hooks through which the processes that hold parts of one scene add up
// their partial sums and agree on decisions. The phases call these hooks and never communicate themselves.
// LocalExchange is the policy of a single process (every hook empty, the calls vanish); the distributed
// policy is MpiExchange (mpi/MpiExchange.hpp). A policy provides:
//   distributed()                       more than one process holds a part of the scene
//   owns(i)                             node i is counted by this process in sums over nodes (one process per node)
//   sumShared(grid, field, err, phase)  every thread: adds the other processes' partial sums of the shared nodes
//                                       to a node array; a failure recorded on any process reaches every err
//   sumSharedArrays(grid, arrays, n, err, phase)  the same for n (≤ 8) per-node arrays of Real, in one message
//   sumInOrder(v, n)                    in oneThread: v ← Σ over the processes, in a fixed order (the same bits on each)
//   oneThread(f)                        every thread: f() on the one thread that may communicate, then a barrier
#pragma once
#include "MpmTypes.hpp"
#include <vector>

namespace mpm {

struct LocalExchange {
	static constexpr bool distributed() { return false; }
	static constexpr bool owns(size_t) { return true; }
	template <class G, class E>
	void sumShared(const G&, std::vector<E>&, ErrorRecord&, const char*) const { }
	template <class G>
	void sumSharedArrays(const G&, Real* const*, int, ErrorRecord&, const char*) const { }
	void sumInOrder(double*, int) const { }
	template <class F>
	static void oneThread(F&& f)
	{
#pragma omp single
		f();
	}
};

} // namespace mpm
