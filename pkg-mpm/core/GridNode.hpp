// The data of a grid node (paper Fig. 2): Node<D>, what P2G sums (one 64-byte cache line, updated as one 8-lane
// vector), and NodeVec<D>, a nodal vector (velocity, MUSL momentum, MUSL velocity; 4 of them fill one or two lane
// vectors along a stencil row). The arrays and the phase that writes each: Grid.hpp.
#pragma once
#include "MpmTypes.hpp"

namespace mpm {

template <int D>
struct alignas(64) Node {
	Real m, mw;   // lumped mass (Eq. 20), Shepard mass Σ w m (Eq. 17 denominator)
	Real p[D];    // momentum (Eq. 20); without damping p + Δt f, Eq. 18's numerator summed by P2G (Transfer::p2g)
	Real f[D];    // force (Eqs. 21–22); 0 without damping (then in p)
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
