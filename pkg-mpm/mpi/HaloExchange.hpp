// Sums of the node layers two ranks share (MPI build only; doc/scaling.md): after a scatter (P2G, Eqs. 20–22; G2P,
// Eq. 16) both neighbours send their partial sums of the shared band and add the other's, so both hold a + b, the
// same bits, and the nodal updates (Eqs. 17–18) need no second exchange. Called by every thread of the step's
// region; the master thread communicates (MPI_THREAD_FUNNELED); a failure on any rank reaches every rank.
#pragma once
#include "MpiComm.hpp"
#include "SlabLayout.hpp"
#include <cstring>

#ifdef MPM_MPI
namespace mpm {

template <int D>
class HaloExchange {
public:
	// One node array as doubles: `per` doubles per stored node.
	struct Span {
		double* data;
		size_t  per;
	};
	// Adds the neighbours' partial sums of the shared bands into field (one entry per stored node).
	template <class E>
	void sum(const SlabLayout<D>& L, const Grid<D>& g, int rank, std::vector<E>& field, ErrorRecord& err, const char* phase)
	{
		static_assert(sizeof(E) % sizeof(double) == 0, "node entries are arrays of doubles");
		const Span s { reinterpret_cast<double*>(field.data()), sizeof(E) / sizeof(double) }; // E is a plain array of doubles
		sumSpans(L, g, rank, &s, 1, err, phase);
	}
	// The same for n node arrays in one message per neighbour (e.g. the contact arrays of PenaltyContact).
	void sumSpans(const SlabLayout<D>& L, const Grid<D>& g, int rank, const Span* s, int n, ErrorRecord& err, const char* phase)
	{
#pragma omp barrier
#pragma omp master
		exchange(L, g, rank, s, n, err, phase);
#pragma omp barrier
	}
	size_t bytesLastStep = 0; // sent per exchange (both neighbours), for doc/scaling.md

private:
	std::vector<double> sd, su, rd, ru;

	void exchange(const SlabLayout<D>& L, const Grid<D>& g, int rank, const Span* s, int n, ErrorRecord& err, const char* phase)
	{
		const int R  = L.ranks();
		size_t    d0 = 0, d1 = 0, u0 = 0, u1 = 0; // node ranges shared with rank − 1 and rank + 1
		int       lo, hi;
		if (rank > 0) L.sharedLayers(g, rank, lo, hi), L.nodeRange(g, lo, hi, d0, d1);
		if (rank + 1 < R) L.sharedLayers(g, rank + 1, lo, hi), L.nodeRange(g, lo, hi, u0, u1);
		auto pack = [&](std::vector<double>& buf, size_t i0, size_t i1) {
			buf.clear();
			for (int k = 0; k < n; ++k) buf.insert(buf.end(), s[k].data + i0 * s[k].per, s[k].data + i1 * s[k].per);
		};
		pack(sd, d0, d1), pack(su, u0, u1);
		rd.resize(sd.size()), ru.resize(su.size());
		Comm::neighbours(rank - 1, rank + 1, sd, rd, su, ru);
		bytesLastStep = (sd.size() + su.size()) * sizeof(double);
		auto add = [&](const std::vector<double>& buf, size_t i0, size_t i1) {
			size_t j = 0;
			for (int k = 0; k < n; ++k)
				for (double *f = s[k].data + i0 * s[k].per, *e = s[k].data + i1 * s[k].per; f < e; ++f) *f += buf[j++];
		};
		add(rd, d0, d1), add(ru, u0, u1);
		Comm::agree(err, phase);
	}
};

} // namespace mpm
#endif
