// The exchange policy of a step: the hooks through which the processes that hold parts of one scene add up their
// partial sums and agree on decisions; the phases call them and never communicate themselves. LocalExchange is the
// policy of one process (every hook empty); mpi/MpiExchange.hpp is the distributed one with the same interface.
#pragma once
#include "MpmTypes.hpp"
#include <vector>

namespace mpm {

struct LocalExchange {
	// More than one process holds a part of the scene.
	static constexpr bool distributed() { return false; }
	// Node i is counted by this process in sums over nodes (each node by one process).
	static constexpr bool owns(size_t) { return true; }
	// Every thread: adds the other processes' partial sums of the shared nodes to a node array (entries of doubles);
	// a failure recorded on any process reaches every err.
	template <class G, class E>
	void sumShared(const G&, std::vector<E>&, ErrorRecord&, const char*) const { }
	// The same for n (≤ 8) per-node arrays of Real, in one message.
	template <class G>
	void sumSharedArrays(const G&, Real* const*, int, ErrorRecord&, const char*) const { }
	// In oneThread: v ← the sum of every process's v in a fixed order (the same bits on each).
	void sumInOrder(double*, int) const { }
	// In oneThread: v ← every process's v concatenated in process order (T trivially copyable); returns where this
	// process's entries start.
	template <class T>
	size_t gatherInOrder(std::vector<T>&) const { return 0; }
	// In oneThread: a failure recorded on any process reaches every err (the others' as "elsewhere").
	void agree(ErrorRecord&, const char*) const { }
	// Every thread: f() on the one thread that may communicate, then a barrier.
	template <class F>
	static void oneThread(F&& f)
	{
#pragma omp single
		f();
	}
};

} // namespace mpm
