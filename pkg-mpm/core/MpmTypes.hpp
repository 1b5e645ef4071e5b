// Basic types shared by every piece of the MPM core.
// Dimension D is a template parameter everywhere: 2 = plane strain (σzz tracked), 3 = full 3D.
#pragma once
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace mpm {

using Real = double;

template <int D>
struct Dim {
	static_assert(D == 2 || D == 3, "MPM is implemented for 2D plane strain and 3D only");
	// Symmetric stress/strain components stored: xx, yy, zz, xy [, xz, yz].
	// In plane strain σzz is a genuine state (ε_zz = 0, σzz ≠ 0); xz, yz vanish and are not stored.
	static constexpr int nSym     = D == 2 ? 4 : 6;
	static constexpr int nStencil = D == 2 ? 16 : 64; // cubic B-spline: 4 nodes per axis
	static constexpr int nColours = 1 << D;
	using Vec  = Eigen::Matrix<Real, D, 1>;
	using Mat  = Eigen::Matrix<Real, D, D>;
	using IVec = Eigen::Matrix<int, D, 1>;
};

// Thrown for invalid user input; the binding layer turns it into Python's ValueError.
struct InputError : std::invalid_argument {
	using std::invalid_argument::invalid_argument;
};
// Thrown when a running simulation cannot continue (non-finite state, particle left the grid).
struct SimulationError : std::runtime_error {
	using std::runtime_error::runtime_error;
};

// First failure of a parallel particle pass. The lowest particle slot wins, so the message is the same
// for any thread count; threads record and go on, the caller throws after the pass (SimulationError).
struct ErrorRecord {
	static constexpr size_t elsewhere = SIZE_MAX - 1; // MPI build: the phase failed on another rank
	size_t      particle = SIZE_MAX;
	std::string what;
	// Position update: particles that left the grid (not a failure yet: the solver's outside policy decides,
	// Solver::settleLeaving); filled in any order by the threads, only on the rare steps where one leaves.
	std::vector<size_t> left;
	bool                leftAnywhere = false; // MPI build: some rank has particles in `left` (reduceStep)
	void        clear() { particle = SIZE_MAX, what.clear(), left.clear(), leftAnywhere = false; }
	bool        none() const { return particle == SIZE_MAX; }
	void        record(size_t p, const std::string& w)
	{
#pragma omp critical(mpm_error)
		if (p < particle) particle = p, what = w;
	}
	void recordLeft(size_t p)
	{
#pragma omp critical(mpm_error)
		left.push_back(p), leftAnywhere = true;
	}
};

// A number for messages (6 significant digits).
inline std::string fmtNum(Real v)
{
	std::ostringstream o;
	o.precision(6);
	o << v;
	return o.str();
}

inline void requireFinite(Real v, const char* name)
{
	if (!std::isfinite(v)) throw InputError(std::string(name) + " must be a finite number (got " + std::to_string(v) + ")");
}
inline void requireRange(Real v, Real lo, Real hi, bool loOpen, bool hiOpen, const char* name, const char* unit)
{
	requireFinite(v, name);
	bool ok = (loOpen ? v > lo : v >= lo) && (hiOpen ? v < hi : v <= hi);
	if (!ok) {
		auto num = [](Real x) {
			if (std::isinf(x)) return std::string(x > 0 ? "inf" : "-inf");
			char b[32];
			snprintf(b, sizeof(b), "%g", x);
			return std::string(b);
		};
		throw InputError(
		        std::string(name) + " = " + num(v) + " " + unit + " is outside the allowed range " + (loOpen ? "(" : "[") + num(lo) + ", " + num(hi)
		        + (hiOpen ? ")" : "]"));
	}
}

} // namespace mpm
