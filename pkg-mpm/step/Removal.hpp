// Material that leaves the grid (Solver.outside, SolverSettings.hpp; doc/algorithm.md "Material that leaves
// the grid"): the record of each removed particle, the running account of what was removed, and the test
// that tells debris from the body (BodyClusters). Everything here runs only on the rare steps where a
// particle left the grid; a step where none leaves pays one check of an empty list.
#pragma once
#include "../core/Grid.hpp"
#include "../core/Particles.hpp"
#include <algorithm>
#include <vector>

namespace mpm {

// A particle taken out of the computation: its state at the end of the step in which it left the grid.
template <int D>
struct RemovedParticle {
	int64_t id;       // stable particle id
	long    step;     // steps taken when it was removed (the step in which it left is step − 1 … step)
	Real    time;     // simulated time at the end of that step [s]
	Real    x[D];     // position, past the grid's edge [m]
	Real    v[D];     // velocity v_p (its momentum is m v_p, the grid's share) [m/s]
	Real    mass;     // [kg] (per metre of thickness in 2D)
	Real    damage;   // Grady–Kipp D (0 without damage state)
	int     face;     // grid face it left through: 2·axis + (1: upper end)
	uint8_t material; // material index
	int     reason;   // 0: outside = 'remove', 1: fully damaged (D = 1), 2: detached from the body
};

// Running sums over the removed particles, in removal order (a resumed run recomputes them from the records
// in the same order: the same bits).
template <int D>
struct RemovedAccount {
	long count = 0;
	Real mass = 0, momentum[D] = {}, kinetic = 0; // Σ m, Σ m v, Σ ½ m v² of the removed particles [kg, kg·m/s, J]
	Real lastTime = -1;                           // time of the last removal [s] (−1: none)
	long lastStep = -1;
	long faces[2 * D] = {}; // removed particles per grid face (x−, x+, y−, y+[, z−, z+])
	void add(const RemovedParticle<D>& r)
	{
		++count, mass += r.mass;
		Real v2 = 0;
		for (int a = 0; a < D; ++a) momentum[a] += r.mass * r.v[a], v2 += r.v[a] * r.v[a];
		kinetic += 0.5 * r.mass * v2;
		lastTime = r.time, lastStep = r.step;
		if (r.face >= 0 && r.face < 2 * D) ++faces[r.face];
	}
};

// The body and its debris: connected clusters of the grid cells that hold intact material (a particle with
// D < 1; 3^D-neighbourhood, particles past the edge counted in the edge cell they crossed). The body is the
// cluster with the most cells (ties: the one met first in cell order); a particle in another cluster is
// detached. The work vectors are kept: repeated removals allocate nothing once they have grown.
template <int D>
struct BodyClusters {
	std::vector<uint8_t> occupied; // per cell: 1 = holds intact material
	std::vector<int32_t> label;    // per cell: cluster number (−1: empty)
	std::vector<size_t>  stack;
	std::vector<long>    size;
	int32_t              body = -1;

	size_t cellOf(const Grid<D>& g, const Particles<D>& P, size_t p) const
	{
		size_t c = 0, s = 1;
		for (int a = 0; a < D; ++a) {
			const Real f = (P.x[a][p] - g.origin[a]) / g.spacing;
			int        i = std::isfinite(f) ? int(std::max(-1.0, std::min(f, Real(g.cells[a])))) : 0;
			i            = std::min(std::max(i, 0), g.cells[a] - 1);
			c += size_t(i) * s;
			s *= size_t(g.cells[a]);
		}
		return c;
	}
	static bool intact(const Particles<D>& P, size_t p) { return !P.hasDamageState() || P.damage[p] < 1; }
	// Cells of this process's intact particles; the MPI build then takes the max over the ranks (label()).
	void mark(const Grid<D>& g, const Particles<D>& P)
	{
		size_t n = 1;
		for (int a = 0; a < D; ++a) n *= size_t(g.cells[a]);
		occupied.assign(n, 0);
		for (size_t p = 0; p < P.n; ++p)
			if (intact(P, p)) occupied[cellOf(g, P, p)] = 1;
	}
	// Labels the clusters of `occupied` and picks the body.
	void labelClusters(const Grid<D>& g)
	{
		const size_t n = occupied.size();
		label.assign(n, -1), size.clear(), body = -1;
		for (size_t c0 = 0; c0 < n; ++c0) {
			if (!occupied[c0] || label[c0] >= 0) continue;
			const int32_t k = int32_t(size.size());
			long          cnt = 0;
			stack.clear(), stack.push_back(c0), label[c0] = k;
			while (!stack.empty()) {
				const size_t c = stack.back();
				stack.pop_back(), ++cnt;
				int    ic[D];
				size_t r = c;
				for (int a = 0; a < D; ++a) ic[a] = int(r % size_t(g.cells[a])), r /= size_t(g.cells[a]);
				for (int nb = 0; nb < (D == 2 ? 9 : 27); ++nb) {
					int    q = nb;
					size_t cn = 0, s = 1;
					bool   ok = true;
					for (int a = 0; a < D; ++a) {
						const int j = ic[a] + q % 3 - 1;
						q /= 3;
						ok = ok && j >= 0 && j < g.cells[a];
						cn += size_t(j) * s, s *= size_t(g.cells[a]);
					}
					if (ok && occupied[cn] && label[cn] < 0) label[cn] = k, stack.push_back(cn);
				}
			}
			size.push_back(cnt);
			if (body < 0 || cnt > size[size_t(body)]) body = k;
		}
	}
	bool detached(const Grid<D>& g, const Particles<D>& P, size_t p) const { return label[cellOf(g, P, p)] != body; }
};

} // namespace mpm
