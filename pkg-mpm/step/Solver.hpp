// Explicit WLS-MPM with MUSL (paper Sec. 2.5, Fig. 2). The solver owns the state (grid, particles, block schedule,
// contact phase, clock), checks what a step reads and runs it; the step itself, phase by phase, is MuslStep.hpp.
#pragma once
#include "../core/Exchange.hpp"
#include "../core/SolverSettings.hpp"
#include "../material/MaterialSet.hpp"
#include "MuslStep.hpp"
#include "Removal.hpp"
#include <omp.h>

// The MPI build (module yade_mpm._core_mpi, -DMPM_MPI; doc/scaling.md) runs the step with the exchange policy of
// the solver's decomposition (mpi/); MPM_IF_MPI(…) marks its few other lines and expands to nothing in the serial
// module, which is compiled without any MPI code.
#ifdef MPM_MPI
#include "../mpi/MpiExchange.hpp"
#define MPM_IF_MPI(...) __VA_ARGS__
namespace mpm {
template <int D>
using StepExchange = MpiExchange<D>;
}
#else
#define MPM_IF_MPI(...)
namespace mpm {
template <int D>
using StepExchange = LocalExchange;
}
#endif

namespace mpm {

// Wall time per phase [s], summed over steps (for the benchmark); stress includes moveParticles.
struct PhaseTimes {
	double sort = 0, p2g = 0, grid = 0, contact = 0, g2p = 0, stress = 0;
};

template <int D>
class Solver {
public:
	using Vec  = typename Dim<D>::Vec;
	using IVec = typename Dim<D>::IVec;

	// ---- settings (gravity, damping, courant, autoDt, fixedDt, …) and writable state (time, externalWork),
	// declared once in SolverSettings.hpp; the binding checks every value written from Python ----
	MPM_PARAMS(Solver, NoParams, MPM_SOLVER_PARAMS)

	// ---- state ----
	Grid<D>         grid;
	Particles<D>    P;
	PtsContact<D>   contact;
	Real            lastDt = 0; // Δt of the last step [s]
	PhaseTimes      phase;
	MPM_IF_MPI(Decomposition<D> dd;) // MPI build only: slabs, migration, shared-node sums (Decomposition.hpp)

	// Arrays handed out without copy (NumPy views, binding layer): appending must not move them, and P2G
	// checks what they may have changed (reach, mass, volume) while one is alive or was taken since the step.
	size_t liveViews = 0;
	void   viewOpened() { ++liveViews, viewTaken = true; }
	void   viewClosed() { --liveViews; }

	// layerLo, layerHi: the grid's node arrays hold these stored layers along the last axis (Grid::init; default all)
	Solver(const Vec& origin, Real spacing, const IVec& cells, int layerLo = 0, int layerHi = INT_MAX)
	    : grid(origin, spacing, cells, layerLo, layerHi), xfer(grid, P, sched)
	{
		materials.setCell(grid.spacing);
		MPM_IF_MPI(exchange.dd = &dd;) // MPI: the step's shared-node sums and the contact's reductions over the ranks
	}
	Solver(const Solver&)            = delete; // xfer refers to the members
	Solver& operator=(const Solver&) = delete;

	// ---------------------------------------------------------------- set-up
	// Particles of material index `material` (addMaterial's return value; 0 = the material of setMaterial).
	void addParticles(const Real* x, const Real* vol, const Real* mass, size_t n, long material = 0)
	{
		materials.checkIndex(material);
		MPM_IF_MPI(dd.refuseAfterSplit("addParticles");) // every rank would add them: duplicates
		if (liveViews && !P.fits(n))
			throw InputError("addParticles: " + std::to_string(liveViews) + " NumPy view(s) of the particle arrays are alive and adding " + std::to_string(n)
			                 + " particles would move the arrays they point to; delete the views first (del v), or call reserve(total particles) before taking them");
		const size_t old = P.n;
		if (materials.size() && materials[size_t(material)].kind == MaterialKind::DruckerPragerGradyKipp)
			materials[size_t(material)].dpgk.checkThresholds(vol, n, grid.spacing, D); // ε_D⁰ ∈ (0, 1) before anything is added
		MPM_IF_MPI(if (dd.building) { if (!dd.appendOwn(grid, P, x, vol, mass, n, uint8_t(material))) return; } else) // only this rank's slab
		P.append(x, vol, mass, n, grid.origin, grid.upper(), uint8_t(material));
		if (materials.anyDpgk()) {
			P.ensureDamageState(); // ε̄p is needed by the DP return even with damage off
			materials.initDamageThresholds(P, old);
		}
		needSort = needCheck = true;
	}
	// Capacity for `total` particles: later addParticles up to that count keep the arrays (and live views) in place.
	void reserve(size_t total) { P.reserve(total); }
	// Simulated clock and energy account, e.g. for a resumed run: refused unless finite, time and steps ≥ 0.
	void setClock(long nSteps, Real t, Real work)
	{
		if (nSteps < 0) throw InputError("steps = " + std::to_string(nSteps) + " is outside the allowed range [0, inf)");
		requireRange(t, 0, INFINITY, false, true, "time", "[s]");
		requireFinite(work, "externalWork [J]");
		steps = nSteps, time = t, externalWork = work;
	}
	// A further material for particles added with addParticles(…, material = index); returns the index.
	template <class Mat>
	size_t addMaterial(const Mat& m)
	{
		const size_t i = materials.add(m);
		if (materials.anyDpgk() && P.n) P.ensureDamageState(), materials.initDamageThresholds(P, 0);
		needCheck = true; // the time step's density measure depends on the material set
		return i;
	}
	// One-material scenes (older scripts): sets material 0, or replaces it and recomputes every particle's
	// damage threshold. A scene with several materials refuses (it would silently change other regions).
	template <class Mat>
	void setMaterial(const Mat& m)
	{
		if (materials.size() == 0) return void(addMaterial(m));
		materials.replaceOnly(m, P);
		needCheck = true;
	}
	// Particle slots `slots` take material index `material` with that material's damage threshold ε_D⁰.
	void setParticleMaterial(const std::vector<size_t>& slots, long material)
	{
		materials.assign(P, slots, material);
		needCheck = true; // ρ/M of a mixed scene's time step depends on the particle's material
	}
	const MaterialSet<D>& materialSet() const { return materials; }
	MaterialKind          materialKind() const { return materials.size() ? materials[0].kind : MaterialKind::None; } // of material 0

	void addBoundaryPlane(int axis, int side, Real position, BoundaryKind k)
	{
		grid.addPlane({ axis, side, position, k });
		needCheck = true; // particles must lie on the material side of every plane
	}

	// Surface force on particle slot p (traction × tributary area) [N].
	void setParticleForce(size_t p, const Vec& f)
	{
		if (p >= P.n) throw InputError("particle index " + std::to_string(p) + " is outside [0, " + std::to_string(P.n) + ")");
		for (int a = 0; a < D; ++a) requireFinite(f[a], "particle surface force");
		P.ensureTraction();
		for (int a = 0; a < D; ++a) P.trac[a][p] = f[a];
	}

	// ---------------------------------------------------------------- time step
	// Characteristic P-wave speed v_c = max over materials of √((K + 4G/3)/ρ_min) [m/s].
	Real waveSpeed() { return prepare(), materials.waveSpeed(dtDensityMin); }
	// Paper's stability condition Δt = C·l/(v_c + max‖v‖) with the current particle velocities.
	Real stableDt() { return prepare(), courant * grid.spacing / (waveSpeed() + vmax); }
	// One step with the automatic Δt (autoDt) or fixedDt.
	void step()
	{
		prepare();
		if (!autoDt && !(fixedDt > 0)) throw InputError("fixedDt = 0 s is not set: set fixedDt > 0 s or autoDt = True");
		advance(autoDt ? stableDt() : fixedDt);
	}
	// One step of length dt (paper Fig. 2); dt above the stable step is refused.
	void advance(Real dt)
	{
		if (!failure.empty())
			throw SimulationError("cannot step: the last step failed after it had partly updated the particles (" + failure
			                      + "); restore a checkpoint (yade_mpm.checkpoint) or rebuild the scene");
		prepare();
		requireRange(dt, 0, INFINITY, true, true, "dt", "[s]");
		const Real lim = stableDt();
		if (dt > lim * (1 + 1e-12))
			throw InputError("dt = " + fmtNum(dt) + " s exceeds the stable time step " + fmtNum(lim) + " s (Δt ≤ C·l/(v_c + max‖v‖), C = "
			                 + fmtNum(courant) + "); lower dt or switch autoDt on");
		MPM_IF_MPI(dd.checkStep(liveViews);)
		double t0 = omp_get_wtime();
		if (needSort || (steps % sortPeriod) == 0 MPM_IF_MPI(|| dd.needsSplit())) {
			MPM_IF_MPI(dd.migrate(grid, P, mpiRebalance);) // re-balance; particles that left the rank's slab go to its owner
			sched.sort(grid, P), needSort = false;
		}
		errP2G.clear(), errContact.clear(), errG2P.clear();
		const ContactStep<D, StepExchange<D>> cs { grid, P, sched, xfer.offs, dt, massFloor, errContact, exchange };
		const StepInputs<D> in { dt, loadScale(time), damping, massFloor, gravity, contact.active(), grid.hasMirrors(),
			                     liveViews > 0 || viewTaken,                 // viewWrites: P2G checks what views may have changed
			                     velocityUpdate == VelocityUpdate::Flip && damping == 0 }; // a damped step: Eq. 6 (SolverSettings)
		if (in.flip)
			for (auto& c : xfer.vg) c.resize(P.n); // grows only with the particle count
		if (in.withContact) contact.beforeTransfer(cs);
		xfer.cuts.beginStep(sched.start.size() - 1, omp_get_max_threads()); // the cut-stencil fits P2G keeps for this step
		double t[6] = { omp_get_wtime() };
		materials.dispatch([&](const auto& mat) {
			gridPhases(xfer, contact, cs, mat, in, errP2G, errG2P, t); // MuslStep.hpp: phases 1–5
			throwIf(errP2G, "P2G", false), throwIf(errContact, "contact", false); // particles untouched so far
			viewTaken = false;                                                       // P2G accepted the state
			throwIf(errG2P, "G2P", true);
			ErrorRecord errStress, errMove;
			auto        st = particlePhases(xfer, mat, dt, in.flip, errStress, errMove); // phases 6–7
			MPM_IF_MPI(dd.reduceStep(st.dtDensityMin, st.v2max, st.drift, errStress, errMove);) // global Δt limits, re-sort flag
			throwIf(errStress, "stress update", true), throwIf(errMove, "position update", true);
			if (errMove.leftAnywhere) settleLeaving(errMove, dt); // a particle left the grid (on some rank): outside policy
			vmax = std::sqrt(st.v2max), dtDensityMin = st.dtDensityMin;
			if (st.drift) needSort = true; // a particle left its block's reach: re-sort before the next scatter
			xfer.cuts.endStep();           // room for the cut-stencil fits this step could not keep
			t[5] = omp_get_wtime();
		});
		phase.sort += t[0] - t0, phase.p2g += t[1] - t[0], phase.grid += t[2] - t[1], phase.contact += t[3] - t[2];
		phase.g2p += t[4] - t[3], phase.stress += t[5] - t[4];
		if (trackEnergy) accumulateExternalWork(dt, in.flip);
		time += dt;
		lastDt = dt;
		++steps;
	}

	// ---------------------------------------------------------------- diagnostics
	Real   kineticEnergy() const { return P.kineticEnergy(); }
	Real   elasticEnergy() const { return materials.elasticEnergy(P); } // stored by the effective stress [J]
	Sym<D> effectiveStress(size_t p) const { return materials.effectiveStress(P, p); } // damaged for DP–GK (Eq. 40)
	Real   cohesion(size_t p) const { return materials.cohesion(P, p); }               // Eq. 34; NaN if not DP–GK
	bool   materialVelocity(size_t p, Real (&v)[D]) const { return xfer.materialVelocity(p, v); } // at x_p (Transfer.hpp)
	Real loadScale(Real t) const { return tractionRampTime > 0 ? std::min(1.0, t / tractionRampTime) : 1.0; }
	Real maxSpeed() // max ‖v‖ [m/s], refreshed after requestSort(); MPI: a collective (every rank calls it)
	{
		if (needCheck && (P.n MPM_IF_MPI(|| dd.decomposed || dd.building)) && materials.size()) prepare(); // a rank without particles joins
		return vmax;
	}
	const BlockSchedule<D>& schedule() const { return sched; }
	// Python calls this after writing particle views: re-sort and re-validate before the next step.
	void requestSort() { needSort = needCheck = true; }

	// ---------------------------------------------------------------- material that left the grid (Removal.hpp)
	// The removed particles in removal order (this rank's, MPI build) and their running account.
	const std::vector<RemovedParticle<D>>& removedParticles() const { return removed; }
	const RemovedAccount<D>&               removedAccount() const { return removedSum; }
	// Checkpoint resume: the saved records (their account recomputed in the same order: the same bits), and
	// the particle arrays cut to the saved count n (the caller then writes the saved particles into them).
	void restoreRemoved(const std::vector<RemovedParticle<D>>& recs, size_t n)
	{
		if (liveViews) throw InputError("checkpoint: delete the NumPy views of the particle arrays first (the particle count changes)");
		if (n > P.n) throw InputError("checkpoint: " + std::to_string(n) + " particles saved, the scene has " + std::to_string(P.n));
		RemovedAccount<D> acc;
		for (const auto& r : recs) {
			if (r.face < 0 || r.face >= 2 * D || !(r.mass > 0) || r.material >= materials.size())
				throw InputError("checkpoint: removed particle id " + std::to_string(r.id) + " has an invalid face, mass or material");
			acc.add(r);
		}
		if (n < P.n) {
			dropScratch.assign(P.n, 0);
			for (size_t p = n; p < P.n; ++p) dropScratch[p] = 1;
			P.compact(dropScratch);
			needSort = needCheck = true;
		}
		removed = recs, removedSum = acc;
	}

	// Checkpoint access (py/yade_mpm/checkpoint.py): with the particle arrays in storage order and the
	// block schedule, these are everything the next step reads, so a resumed run is bitwise identical.
	struct ResumeState {
		long steps;
		Real time, lastDt, externalWork, vmax, dtDensityMin, massFloor;
		bool needSort, needCheck;
	};
	ResumeState resumeState() const { return { steps, time, lastDt, externalWork, vmax, dtDensityMin, massFloor, needSort, needCheck }; }
	void setResumeState(const ResumeState& r, const std::vector<uint32_t>& blockStart)
	{
		const long s0 = steps;
		const Real t0 = time, w0 = externalWork;
		setClock(r.steps, r.time, r.externalWork); // checked before anything else changes
		const bool neverSorted = blockStart.empty() && r.needSort; // saved before the first step
		if (!neverSorted && !sched.restore(grid, blockStart, P.n)) {
			setClock(s0, t0, w0);
			throw InputError("checkpoint: the block schedule does not fit this grid and particle count");
		}
		lastDt = r.lastDt;
		vmax = r.vmax, dtDensityMin = r.dtDensityMin, massFloor = r.massFloor;
		needSort = r.needSort, needCheck = r.needCheck;
		failure.clear();
	}

private:
	MaterialSet<D>   materials;
	BlockSchedule<D> sched;
	Transfer<D>      xfer;               // the transfers, bound to grid, P and sched
	StepExchange<D>  exchange;           // sums and decisions shared with the other processes (core/Exchange.hpp)
	bool             needSort  = true;   // particles must be re-sorted by block before the next transfer
	bool             needCheck = true;   // particle data changed from outside: validate and refresh ρ_min, mass floor
	bool             viewTaken = true;   // a view was handed out since the last accepted P2G
	Real             vmax = 0, massFloor = 0;
	Real             dtDensityMin = INFINITY; // min dtDensity of the particles: ρ (one material) or ρ/M (mixed; MaterialSet.hpp)
	ErrorRecord      errP2G, errContact, errG2P; // shared by the threads of the transfer region
	std::string      failure;                    // message of a step that failed with particles partly updated
	std::vector<RemovedParticle<D>> removed;     // particles taken out after leaving the grid (outside policy)
	RemovedAccount<D>               removedSum;
	BodyClusters<D>                 clusters;    // debris or body (outside = 'remove-debris'), work arrays kept
	std::vector<uint8_t>            dropScratch;

	// End of a step in which particles left the grid (e.left, this rank's; MPI: every rank calls it when any
	// rank has some). outside = 'stop', or a particle of the body under 'remove-debris': the run stops with the
	// message naming the lowest such slot. Otherwise the particles are recorded, added to the account and
	// taken out of the arrays (the block schedule keeps the others' order), and Δt's limits are refreshed.
	void settleLeaving(ErrorRecord& e, Real dt)
	{
		auto& left = e.left;
		std::sort(left.begin(), left.end()); // the threads filled it in any order
		std::vector<int> reason(left.size(), 0);
		size_t           stopAt = SIZE_MAX;
		if (outside == OutsidePolicy::Stop) {
			if (!left.empty()) stopAt = left[0];
		} else if (outside == OutsidePolicy::RemoveDebris) {
			bool needBody = false; // is any leaving particle intact (D < 1)? then the clusters decide
			for (size_t k = 0; k < left.size(); ++k) {
				reason[k] = BodyClusters<D>::intact(P, left[k]) ? 2 : 1;
				needBody  = needBody || reason[k] == 2;
			}
#ifdef MPM_MPI
			needBody = !Comm::all(!needBody); // every rank builds the map if one rank needs it (a collective)
#endif
			if (needBody) {
				clusters.mark(grid, P);
				MPM_IF_MPI(if (dd.distributed()) Comm::maxBytes(clusters.occupied.data(), clusters.occupied.size());)
				clusters.labelClusters(grid);
				for (size_t k = 0; k < left.size() && stopAt == SIZE_MAX; ++k)
					if (reason[k] == 2 && !clusters.detached(grid, P, left[k])) stopAt = left[k];
			}
		}
		bool stop = stopAt != SIZE_MAX;
#ifdef MPM_MPI
		if (!Comm::all(!stop) && !stop)
			e.record(ErrorRecord::elsewhere, "stopped: a particle of the body left the grid on another MPI rank (its message names the particle)"), stop = true;
#endif
		if (stop) {
			if (stopAt != SIZE_MAX) {
				std::string hint = outside == OutsidePolicy::Stop
				                           ? " (outside = 'stop')"
				                           : "; it is intact material of the body (D < 1, in the largest connected cluster of intact material), so the grid "
				                             "is too small for the body: enlarge the grid, or set outside = 'remove' to remove any particle that leaves";
				e.record(stopAt, leftGridMessage(P, grid, stopAt) + hint);
			}
			throwIf(e, "position update", true);
		}
		dropScratch.assign(P.n, 0);
		for (size_t k = 0; k < left.size(); ++k) {
			const size_t       p = left[k];
			RemovedParticle<D> r {};
			r.id = P.id[p], r.step = steps + 1, r.time = time + dt;
			for (int a = 0; a < D; ++a) r.x[a] = P.x[a][p], r.v[a] = P.v[a][p];
			r.mass = P.mass[p], r.damage = P.hasDamageState() ? P.damage[p] : 0.0;
			r.face = exitFace(P, grid, p), r.material = P.mat[p], r.reason = reason[k];
			removed.push_back(r), removedSum.add(r);
			dropScratch[p] = 1;
		}
		if (!left.empty()) P.compact(dropScratch), sched.dropSlots(dropScratch);
		needCheck = true; // ρ_min, max ‖v‖ and the mass floor of the particles left (prepare; MPI: every rank takes part)
	}

	// After a failure in a phase that had already changed particles (partly), the state is not one of
	// the scheme's states: further steps are refused until a checkpoint is restored (setResumeState).
	void throwIf(const ErrorRecord& e, const char* phaseName, bool particlesChanged)
	{
		if (e.none()) return;
		const std::string who  = e.particle < P.n ? "particle id " + std::to_string(P.id[e.particle]) + " " : "";
		const std::string what = "MPM stopped at step " + std::to_string(steps) + " (t = " + fmtNum(time) + " s) in " + phaseName + ": " + who + e.what;
		if (particlesChanged) failure = what;
		throw SimulationError(what);
	}

	// Validation that must precede any work; cheap when nothing changed.
	void prepare()
	{
		if (P.n == 0 MPM_IF_MPI(&&!dd.decomposed && !dd.building)) throw InputError("particles: no particles in the solver; add particles before stepping");
		if (materials.size() == 0) throw InputError("material: no material assigned; set a material before stepping");
		if (!std::isfinite(dtDensityMin) || needCheck) {
			// State edited through the live views (requestSort() after editing) is validated like
			// addParticles input: a NaN or off-grid position would index outside the node arrays.
			auto validate = [&] {
				const auto c = P.check(grid.allowedLo, grid.allowedHi, materials.size()); // the grid cut by the boundary planes
				P.checkDamageState([&](size_t p) { // ε_D⁰ is checked where the particle's material has damage on
					const auto& e = materials.of(P, p);
					return e.kind == MaterialKind::DruckerPragerGradyKipp && e.dpgk.damage;
				});
				dtDensityMin = materials.single() ? c.rhoMin : materials.minDtDensity(P);
				vmax      = c.vmax; // also lowered when velocities were lowered through the views
				massFloor = 1e-14 * c.massMin; // nodes lighter than this carry no velocity (only roundoff-level mass)
			};
#ifdef MPM_MPI
			dd.agree(validate), dd.reduceLimits(dtDensityMin, vmax, massFloor); // every rank stops if one fails; global limits
#else
			validate();
#endif
			needCheck = false;
		}
	}

	void accumulateExternalWork(Real dt, bool flip)
	{
		Real w = P.externalWork(gravity, loadScale(time + dt), dt, flip ? xfer.vg : P.v); // along the velocity the particles moved with
		MPM_IF_MPI(w = dd.sum(w);) // MPI: the work on every rank's particles
		externalWork += w;
	}
};

} // namespace mpm
