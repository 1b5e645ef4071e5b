// C++ unit tests of the MPI slab layout (SlabLayout.hpp), in the serial build: the load-balance rule on
// given counts, the owner of each block layer, and the node layers a rank's particles reach, checked
// against a brute-force walk over particle positions (stencil nodes floor(f) − 1 … floor(f) + 2 of every
// position a particle of the slab may take before a re-sort).
#include "mpi/SlabLayout.hpp"
#include "Check.hpp"
#include <set>

using namespace mpm;

template <int D>
void balance()
{
	using S = SlabLayout<D>;
	// uniform counts: equal slabs
	auto u = S::balanced(std::vector<double>(8, 100.0), 4);
	CHECK((u.first == std::vector<int> { 0, 2, 4, 6, 8 }), "uniform: %d %d %d", u.first[1], u.first[2], u.first[3]);
	// all particles in the upper half: the boundary moves up (rank 0 takes the empty layers)
	std::vector<double> c { 0, 0, 0, 0, 10, 10, 10, 10 };
	auto h = S::balanced(c, 2);
	CHECK(h.first[1] == 6, "upper half: first[1] = %d (expected 6)", h.first[1]);
	// empty scene or more ranks than particles: still ≥ 1 layer each
	auto e = S::balanced(std::vector<double>(5, 0.0), 5);
	for (int r = 0; r < 5; ++r) CHECK(e.first[size_t(r) + 1] - e.first[size_t(r)] == 1, "empty: rank %d owns %d layers", r, e.first[size_t(r) + 1] - e.first[size_t(r)]);
	// owner of every layer
	for (int l = 0; l < 8; ++l) CHECK(u.owner(l) == l / 2, "owner(%d) = %d", l, u.owner(l));
	bool threw = false;
	try {
		S::balanced(std::vector<double>(3, 1.0), 4);
	} catch (const InputError&) {
		threw = true;
	}
	CHECK(threw, "4 ranks on 3 layers must be refused");
}

// Brute force: stored node layers along the slab axis reached by the particles of rank r.
template <int D>
std::set<int> reached(const SlabLayout<D>& s, int r, int cells)
{
	constexpr int B = SlabLayout<D>::B, M = SlabLayout<D>::margin, G = Grid<D>::ghost;
	std::set<int> k;
	for (int l = s.first[size_t(r)]; l < s.first[size_t(r) + 1]; ++l)
		for (double f = l * B - M; f < (l + 1) * B + M; f += 0.125) {
			if (f < 0 || f >= cells) continue; // particles stay on the grid
			const int c = int(std::floor(f));
			for (int j = -1; j <= 2; ++j) k.insert(c + j + G);
		}
	return k;
}

template <int D>
void reach()
{
	typename Dim<D>::Vec o = Dim<D>::Vec::Zero();
	typename Dim<D>::IVec n = Dim<D>::IVec::Constant(10);
	n[D - 1] = 61; // 8 block layers, the last one partly filled
	Grid<D> g(o, 0.1, n);
	CHECK(SlabLayout<D>::layers(g) == 8, "layers = %d", SlabLayout<D>::layers(g));
	auto s = SlabLayout<D>::balanced({ 5, 1, 1, 9, 2, 2, 7, 3 }, 3);
	std::vector<std::set<int>> R;
	for (int r = 0; r < 3; ++r) {
		R.push_back(reached(s, r, n[D - 1]));
		int lo, hi;
		s.reachedLayers(g, r, lo, hi);
		CHECK(*R[r].begin() >= lo && *R[r].rbegin() <= hi, "rank %d reaches [%d, %d] outside [%d, %d]", r, *R[r].begin(), *R[r].rbegin(), lo, hi);
	}
	// every layer two ranks reach lies in their shared band; ranks two apart share nothing
	for (int r = 1; r < 3; ++r) {
		int lo, hi;
		s.sharedLayers(g, r, lo, hi);
		for (int k : R[r])
			if (R[r - 1].count(k)) CHECK(k >= lo && k <= hi, "layer %d reached by ranks %d and %d is outside the shared band [%d, %d]", k, r - 1, r, lo, hi);
	}
	for (int k : R[0]) CHECK(!R[2].count(k), "layer %d reached by ranks 0 and 2", k);
	// layer of a coordinate: the block layer, clamped like BlockSchedule::blockOf
	CHECK(SlabLayout<D>::layerOf(g, 0.79) == 0 && SlabLayout<D>::layerOf(g, 0.81) == 1 && SlabLayout<D>::layerOf(g, 6.09) == 7, "layerOf");
}

int main()
{
	balance<2>(), balance<3>();
	reach<2>(), reach<3>();
	std::printf("%s (%d failures)\n", failures ? "FAILED" : "OK", failures);
	return failures ? 1 : 0;
}
