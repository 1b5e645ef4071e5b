// Grid node data, one array per quantity as the step's phases produce them (paper Fig. 2):
//
//   nodes  Node<D>      P2G: lumped mass m (Eq. 20), Shepard mass mw = Σ w m (Eq. 17 denominator),
//                       momentum p (Eq. 20) and force f (Eqs. 21–22); without damping p holds p + Δt f
//                       (Eq. 18's numerator, summed by P2G directly) and f stays 0 (Transfer::p2g)
//   vel    NodeVec<D>   gridUpdate: updated velocity (Eq. 18), corrected by the contact (Eqs. 23–26)
//   mom    NodeVec<D>   G2P: MUSL momentum Σ w m h_p(x_i) (Eq. 16 numerator)
//   vmusl  NodeVec<D>   gridMusl: MUSL velocity (Eqs. 16–17), read by the stress pass (Eq. 7)
//
// A Node fills one 64-byte cache line (2D: 6 values + 2 padding lanes, 3D: 8), so P2G updates a whole
// node with one 8-lane vector operation (2D without damping: the 4 lanes m, mw, p + Δt f). A NodeVec holds D components (3D: + 1 padding lane), so the 4
// nodes of a stencil row along x are one (2D) or two (3D) contiguous 8-lane vectors for the gathers
// and the MUSL scatter (Lanes.hpp).
#pragma once
#include "MpmTypes.hpp"

namespace mpm {

template <int D>
struct alignas(64) Node {
	Real m, mw;
	Real p[D]; // momentum
	Real f[D]; // force
};
// Lane vectors of doubles alias doubles (GCC gives a vector type its element's alias set), not the pointers
// of the particle arrays: no may_alias, so stores to nodes do not force the array pointers to be reloaded.
typedef Real NodeLanes __attribute__((vector_size(64)));
static_assert(sizeof(Node<2>) == sizeof(NodeLanes) && sizeof(Node<3>) == sizeof(NodeLanes), "a node must fill one lane vector");
template <int D>
inline NodeLanes& lanes(Node<D>& n) { return *reinterpret_cast<NodeLanes*>(&n); }
template <int D>
inline const NodeLanes& lanes(const Node<D>& n) { return *reinterpret_cast<const NodeLanes*>(&n); }

// A nodal vector (velocity, MUSL momentum, MUSL velocity): D components, 2 lanes in 2D, 4 in 3D.
template <int D>
struct alignas(D == 2 ? 16 : 32) NodeVec { // aligned as its lane vector (C++17 aligned new in std::vector)
	static constexpr int S = D == 2 ? 2 : 4;
	Real                 c[S];
};
template <int D>
struct NodeVecLanesOf {
	typedef Real type __attribute__((vector_size(sizeof(NodeVec<D>))));
};
template <int D>
using NodeVecLanes = typename NodeVecLanesOf<D>::type;
template <int D>
inline NodeVecLanes<D>& lanes(NodeVec<D>& n) { return *reinterpret_cast<NodeVecLanes<D>*>(&n); }
template <int D>
inline const NodeVecLanes<D>& lanes(const NodeVec<D>& n) { return *reinterpret_cast<const NodeVecLanes<D>*>(&n); }
static_assert(sizeof(NodeVec<2>) == 16 && sizeof(NodeVec<3>) == 32, "4 NodeVecs of a row fill 1 (2D) or 2 (3D) lane vectors");

} // namespace mpm
