// One grid node as the transfer kernels see it: a 64-byte record updated as one 8-lane vector.
#pragma once
#include "MpmTypes.hpp"

namespace mpm {

// Lumped mass (Eq. 20), Shepard mass Σ w m (Eq. 17 denominator) and two vector slots reused within a
// step: a = momentum → updated velocity, b = force → MUSL velocity.
// A node fills one 64-byte cache line (2D: 6 values + 2 padding lanes, 3D: 8 values), so the transfer
// kernels update a whole node with one 8-lane vector operation (lanes: m, mw, a…, b…, padding).
template <int D>
struct alignas(64) Node {
	Real m, mw;
	Real a[D];
	Real b[D];
};
typedef Real NodeLanes __attribute__((vector_size(64), may_alias));
static_assert(sizeof(Node<2>) == sizeof(NodeLanes) && sizeof(Node<3>) == sizeof(NodeLanes), "a node must fill one lane vector");
template <int D>
inline NodeLanes& lanes(Node<D>& n) { return *reinterpret_cast<NodeLanes*>(&n); }
template <int D>
inline const NodeLanes& lanes(const Node<D>& n) { return *reinterpret_cast<const NodeLanes*>(&n); }

} // namespace mpm
