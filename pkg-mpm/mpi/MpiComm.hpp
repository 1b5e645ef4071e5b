// The MPI layer of the distributed build (module yade_mpm._core_mpi, compiled with -DMPM_MPI; doc/scaling.md).
// Comm wraps the few MPI calls the decomposition needs (MPI_COMM_WORLD, called by one thread of a rank:
// MPI_THREAD_FUNNELED). Reductions whose result enters the state are max (exact), sums of integers stored as
// doubles (exact) or sums in rank order, so every rank gets the same bits.
#pragma once
#include "../core/MpmTypes.hpp"
#include <algorithm>
#include <vector>

#ifdef MPM_MPI
#include <mpi.h>
#endif

namespace mpm {

#ifdef MPM_MPI
struct Comm {
	static MPI_Comm world() { return MPI_COMM_WORLD; }
	static int      rank()
	{
		int r = 0;
		MPI_Comm_rank(world(), &r);
		return r;
	}
	static int size()
	{
		int s = 1;
		MPI_Comm_size(world(), &s);
		return s;
	}
	static void max(double* v, int n) { MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_MAX, world()); }
	static void sum(double* v, int n) { MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_SUM, world()); }
	static void maxBytes(uint8_t* v, size_t n) // element-wise max of a byte map (cell occupancy), in chunks of < 2^31
	{
		for (size_t k = 0; k < n; k += size_t(INT32_MAX)) MPI_Allreduce(MPI_IN_PLACE, v + k, int(std::min(n - k, size_t(INT32_MAX))), MPI_UINT8_T, MPI_MAX, world());
	}
	// v ← Σ_r v_r summed in rank order 0, 1, …, R − 1 on every rank (an all-gather, then the same additions
	// everywhere): the same bits on every rank for any rank count (MPI_SUM leaves the order to the library).
	static void sumInRankOrder(double* v, int n, std::vector<double>& all) // all: scratch
	{
		const int R = size();
		all.resize(size_t(R) * size_t(n));
		MPI_Allgather(v, n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, world());
		for (int k = 0; k < n; ++k) {
			double s = all[size_t(k)];
			for (int r = 1; r < R; ++r) s += all[size_t(r) * size_t(n) + size_t(k)];
			v[k] = s;
		}
	}
	// The concatenation of every rank's bytes in rank order, on every rank (an all-gather of the counts, then of the
	// bytes); returns where this rank's bytes start in `all`.
	// counts: scratch (2 ints per rank).
	static size_t gatherBytes(const char* mine, size_t n, std::vector<char>& all, std::vector<int>& counts)
	{
		const int R = size(), me = rank();
		counts.assign(2 * size_t(R), 0);
		int* const count = counts.data();
		int* const at    = count + R;
		if (n > size_t(INT32_MAX)) throw SimulationError("MPI gather of " + std::to_string(n) + " bytes exceeds the 2^31 − 1 limit of one message");
		const int nn = int(n);
		MPI_Allgather(&nn, 1, MPI_INT, count, 1, MPI_INT, world());
		size_t total = 0;
		for (int r = 0; r < R; ++r) {
			if (total > size_t(INT32_MAX)) throw SimulationError("MPI gather exceeds the 2^31 − 1 byte limit of one message");
			at[r] = int(total), total += size_t(count[r]);
		}
		all.resize(total);
		MPI_Allgatherv(mine, nn, MPI_BYTE, all.data(), count, at, MPI_BYTE, world());
		return size_t(at[me]);
	}
	// A failure recorded on any rank reaches every rank's err (the other ranks' as "elsewhere"); phase names the step's part.
	static void agree(ErrorRecord& err, const char* phase)
	{
		if (!all(err.none()) && err.none())
			err.record(ErrorRecord::elsewhere, std::string("stopped: the ") + phase + " of another MPI rank failed (its message names the particle)");
	}
	// True on every rank iff `ok` is true on every rank (a failure on one rank stops all of them together).
	static bool all(bool ok)
	{
		int v = ok ? 1 : 0;
		MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_INT, MPI_MIN, world());
		return v == 1;
	}
	// Exchange with the two slab neighbours (down = rank − 1, up = rank + 1; < 0 or ≥ size: none):
	// sends sd/su, receives into rd/ru, whose sizes both sides know. Non-blocking pairs, one wait.
	static void neighbours(int down, int up, const std::vector<double>& sd, std::vector<double>& rd, const std::vector<double>& su, std::vector<double>& ru)
	{
		MPI_Request req[4];
		int         k = 0;
		const int   s = size();
		auto count = [](size_t n) {
			if (n > size_t(INT32_MAX)) throw SimulationError("MPI message of " + std::to_string(n) + " values exceeds the 2^31 − 1 limit of one message");
			return int(n);
		};
		if (down >= 0) MPI_Irecv(rd.data(), count(rd.size()), MPI_DOUBLE, down, 1, world(), &req[k++]);
		if (up < s) MPI_Irecv(ru.data(), count(ru.size()), MPI_DOUBLE, up, 0, world(), &req[k++]);
		if (down >= 0) MPI_Isend(sd.data(), count(sd.size()), MPI_DOUBLE, down, 0, world(), &req[k++]);
		if (up < s) MPI_Isend(su.data(), count(su.size()), MPI_DOUBLE, up, 1, world(), &req[k++]);
		MPI_Waitall(k, req, MPI_STATUSES_IGNORE);
	}
};
#endif

} // namespace mpm
