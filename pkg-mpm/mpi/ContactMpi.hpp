// The MPI side of the PTS contact (MPI build only; PtsContact.hpp, doc/scaling.md "Rigid bodies").
// Every rank holds the same rigid bodies (YADE replicated on every rank) and the grid nodes its particles
// reach. A group is skipped from its geometry alone (its exchange and reductions are collective: every
// rank takes part, with or without particles near the body). Two collectives per step make the contact
// of N ranks the contact of one scene:
//   sumShared    after the particle pass: f_nor, N_i, A_i of the shared node bands summed like P2G's sums
//                (HaloExchange), so the node pass of a shared node gives the same bits on both ranks;
//   reduceParts  after the reactions: each rank sums over the nodes it owns (Decomposition::ownsNode), then
//                the per-part force and torque are added over the ranks in rank order (an all-gather and the
//                same additions on every rank) before YADE integrates them: the same bits on every rank.
// bodyResponse (a free body's stick step) reduces its A and b the same way (Decomposition::sumInRankOrder).
#pragma once
#include "Decomposition.hpp"

#ifdef MPM_MPI
namespace mpm {
namespace contactMpi {

// Called by every thread of the step's parallel region (HaloExchange communicates from the master thread).
template <int D>
void sumShared(Decomposition<D>* dd, const Grid<D>& grid, std::vector<Real> (&fn)[D], std::vector<Real>& load, std::vector<Real>& area, ErrorRecord& err)
{
	if (!dd || !dd->distributed()) return;
	typename HaloExchange<D>::Span sp[D + 2];
	for (int a = 0; a < D; ++a) sp[a] = { fn[a].data(), 1 };
	sp[D] = { load.data(), 1 }, sp[D + 1] = { area.data(), 1 };
	dd->halo.sumSpans(dd->layout, grid, dd->rank, sp, D + 2, err, "contact");
}

template <int D, class Parts>
void reduceParts(Decomposition<D>* dd, std::vector<double>& buf, Parts& parts)
{
	if (!dd || !dd->distributed()) return;
	constexpr int n = D + (D == 2 ? 1 : 3); // force, torque
	buf.resize(parts.size() * n);
	for (size_t p = 0; p < parts.size(); ++p)
		for (int k = 0; k < n; ++k) buf[p * n + size_t(k)] = k < D ? parts[p].force[k] : parts[p].torque[k - D];
	dd->sumInRankOrder(buf.data(), int(buf.size()));
	for (size_t p = 0; p < parts.size(); ++p)
		for (int k = 0; k < n; ++k) (k < D ? parts[p].force[k] : parts[p].torque[k - D]) = buf[p * n + size_t(k)];
}

} // namespace contactMpi
} // namespace mpm
#endif
