// The cut-stencil fits of one step, made once in P2G and read back by G2P and the stress pass (Transfer.hpp).
#pragma once
#include "../core/WlsShape.hpp"
#include <algorithm>
#include <vector>

namespace mpm {

// The cut-stencil fits of one step (a stencil node excluded: fillStencil's general path), made once in P2G and read
// back by G2P and the stress pass, between which neither the particles nor the node exclusions change. Each thread
// fills its own store; block b's fits are owner[b]'s entries from start[b] on, in the block's particle order. The
// capacity is fixed during a step: a block that does not fit is not cached (its later passes fit again, the same
// bits) and the stores grow after the step (endStep). Memory: the cut particles of a step and two words per block.
template <int D>
struct CutStencilCache {
	static constexpr uint32_t none = UINT32_MAX;
	std::vector<std::vector<Stencil<D>>> store; // per thread
	std::vector<uint32_t>                used, need; // per thread: entries filled this step, entries it met
	std::vector<uint32_t>                owner, start; // per block (start = none: not cached)

	// Serial, before the step's P2G: room for `blocks` blocks and `threads` threads (grows only).
	void beginStep(size_t blocks, int threads)
	{
		if (owner.size() < blocks) owner.resize(blocks), start.resize(blocks);
		if (store.size() < size_t(threads)) store.resize(size_t(threads)), used.resize(size_t(threads)), need.resize(size_t(threads));
		std::fill(used.begin(), used.end(), 0u), std::fill(need.begin(), need.end(), 0u);
	}
	// Serial, after the step: a thread that met more cut particles than its store holds gets room for them.
	void endStep()
	{
		for (size_t t = 0; t < store.size(); ++t)
			if (need[t] > store[t].size()) store[t].resize(need[t] + need[t] / 2 + 8);
	}
	// The fits of block b in particle order, or nullptr when the block was not cached.
	const Stencil<D>* block(uint32_t b) const { return start[b] == none ? nullptr : store[owner[b]].data() + start[b]; }
};

} // namespace mpm
