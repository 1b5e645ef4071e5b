// Deterministic parallel scatter without atomics: particles are counting-sorted into blocks of
// B^D cells and blocks are coloured 2^D ways. Two blocks of one colour are ≥ B cells apart, so
// their stencils (a particle may drift up to `margin` cells out of its block before a re-sort)
// never share a node. Colours run one after another; within a colour each block is summed by one
// thread in particle order, so every node sum has the same order for any thread count.
#pragma once
#include "Grid.hpp"
#include "Particles.hpp"
#include <algorithm>
#include <vector>

namespace mpm {

template <int D>
struct BlockSchedule {
	using IVec                  = typename Dim<D>::IVec;
	static constexpr int B      = 8; // cells per block edge
	static constexpr int margin = 1; // cells a particle may leave its block before a re-sort
	static_assert(B + 3 + 2 * margin < 2 * B, "same-colour blocks must not share stencil nodes");

	IVec                  nBlocks;
	std::vector<uint32_t> start;               // particles of block b: [start[b], start[b+1])
	std::vector<uint32_t> colour[1 << D];      // non-empty blocks per colour
	std::vector<uint32_t> colourCum[1 << D];   // particles in colour[c][0..k), k = 0..size (thread shares)
	std::vector<uint32_t> perm, count, key;    // sort work arrays (kept: no allocation while stepping)
	std::vector<Real>     tmp;                 // Particles::permute's buffer (fields, material indices and ids)

	size_t blockCount() const
	{
		size_t n = 1;
		for (int a = 0; a < D; ++a) n *= nBlocks[a];
		return n;
	}
	IVec blockCoords(size_t b) const
	{
		IVec c;
		for (int a = 0; a < D; ++a) {
			c[a] = int(b % nBlocks[a]);
			b /= nBlocks[a];
		}
		return c;
	}
	size_t blockOf(const Grid<D>& g, const Particles<D>& P, size_t p) const
	{
		size_t b = 0, s = 1;
		for (int a = 0; a < D; ++a) {
			int c = int(std::floor((P.x[a][p] - g.origin[a]) / g.spacing)) / B;
			c     = std::min(std::max(c, 0), nBlocks[a] - 1);
			b += size_t(c) * s;
			s *= nBlocks[a];
		}
		return b;
	}
	// Fractional cell coordinates (x − origin)/l a particle of block b may reach, per axis, before a re-sort.
	void reach(size_t b, Real* lo, Real* hi) const
	{
		IVec bc = blockCoords(b);
		for (int a = 0; a < D; ++a) {
			lo[a] = bc[a] * B - margin;
			hi[a] = (bc[a] + 1) * B + margin;
		}
	}

	// Stable counting sort of the particles by block; permutes every particle field.
	void sort(const Grid<D>& g, Particles<D>& P)
	{
		for (int a = 0; a < D; ++a) nBlocks[a] = (g.cells[a] + B - 1) / B;
		const size_t nb = blockCount();
		count.assign(nb + 1, 0);
		key.resize(P.n);
		for (size_t p = 0; p < P.n; ++p) {
			key[p] = uint32_t(blockOf(g, P, p));
			++count[key[p] + 1];
		}
		for (size_t b = 0; b < nb; ++b) count[b + 1] += count[b];
		start.assign(count.begin(), count.end());
		perm.resize(P.n);
		for (size_t p = 0; p < P.n; ++p) perm[count[key[p]]++] = uint32_t(p);
		P.permute(perm, tmp);
		buildColours();
	}

	// Schedule of a checkpoint (py/yade_mpm/checkpoint.py): the block ranges of the last sort, for
	// particles already stored in that sort's order. False (nothing changed) if they do not fit.
	bool restore(const Grid<D>& g, const std::vector<uint32_t>& blockStart, size_t nParticles)
	{
		IVec nbk;
		size_t nb = 1;
		for (int a = 0; a < D; ++a) nbk[a] = (g.cells[a] + B - 1) / B, nb *= nbk[a];
		if (blockStart.size() != nb + 1 || blockStart.front() != 0 || blockStart.back() != nParticles) return false;
		for (size_t b = 0; b < nb; ++b)
			if (blockStart[b + 1] < blockStart[b]) return false;
		nBlocks = nbk;
		start   = blockStart;
		buildColours();
		return true;
	}

	// The particles with drop[p] == 1 are taken out of the storage (Particles::compact): each block keeps its
	// other particles, in their order, so the schedule stays valid without a re-sort.
	void dropSlots(const std::vector<uint8_t>& drop)
	{
		uint32_t gone = 0;
		for (size_t b = 0; b + 1 < start.size(); ++b) {
			const uint32_t s0 = start[b], s1 = start[b + 1];
			start[b] -= gone;
			for (uint32_t p = s0; p < s1; ++p) gone += drop[p];
		}
		if (!start.empty()) start.back() -= gone;
		buildColours();
	}

	void buildColours()
	{
		const size_t nb = blockCount();
		for (auto& c : colour) c.clear();
		for (size_t b = 0; b < nb; ++b) {
			if (start[b] == start[b + 1]) continue;
			IVec bc = blockCoords(b);
			int  k  = 0;
			for (int a = 0; a < D; ++a) k |= (bc[a] & 1) << a;
			colour[k].push_back(uint32_t(b));
		}
		for (int c = 0; c < (1 << D); ++c) {
			colourCum[c].assign(1, 0);
			for (uint32_t b : colour[c]) colourCum[c].push_back(colourCum[c].back() + (start[b + 1] - start[b]));
		}
	}

	// Share t of T of the blocks of colour c (Transfer::scatterBlocks): the entries [k0, k1) of colour[c],
	// contiguous runs of about equal particle counts.
	void colourShare(int c, int t, int T, size_t& k0, size_t& k1) const
	{
		if (colour[c].empty()) return void(k0 = k1 = 0);
		const uint32_t* cum   = colourCum[c].data();
		const size_t    n     = colour[c].size();
		const uint64_t  total = cum[n];
		auto            at    = [&](int i) {
			const uint64_t target = total * uint64_t(i) / uint64_t(T);
			return std::min(size_t(std::lower_bound(cum, cum + n + 1, target) - cum), n);
		};
		k0 = t == 0 ? 0 : at(t);
		k1 = t + 1 == T ? n : at(t + 1);
	}
};

} // namespace mpm
