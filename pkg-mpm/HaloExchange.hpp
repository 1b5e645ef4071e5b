// Sums of the node layers two ranks share (MPI build only; SlabLayout.hpp, doc/scaling.md). After a
// scatter (P2G: nodes, Eqs. 20–22; G2P: the MUSL momentum mom, Eq. 16) each rank holds partial sums from
// its own particles; both neighbours send their partial sums of the shared band and add the other's, so
// both hold a + b, the same bits (IEEE addition is commutative; a node is shared by two ranks at most).
// The grid update (Eq. 18) and the MUSL velocity (Eq. 17) then run on each rank's copy of the band with
// the same inputs and give the same values: no second exchange before G2P or the stress update.
//
// The exchange is called by every thread of the step's parallel region; one thread communicates
// (MPI_THREAD_FUNNELED) between two barriers. It also agrees on failures: if the scatter failed on any
// rank, every rank's ErrorRecord holds a failure afterwards and all ranks stop the step together.
#pragma once
#include "MpiComm.hpp"
#include "SlabLayout.hpp"
#include <cstring>

#ifdef MPM_MPI
namespace mpm {

template <int D>
class HaloExchange {
public:
	// Adds the neighbours' partial sums of the shared bands into field (one entry per stored node).
	template <class E>
	void sum(const SlabLayout<D>& L, const Grid<D>& g, int rank, std::vector<E>& field, ErrorRecord& err, const char* phase)
	{
#pragma omp barrier
#pragma omp master
		exchange(L, g, rank, field, err, phase);
#pragma omp barrier
	}
	size_t bytesLastStep = 0; // sent per exchange (both neighbours), for doc/scaling.md

private:
	std::vector<double> sd, su, rd, ru;

	template <class E>
	void exchange(const SlabLayout<D>& L, const Grid<D>& g, int rank, std::vector<E>& field, ErrorRecord& err, const char* phase)
	{
		static_assert(sizeof(E) % sizeof(double) == 0, "node entries are arrays of doubles");
		constexpr size_t per = sizeof(E) / sizeof(double);
		const int        R   = L.ranks();
		size_t           d0 = 0, d1 = 0, u0 = 0, u1 = 0; // node ranges shared with rank − 1 and rank + 1
		int              lo, hi;
		if (rank > 0) L.sharedLayers(g, rank, lo, hi), L.nodeRange(g, lo, hi, d0, d1);
		if (rank + 1 < R) L.sharedLayers(g, rank + 1, lo, hi), L.nodeRange(g, lo, hi, u0, u1);
		auto pack = [&](std::vector<double>& buf, size_t i0, size_t i1) {
			buf.resize((i1 - i0) * per);
			if (i1 > i0) std::memcpy(buf.data(), &field[i0], (i1 - i0) * sizeof(E));
		};
		pack(sd, d0, d1), pack(su, u0, u1);
		rd.resize(sd.size()), ru.resize(su.size());
		Comm::neighbours(rank - 1, rank + 1, sd, rd, su, ru);
		bytesLastStep = (sd.size() + su.size()) * sizeof(double);
		auto add = [&](const std::vector<double>& buf, size_t i0, size_t i1) {
			double* f = reinterpret_cast<double*>(field.data() + i0); // E is a plain array of doubles
			for (size_t k = 0, n = (i1 - i0) * per; k < n; ++k) f[k] += buf[k];
		};
		add(rd, d0, d1), add(ru, u0, u1);
		if (!Comm::all(err.none()) && err.none())
			err.record(ErrorRecord::elsewhere, std::string("stopped: the ") + phase + " of another MPI rank failed (its message names the particle)");
	}
};

} // namespace mpm
#endif
