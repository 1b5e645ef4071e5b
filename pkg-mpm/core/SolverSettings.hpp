// The solver settings and the user-writable solver state, each declared once (columns: ParamTable.hpp).
// Solver<D> expands these lists into its plain fields with MPM_PARAMS; the binding generates the checked
// Python properties (unit and range in the docstring) and Solver.settings()/setSettings() from them.
#pragma once
#include "ParamTable.hpp"

namespace mpm {
// What happens to a particle that leaves the grid (the position update takes it past the grid's edge; crossing a
// boundary plane is always an error). doc/algorithm.md, "Material that leaves the grid".
enum class OutsidePolicy : int {
	Stop         = 0, // stop the run with a SimulationError naming the particle, the face and the position
	Remove       = 1, // remove every particle that leaves; its mass, momentum and kinetic energy go to the removed account
	RemoveDebris = 2  // remove debris (damage D = 1, or detached from the body: not in the largest connected
	                  // cluster of intact material); stop when intact material of the body reaches the edge
};
MPM_CHOICES(OutsidePolicy, "stop|remove|remove-debris")
// How G2P updates the particle velocity (doc/reference/algorithm.md, "The particle velocity update and C").
enum class VelocityUpdate : int {
	Pic  = 0, // Eq. 6 as printed: v_p ← Σ ψ_i v_i (the paper's; loses a share of the sub-grid motion every step)
	Flip = 1  // default: v_p ← v_p + Σ ψ_i (v_i − v_i^old), positions moved with Σ ψ_i v_i (as the reference code Graphyt);
	          // a damped step (damping > 0) takes Eq. 6: Cundall damping acts on nodal forces, FLIP's sub-grid part is off the grid
};
MPM_CHOICES(VelocityUpdate, "pic|flip")
} // namespace mpm

// X(type, name, default, unit, lo, hi, ends, symbol, doc, equation, gate); Vec = Dim<D>::Vec (per component)
#define MPM_SOLVER_SETTINGS(X)                                                                                                    \
	X(Vec, gravity, 0, "m/s²", -INFINITY, INFINITY, OO, "g", "gravitational acceleration", "Eq. 22", "")                        \
	X(Real, damping, 0, "-", 0, 1, CO, "α", "Cundall local damping of the nodal forces, f ← f − α|f|sign(v)", "", "")           \
	X(Real, courant, 1.0, "-", 0, 1, OC, "C", "Courant number of the automatic step Δt = C·l/(v_c + max‖v‖)", "Sec. 2.5", "")    \
	X(bool, autoDt, true, "-", 0, 1, CC, "", "recompute Δt every step from the stability condition (else fixedDt)", "", "")     \
	X(Real, fixedDt, 0, "s", 0, INFINITY, CO, "Δt", "time step used when autoDt is off (0 = not set; must be > 0 then)", "", "") \
	X(Real, tractionRampTime, 0, "s", 0, INFINITY, CO, "", "particle surface forces ramp linearly from 0 over this time; 0 = at once", \
	  "Eq. 22", "")                                                                                                              \
	X(int, sortPeriod, 50, "steps", 1, 1e9, CC, "", "re-sort particles by block at least every this many steps", "", "")        \
	X(Real, mpiRebalance, 1.1, "-", 1, INFINITY, CC, "", "MPI only: at each re-sort, cut the slabs again when the busiest rank holds more " \
	  "than this × the mean particle count (inf = never; doc/scaling.md)", "", "")                                             \
	X(VelocityUpdate, velocityUpdate, VelocityUpdate::Flip, "-", 0, 1, CC, "", "particle velocity in G2P: 'flip' (default, "   \
	  "v_p += Σ ψ_i Δv_i, as the reference code Graphyt: no loss per step, so results after cracking hardly depend on C) " \
	  "or 'pic' (Eq. 6 as printed, the paper's: v_p = Σ ψ_i v_i loses a share of the sub-grid motion every step, so "       \
	  "results after cracking depend on C); positions move with Σ ψ_i v_i either way; a step with damping > 0 takes Eq. 6 " \
	  "under both (nodal damping cannot reach the sub-grid part FLIP keeps)", "Eq. 6", "")                                  \
	X(bool, trackEnergy, false, "-", 0, 1, CC, "", "accumulate the external work (one extra pass per step)", "", "")             \
	X(OutsidePolicy, outside, OutsidePolicy::RemoveDebris, "-", 0, 2, CC, "", "particles that leave the grid: 'stop' the run, "  \
	  "'remove' them, or 'remove-debris' (D = 1 or detached material removed, the body reaching the edge stops the run); "   \
	  "removed particles are accounted in yade_mpm.removed(solver)", "", "")

#define MPM_SOLVER_PARAMS(X) MPM_SOLVER_SETTINGS(X) MPM_SOLVER_STATE(X)

// State a script may set (resume, restart): checked like the settings, not part of settings().
#define MPM_SOLVER_STATE(X)                                                                                          \
	X(Real, time, 0, "s", 0, INFINITY, CO, "t", "simulated time (ramped tractions are evaluated at it)", "", "")   \
	X(long, steps, 0, "steps", 0, 9.2e18, CC, "", "steps taken (the sort period counts from it)", "", "")          \
	X(Real, externalWork, 0, "J", -INFINITY, INFINITY, OO, "W_ext", "work of gravity and surface forces (trackEnergy)", "", "")
