// Explicit WLS-MPM with MUSL (paper Sec. 2.5, Fig. 2). One step, in the order of the flow chart:
//
//   p2g();         lumped mass, momentum, internal/external force      Eqs. 20–22
//   gridUpdate();  nodal momentum balance with lumped mass, boundaries  Eq. 18
//   (contact();    PTS contact with rigid bodies joins here, Eqs. 23–26)
//   g2p();         particle velocity, position rate; MUSL remap         Eqs. 6–7, 16–17
//   gridMusl();    nodal MUSL velocities                                Eq. 16
//   updateStress(); velocity gradient and constitutive update           Eqs. 7, 27–40
#pragma once
#include "BlockSchedule.hpp"
#include "DruckerPragerGradyKipp.hpp"
#include "WlsShape.hpp"
#include <omp.h>
#include <sstream>

namespace mpm {

enum class MaterialKind : int { None = -1, Elastic = 0, DruckerPragerGradyKipp = 1 };

// Wall time per phase [s], summed over steps (for the benchmark).
struct PhaseTimes {
	double sort = 0, p2g = 0, grid = 0, g2p = 0, stress = 0;
};

template <int D>
class Solver {
public:
	using Vec  = typename Dim<D>::Vec;
	using IVec = typename Dim<D>::IVec;
	static constexpr int N  = Dim<D>::nStencil;
	static constexpr int NS = Dim<D>::nSym;

	// ---- settings (each validated where it is set) ----
	Vec  gravity          = Vec::Zero(); // g [m/s²]
	Real damping          = 0;   // Cundall local damping α on nodal forces: f ← f − α|f|sign(v) [-], 0 ≤ α < 1
	Real courant          = 0.5; // C in Δt = C·l/(v_c + max‖v‖) [-], 0 < C ≤ 1
	bool autoDt           = true; // recompute Δt every step from the stability condition
	Real fixedDt          = 0;   // Δt used when autoDt is false [s]
	Real tractionRampTime = 0;   // particle surface forces ramp linearly from 0 over this time [s]; 0 = at once
	int  sortPeriod       = 50;  // re-sort particles by block at least every this many steps
	bool trackEnergy      = false; // accumulate external work (costs one extra pass)

	// ---- state ----
	Grid<D>      grid;
	Particles<D> P;
	Real         time = 0;   // simulated time [s]
	long         steps = 0;
	Real         lastDt = 0; // Δt of the last step [s]
	Real         externalWork = 0; // work of gravity and surface forces on the particles [J] (trackEnergy)
	PhaseTimes   phase;

	Solver(const Vec& origin, Real spacing, const IVec& cells) : grid(origin, spacing, cells), offs(grid) { }

	// ---------------------------------------------------------------- set-up
	void addParticles(const Real* x, const Real* vol, const Real* mass, size_t n)
	{
		if (n == 0) throw InputError("particles: the particle set to add is empty");
		const Vec lo = grid.origin, hi = grid.upper();
		for (size_t p = 0; p < n; ++p) {
			for (int a = 0; a < D; ++a) {
				Real xa = x[p * D + a];
				if (!std::isfinite(xa)) throw InputError("position of particle " + std::to_string(P.n + p) + " is not finite (NaN or inf)");
				if (xa < lo[a] || xa >= hi[a])
					throw InputError(
					        "position of particle " + std::to_string(P.n + p) + " is outside the grid along axis " + std::to_string(a) + ": "
					        + std::to_string(xa) + " m not in [" + std::to_string(lo[a]) + ", " + std::to_string(hi[a]) + ") m");
			}
			if (!(std::isfinite(vol[p]) && vol[p] > 0))
				throw InputError("volume of particle " + std::to_string(P.n + p) + " must be finite and > 0 m³ (got " + std::to_string(vol[p]) + ")");
			if (!(std::isfinite(mass[p]) && mass[p] > 0))
				throw InputError("mass of particle " + std::to_string(P.n + p) + " must be finite and > 0 kg (got " + std::to_string(mass[p]) + ")");
		}
		const size_t old = P.n;
		P.n += n;
		P.forEachRealField([&](std::vector<Real>& f) { f.resize(P.n, 0.0); });
		P.id.resize(P.n);
		for (size_t p = 0; p < n; ++p) {
			for (int a = 0; a < D; ++a) P.x[a][old + p] = x[p * D + a];
			P.vol[old + p] = P.vol0[old + p] = vol[p];
			P.mass[old + p]                  = mass[p];
			P.id[old + p]                    = int64_t(old + p);
		}
		if (kind == MaterialKind::DruckerPragerGradyKipp) {
			P.ensureDamageState(); // ε̄p is needed by the DP return even with damage off (was left unallocated → segfault)
			initDamageThresholds(old);
		}
		needSort = needCheck = true;
	}

	void setMaterial(const ElasticMat& m)
	{
		m.validate();
		elastic = m;
		kind    = MaterialKind::Elastic;
	}
	void setMaterial(const DpGkMat& m)
	{
		m.validate();
		dpgk    = m;
		elastic = m;
		kind    = MaterialKind::DruckerPragerGradyKipp;
		P.ensureDamageState();
		initDamageThresholds(0);
	}
	MaterialKind materialKind() const { return kind; }
	const ElasticMat& elasticParameters() const { return elastic; }
	const DpGkMat& dpgkParameters() const { return dpgk; }

	void addBoundaryPlane(int axis, int side, Real position, BoundaryKind k) { grid.addPlane({ axis, side, position, k }); }

	// Surface force on particle slot p (traction × tributary area) [N].
	void setParticleForce(size_t p, const Vec& f)
	{
		if (p >= P.n) throw InputError("particle index " + std::to_string(p) + " is outside [0, " + std::to_string(P.n) + ")");
		for (int a = 0; a < D; ++a) requireFinite(f[a], "particle surface force");
		P.ensureTraction();
		for (int a = 0; a < D; ++a) P.trac[a][p] = f[a];
	}

	void setSetting(const char* name, Real v)
	{
		std::string n(name);
		if (n == "damping") requireRange(v, 0, 1, false, true, "damping", "[-]"), damping = v;
		else if (n == "courant") requireRange(v, 0, 1, true, false, "courant", "[-]"), courant = v;
		else if (n == "fixedDt") requireRange(v, 0, INFINITY, true, true, "fixedDt", "[s]"), fixedDt = v;
		else if (n == "tractionRampTime") requireRange(v, 0, INFINITY, false, true, "tractionRampTime", "[s]"), tractionRampTime = v;
		else if (n == "sortPeriod") requireRange(v, 1, 1e9, false, false, "sortPeriod", "[steps]"), sortPeriod = int(v);
		else throw InputError("unknown setting " + n);
	}

	// ---------------------------------------------------------------- time step
	// Characteristic P-wave speed v_c = √((K + 4G/3)/ρ_min) [m/s].
	Real waveSpeed() const { return std::sqrt(elastic.pWaveModulus() / rhoMin); }
	// Paper's stability condition Δt = C·l/(v_c + max‖v‖) with the current particle velocities.
	Real stableDt()
	{
		prepare();
		return courant * grid.spacing / (waveSpeed() + vmax);
	}
	// One step with the automatic Δt (autoDt) or fixedDt.
	void step()
	{
		prepare();
		if (autoDt) advance(stableDt());
		else advance(fixedDt);
	}
	// One step of length dt; dt above the stable step is refused.
	void advance(Real dt)
	{
		prepare();
		requireRange(dt, 0, INFINITY, true, true, "dt", "[s]");
		const Real lim = stableDt();
		if (dt > lim * (1 + 1e-12))
			throw InputError(
			        "dt = " + fmt(dt) + " s exceeds the stable time step " + fmt(lim) + " s (Δt ≤ C·l/(v_c + max‖v‖), C = " + fmt(courant)
			        + "); lower dt or switch autoDt on");
		double t0 = omp_get_wtime();
		if (needSort || (steps % sortPeriod) == 0) {
			sched.sort(grid, P);
			needSort = false;
		}
		double t1 = omp_get_wtime();
		phase.sort += t1 - t0;
		withMaterial([&](const auto& mat) {
			// The grid phases run in one parallel region (orphaned worksharing loops inside each phase):
			// a thread team is woken once per step, not once per phase, which matters when other
			// processes share the cores. Every thread takes the same error branch after a barrier.
			double a = omp_get_wtime(), b = a, c = a, d = a;
			errP2G.clear(), errG2P.clear();
#pragma omp parallel
			{
				p2g(mat);
#pragma omp master
				b = omp_get_wtime();
				if (errP2G.none()) {
					gridUpdate(dt);
					// contact(dt): PTS contact with rigid bodies (Eqs. 23–26) is applied to the nodes here.
#pragma omp master
					c = omp_get_wtime();
					g2p();
					if (errG2P.none()) gridMusl();
				}
#pragma omp master
				d = omp_get_wtime();
			}
			throwIf(errP2G, "P2G");
			throwIf(errG2P, "G2P");
			updateStress(mat, dt);
			double e = omp_get_wtime();
			phase.p2g += b - a;
			phase.grid += c - b;
			phase.g2p += d - c;
			phase.stress += e - d;
		});
		if (trackEnergy) accumulateExternalWork(dt);
		time += dt;
		lastDt = dt;
		++steps;
	}

	// ---------------------------------------------------------------- diagnostics
	Real kineticEnergy() const
	{
		Real e = 0;
		for (size_t p = 0; p < P.n; ++p)
			for (int a = 0; a < D; ++a) e += 0.5 * P.mass[p] * P.v[a][p] * P.v[a][p];
		return e;
	}
	// Elastic energy stored by the (effective) stress, Σ V (s:s/(4G) + σm²/(2K)) [J].
	Real elasticEnergy() const
	{
		const Real K = elastic.bulk(), G = elastic.shear();
		Real       e = 0;
		for (size_t p = 0; p < P.n; ++p) {
			Sym<D> s  = effectiveStress(p);
			Real   sm = s.toDeviator();
			e += P.vol[p] * (s.contract() / (4 * G) + sm * sm / (2 * K));
		}
		return e;
	}
	// The stress the particle carries: the damaged stress for DP–GK (Eq. 40), else the state.
	Sym<D> effectiveStress(size_t p) const
	{
		if (kind == MaterialKind::DruckerPragerGradyKipp) return DruckerPragerGradyKipp<D>::damaged(P.stress(p), P.damage[p]);
		return P.stress(p);
	}
	Real loadScale(Real t) const { return tractionRampTime > 0 ? std::min(1.0, t / tractionRampTime) : 1.0; }
	Real maxSpeed() const { return vmax; }
	const BlockSchedule<D>& schedule() const { return sched; }
	// Python calls this after writing particle views: re-sort and re-validate before the next step.
	void requestSort() { needSort = needCheck = true; }

	// Checkpoint access (py/yade_mpm/checkpoint.py): with the particle arrays in storage order and the
	// block schedule, these are everything the next step reads, so a resumed run is bitwise identical.
	struct ResumeState {
		long steps;
		Real time, lastDt, externalWork, vmax, rhoMin, massFloor;
		bool needSort, needCheck;
	};
	ResumeState resumeState() const { return { steps, time, lastDt, externalWork, vmax, rhoMin, massFloor, needSort, needCheck }; }
	void setResumeState(const ResumeState& r, const std::vector<uint32_t>& blockStart)
	{
		const bool neverSorted = blockStart.empty() && r.needSort; // saved before the first step
		if (!neverSorted && !sched.restore(grid, blockStart, P.n)) throw InputError("checkpoint: the block schedule does not fit this grid and particle count");
		steps = r.steps, time = r.time, lastDt = r.lastDt, externalWork = r.externalWork;
		vmax = r.vmax, rhoMin = r.rhoMin, massFloor = r.massFloor;
		needSort = r.needSort, needCheck = r.needCheck;
	}

private:
	MaterialKind      kind = MaterialKind::None;
	ElasticMat        elastic;
	DpGkMat           dpgk;
	BlockSchedule<D>  sched;
	StencilOffsets<D> offs;
	bool              needSort = true;  // particles must be re-sorted by block before the next transfer
	bool              needCheck = true; // particle data changed from outside: validate and refresh ρ_min, mass floor
	Real              vmax = 0, rhoMin = INFINITY, massFloor = 0;

	struct ErrorRecord {
		size_t      particle = SIZE_MAX;
		std::string what;
		void        clear() { particle = SIZE_MAX, what.clear(); }
		bool        none() const { return particle == SIZE_MAX; }
		void record(size_t p, const std::string& w)
		{
#pragma omp critical(mpm_error)
			if (p < particle) particle = p, what = w;
		}
	};
	ErrorRecord errP2G, errG2P; // shared by the threads of the transfer region

	static std::string fmt(Real v)
	{
		std::ostringstream o;
		o.precision(6);
		o << v;
		return o.str();
	}

	template <class F>
	void withMaterial(F&& f)
	{
		if (kind == MaterialKind::Elastic) f(LinearElastic<D>(elastic));
		else f(DruckerPragerGradyKipp<D>(dpgk));
	}

	void initDamageThresholds(size_t from)
	{
		if (!dpgk.damage) return;
		P.ensureDamageState();
		for (size_t p = from; p < P.n; ++p) P.eps0[p] = dpgk.activationStrain(P.vol0[p]); // Eq. 37
	}

	// Validation that must precede any work; cheap when nothing changed.
	void prepare()
	{
		if (P.n == 0) throw InputError("particles: no particles in the solver; add particles before stepping");
		if (kind == MaterialKind::None) throw InputError("material: no material assigned; set a material before stepping");
		if (!std::isfinite(rhoMin) || needCheck) {
			Real mmin = INFINITY;
			rhoMin    = INFINITY;
			const Vec lo = grid.origin, hi = grid.upper();
			for (size_t p = 0; p < P.n; ++p) {
				// State edited through the live views (requestSort() after editing) is validated like
				// addParticles input: a NaN or off-grid position would index outside the node arrays.
				auto who = [&] { return "particle id " + std::to_string(P.id[p]); }; // built only for a message
				for (int a = 0; a < D; ++a)
					if (!(P.x[a][p] >= lo[a] && P.x[a][p] < hi[a]))
						throw InputError("position of " + who() + " along axis " + std::to_string(a) + " = " + fmt(P.x[a][p]) + " m is not finite or outside the grid ["
						                 + fmt(lo[a]) + ", " + fmt(hi[a]) + ") m");
				if (!(std::isfinite(P.mass[p]) && P.mass[p] > 0)) throw InputError("mass of " + who() + " = " + fmt(P.mass[p]) + " kg must be finite and > 0");
				if (!(std::isfinite(P.vol[p]) && P.vol[p] > 0)) throw InputError("volume of " + who() + " = " + fmt(P.vol[p]) + " m³ must be finite and > 0");
				rhoMin = std::min(rhoMin, P.mass[p] / P.vol[p]);
				mmin   = std::min(mmin, P.mass[p]);
				for (int a = 0; a < D; ++a)
					if (!std::isfinite(P.v[a][p])) throw InputError("velocity of particle id " + std::to_string(P.id[p]) + " is not finite");
				for (int k = 0; k < NS; ++k)
					if (!std::isfinite(P.sig[k][p])) throw InputError("stress of particle id " + std::to_string(P.id[p]) + " is not finite");
				Real sp = 0;
				for (int a = 0; a < D; ++a) sp += P.v[a][p] * P.v[a][p];
				vmax = std::max(vmax, std::sqrt(sp));
			}
			massFloor = 1e-14 * mmin; // nodes lighter than this carry no velocity (only roundoff-level mass)
			needCheck = false;
		}
	}

	// Particles of block b.
	template <class F>
	void forBlock(uint32_t b, F&& f) const
	{
		for (uint32_t p = sched.start[b]; p < sched.start[b + 1]; ++p) f(size_t(p));
	}
	// Scatter pass: colours in sequence, blocks of one colour in parallel (deterministic sums).
	// Called by every thread of the step's parallel region (orphaned worksharing loops).
	template <class F>
	void scatterPass(F&& f)
	{
		for (int c = 0; c < Dim<D>::nColours; ++c) {
			const auto& blocks = sched.colour[c];
#pragma omp for schedule(dynamic, 1)
			for (size_t k = 0; k < blocks.size(); ++k) forBlock(blocks[k], f);
		}
	}
	void throwIf(const ErrorRecord& e, const char* phaseName)
	{
		if (e.particle == SIZE_MAX) return;
		throw SimulationError(
		        "MPM stopped at step " + std::to_string(steps) + " (t = " + fmt(time) + " s) in " + phaseName + ": particle id " + std::to_string(P.id[e.particle])
		        + " " + e.what);
	}
	void kernelOf(size_t p, Kernel<D>& k) const
	{
		Real x[D];
		for (int a = 0; a < D; ++a) x[a] = P.x[a][p];
		computeKernel(grid, offs, x, k);
	}
	std::string positionText(size_t p) const
	{
		std::string t = "(";
		for (int a = 0; a < D; ++a) t += (a ? ", " : "") + fmt(P.x[a][p]);
		return t + ") m";
	}
	Real dxOf(const Stencil<D>& st, int n, int a) const { return st.d[a][Stencil<D>::along(n, a)]; }

	// ---------------------------------------------------------------- P2G: Eqs. 20–22
	// Every node receives w·(P0 + Σ_b A_b (x_i − x_p)_b) with the per-particle affine coefficients
	// P0 = [m, m, m v, f_ext] and A_b = [0, 0, m C_·b, −V σ_·b 3/l²] (interior particles, where
	// ∇ψ_i = w_i 3/l² (x_i − x_p)); particles with a general WLS stencil go through the full ψ, ∇ψ.
	template <class Mat>
	void p2g(const Mat& mat)
	{
		auto& nodes = grid.nodes;
#pragma omp for schedule(static)
		for (size_t i = 0; i < nodes.size(); ++i) lanes(nodes[i]) = NodeLanes {}; // padding lanes too
		const Real  s = loadScale(time);
		const Real  Dinv = 3.0 / (grid.spacing * grid.spacing); // interior M⁻¹ gradient factor
		ErrorRecord& err = errP2G;
		scatterPass([&](size_t p) {
			Kernel<D> k;
			kernelOf(p, k);
			if (!k.inside) return err.record(p, "has a position outside the grid or not finite: " + positionText(p));
			const Real   m = P.mass[p], V = P.vol[p];
			const Sym<D> sg = mat.forceStress(P, p);
			Real         mv[D], mC[D][D], fe[D];
			for (int a = 0; a < D; ++a) {
				mv[a] = m * P.v[a][p];
				for (int b = 0; b < D; ++b) mC[a][b] = m * P.C[a * D + b][p];
				fe[a] = m * gravity[a] + (P.hasTraction() ? s * P.trac[a][p] : 0.0); // Eq. 22
			}
			if (!k.general) {
				Real sgm[D][D];
				sym2full(sg, sgm);
				// lanes: m, mw, momentum…, force…
				const NodeLanes P0 = nodeLanes(m, m, mv, fe);
				NodeLanes       A[D];
				for (int b = 0; b < D; ++b) {
					Real ca[D], fa[D];
					for (int a = 0; a < D; ++a) {
						ca[a] = mC[a][b];
						fa[a] = -V * Dinv * sgm[a][b]; // Eq. 21, f_int = −Σ V σ ∇ψ
					}
					A[b] = nodeLanes(0, 0, ca, fa);
				}
				scatterAffine(k, P0, A); // Eqs. 20–22 with ψ = w: w (P0 + Σ_b A_b (x_i − x_p)_b)
				return;
			}
			Stencil<D> st;
			if (!fillStencil(grid, offs, k, st)) return err.record(p, "has too few active grid nodes for the WLS fit (singular moment matrix)");
			for (int n = 0; n < N; ++n) {
				Node<D>&    nd  = nodes[st.base + offs.off[n]];
				const Real  psi = st.psi[n];
				const Real* g   = st.grad[n];
				nd.m += psi * m;     // Eq. 20
				nd.mw += st.w[n] * m; // Σ w m, denominator of Eq. 17
				Real sg_g[D];
				stressTimesVector(sg, g, sg_g);
				for (int a = 0; a < D; ++a) {
					Real mom = mv[a];
					for (int b = 0; b < D; ++b) mom += mC[a][b] * dxOf(st, n, b);
					nd.a[a] += psi * mom;                       // momentum of the affine velocity field (Eq. 16)
					nd.b[a] += -V * sg_g[a] + psi * fe[a]; // Eq. 21 (f_int = −Σ V σ ∇ψ) + Eq. 22
				}
			}
		});
	}
	// Interior scatter of an affine field: node i of the stencil receives w_i (base + Σ_b slope_b (x_i − x_p)_b),
	// expanded row by row (the x-layer is the innermost loop).
	void scatterAffine(const Kernel<D>& k, const NodeLanes& base, const NodeLanes* slope)
	{
		auto& nodes = grid.nodes;
		forRows(k, [&](size_t row, Real wr, const Real* dr) {
			NodeLanes R = base;
			for (int b = 1; b < D; ++b) R += slope[b] * dr[b - 1];
			R *= wr;
			const NodeLanes S = slope[0] * wr;
			for (int i = 0; i < 4; ++i) {
				const Real wx = k.w[0][i];
				lanes(nodes[row + i]) += wx * R + (wx * k.d[0][i]) * S;
			}
		});
	}
	// Lane vector of a node: m, mw, a…, b… (and zero padding in 2D).
	static NodeLanes nodeLanes(Real m, Real mw, const Real (&a)[D], const Real (&b)[D])
	{
		if constexpr (D == 2) return NodeLanes { m, mw, a[0], a[1], b[0], b[1], 0, 0 };
		else return NodeLanes { m, mw, a[0], a[1], a[2], b[0], b[1], b[2] };
	}
	static void sym2full(const Sym<D>& s, Real (&f)[D][D])
	{
		f[0][0] = s.c[0], f[1][1] = s.c[1], f[0][1] = f[1][0] = s.c[3];
		if constexpr (D == 3) {
			f[2][2] = s.c[2];
			f[0][2] = f[2][0] = s.c[4];
			f[1][2] = f[2][1] = s.c[5];
		}
	}
	// Visits the 4^(D−1) stencil rows along x of an interior kernel: f(linear index of the row's first
	// node, product of the row's weights along y[, z], its offsets (x_i − x_p) along y[, z]).
	template <class F>
	void forRows(const Kernel<D>& k, F&& f) const
	{
		const size_t sy = grid.stride[1];
		if constexpr (D == 2) {
			for (int j = 0; j < 4; ++j) f(k.base + j * sy, k.w[1][j], &k.d[1][j]);
		} else {
			const size_t sz = grid.stride[2];
			for (int l = 0; l < 4; ++l)
				for (int j = 0; j < 4; ++j) {
					const Real dr[2] = { k.d[1][j], k.d[2][l] };
					f(k.base + l * sz + j * sy, k.w[1][j] * k.w[2][l], dr);
				}
		}
	}
	static void stressTimesVector(const Sym<D>& s, const Real* g, Real* out)
	{
		if constexpr (D == 2) {
			out[0] = s.c[0] * g[0] + s.c[3] * g[1];
			out[1] = s.c[3] * g[0] + s.c[1] * g[1];
		} else {
			out[0] = s.c[0] * g[0] + s.c[3] * g[1] + s.c[4] * g[2];
			out[1] = s.c[3] * g[0] + s.c[1] * g[1] + s.c[5] * g[2];
			out[2] = s.c[4] * g[0] + s.c[5] * g[1] + s.c[2] * g[2];
		}
	}

	// ---------------------------------------------------------------- grid: Eq. 18 with lumped mass
	void gridUpdate(Real dt)
	{
		auto&      nodes = grid.nodes;
		const Real alpha = damping, mf = massFloor;
#pragma omp for schedule(static)
		for (size_t i = 0; i < nodes.size(); ++i) {
			Node<D>&      nd  = nodes[i];
			const uint8_t fix = grid.fixMask[i];
			if (nd.m > mf) {
				for (int a = 0; a < D; ++a) {
					const Real v = nd.a[a] / nd.m;
					Real       f = nd.b[a];
					if (alpha > 0 && v != 0) f -= alpha * std::abs(f) * (v > 0 ? 1 : -1);
					nd.a[a] = (fix >> a) & 1 ? 0.0 : v + dt * f / nd.m;
				}
			} else {
				for (int a = 0; a < D; ++a) nd.a[a] = 0;
			}
			for (int a = 0; a < D; ++a) nd.b[a] = 0; // b collects the MUSL momentum next
		}
	}

	// ---------------------------------------------------------------- G2P + MUSL remap: Eqs. 6–7, 16–17
	// Particle velocity and its WLS gradient from the updated nodal velocities, then the particle's
	// local linear velocity field is spread back with Shepard weights ξ = w m / Σ w m.
	void g2p()
	{
		auto&        nodes = grid.nodes;
		ErrorRecord& err   = errG2P;
		scatterPass([&](size_t p) {
			Kernel<D> k;
			kernelOf(p, k);
			const Real m = P.mass[p];
			Real       v[D] = {}, C[D][D] = {};
			if (!k.general) {
				gatherInterior<2>(k, v, C); // Eqs. 6–7 from the updated velocities (lanes a)
				storeVelocity(p, v, C);
				NodeLanes H[D + 1]; // m h_p(x_i) = m (v + ∇v (x_i − x_p)) into lanes b
				{
					const Real zero[D] = {};
					Real       mvv[D], mc[D];
					for (int a = 0; a < D; ++a) mvv[a] = m * v[a];
					H[D] = nodeLanes(0, 0, zero, mvv);
					for (int b = 0; b < D; ++b) {
						for (int a = 0; a < D; ++a) mc[a] = m * C[a][b];
						H[b] = nodeLanes(0, 0, zero, mc);
					}
				}
				scatterAffine(k, H[D], H); // Eq. 16 numerator, Σ w m h_p(x_i)
				return;
			}
			Stencil<D> st;
			if (!fillStencil(grid, offs, k, st)) return err.record(p, "has too few active grid nodes for the WLS fit (singular moment matrix)");
			for (int n = 0; n < N; ++n) {
				const Node<D>& nd = nodes[st.base + offs.off[n]];
				for (int a = 0; a < D; ++a) {
					v[a] += st.psi[n] * nd.a[a]; // Eq. 6
					for (int b = 0; b < D; ++b) C[a][b] += nd.a[a] * st.grad[n][b]; // Eq. 7
				}
			}
			storeVelocity(p, v, C);
			for (int n = 0; n < N; ++n) {
				Node<D>&   nd = nodes[st.base + offs.off[n]];
				const Real wm = st.w[n] * m;
				for (int a = 0; a < D; ++a) {
					Real h = v[a];
					for (int b = 0; b < D; ++b) h += C[a][b] * dxOf(st, n, b);
					nd.b[a] += wm * h; // Eq. 16 numerator, h_p(x_i) = v_p + ∇v_p (x_i − x_p)
				}
			}
		});
	}
	// Interior gather of a nodal vector field u (lanes first..first+D−1): u_p = Σ w_i u_i and
	// ∇u_p = Σ u_i ⊗ ∇ψ_i with ∇ψ_i = w_i 3/l² (x_i − x_p) (Eqs. 6–7).
	template <int first>
	void gatherInterior(const Kernel<D>& k, Real (&u)[D], Real (&G)[D][D]) const
	{
		const auto& nodes = grid.nodes;
		NodeLanes   U = {}, Gb[D] = {};
		forRows(k, [&](size_t row, Real wr, const Real* dr) {
			NodeLanes r0 = {}, r1 = {};
			for (int i = 0; i < 4; ++i) {
				const NodeLanes& q  = lanes(nodes[row + i]);
				const Real       wx = k.w[0][i];
				r0 += wx * q;
				r1 += (wx * k.d[0][i]) * q;
			}
			U += wr * r0;
			Gb[0] += wr * r1;
			for (int b = 1; b < D; ++b) Gb[b] += (wr * dr[b - 1]) * r0;
		});
		const Real Dinv = 3.0 / (grid.spacing * grid.spacing);
		for (int a = 0; a < D; ++a) {
			u[a] = U[first + a];
			for (int b = 0; b < D; ++b) G[a][b] = Dinv * Gb[b][first + a];
		}
	}
	void storeVelocity(size_t p, const Real (&v)[D], const Real (&C)[D][D])
	{
		for (int a = 0; a < D; ++a) {
			P.v[a][p] = v[a];
			for (int b = 0; b < D; ++b) P.C[a * D + b][p] = C[a][b];
		}
	}
	void gridMusl()
	{
		auto&      nodes = grid.nodes;
		const Real mf    = massFloor;
#pragma omp for schedule(static)
		for (size_t i = 0; i < nodes.size(); ++i) {
			Node<D>&      nd  = nodes[i];
			const uint8_t fix = grid.fixMask[i];
			const Real    inv = nd.mw > mf ? 1.0 / nd.mw : 0.0; // Eq. 17 denominator
			for (int a = 0; a < D; ++a) nd.b[a] = (fix >> a) & 1 ? 0.0 : nd.b[a] * inv;
		}
	}

	// ---------------------------------------------------------------- stress update: Eqs. 7, 27–40
	template <class Mat>
	void updateStress(const Mat& mat, Real dt)
	{
		ErrorRecord err;
		Real        v2max = 0, rmin = INFINITY;
		bool        drift = false;
		const auto& blocks = sched.start;
		const long  nb     = long(blocks.size()) - 1;
		const Vec   lo = grid.origin, hi = grid.upper();
		const Real  invH = 1.0 / grid.spacing;
#pragma omp parallel for schedule(dynamic, 4) reduction(max : v2max) reduction(min : rmin) reduction(|| : drift)
		for (long b = 0; b < nb; ++b) {
			Real cellLo[D], cellHi[D]; // cells a particle of block b may reach before a re-sort
			sched.reach(size_t(b), cellLo, cellHi);
			for (uint32_t pp = blocks[b]; pp < blocks[b + 1]; ++pp) {
				const size_t p = pp;
				Real L[D][D] = {}; // ∇v from the MUSL nodal velocities, Eq. 7
				if (!velocityGradient(p, L)) {
					err.record(p, "has too few active grid nodes for the WLS fit (singular moment matrix)");
					continue;
				}
				Sym<D> de;   // Δε = sym(∇v) Δt, Eq. 29
				Sym<D> s = P.stress(p);
				strainIncrement(L, dt, de);
				jaumannRotation(L, dt, s);
				mat.update(P, p, s, de, dt); // Eqs. 27–40
				P.setStress(p, s);
				const Real J = jacobian(L, dt);
				P.vol[p] *= J;
				Real sp = 0, check = J;
				bool inside = true, near = true;
				for (int k = 0; k < Dim<D>::nSym; ++k) check += s.c[k];
				for (int a = 0; a < D; ++a) {
					const Real va = P.v[a][p], xa = P.x[a][p] + dt * va;
					P.x[a][p] = xa;
					sp += va * va;
					check += xa;
					inside = inside && xa >= lo[a] && xa < hi[a];
					const Real f = (xa - lo[a]) * invH;
					near = near && f >= cellLo[a] && f < cellHi[a];
				}
				// one sum carries every value that must be finite (NaN/inf propagate), checked once
				if (!(std::isfinite(check) && std::isfinite(sp) && J > 0)) {
					err.record(p, describeBad(p, s, J));
					continue;
				}
				if (!inside) {
					for (int a = 0; a < D; ++a)
						if (P.x[a][p] < lo[a] || P.x[a][p] >= hi[a]) {
							err.record(p, "left the grid along axis " + std::to_string(a) + " at x = " + fmt(P.x[a][p]) + " m (grid spans [" + fmt(lo[a])
							                      + ", " + fmt(hi[a]) + ") m)");
							break;
						}
					continue;
				}
				v2max = std::max(v2max, sp);
				rmin  = std::min(rmin, P.mass[p] / P.vol[p]);
				drift = drift || !near;
			}
		}
		throwIf(err, "stress update");
		vmax   = std::sqrt(v2max);
		rhoMin = rmin;
		if (drift) needSort = true;
	}
	// ∇v_p = Σ v_i ⊗ ∇ψ_i over the MUSL nodal velocities (Eq. 7). False if the WLS fit is singular.
	bool velocityGradient(size_t p, Real (&L)[D][D]) const
	{
		const auto& nodes = grid.nodes;
		Kernel<D>   k;
		kernelOf(p, k);
		if (!k.general) {
			Real v[D];
			gatherInterior<2 + D>(k, v, L); // MUSL velocities (lanes b)
			return true;
		}
		Stencil<D> st;
		if (!fillStencil(grid, offs, k, st)) return false;
		for (int n = 0; n < N; ++n) {
			const Node<D>& nd = nodes[st.base + offs.off[n]];
			for (int a = 0; a < D; ++a)
				for (int c = 0; c < D; ++c) L[a][c] += nd.b[a] * st.grad[n][c];
		}
		return true;
	}
	std::string describeBad(size_t p, const Sym<D>& s, Real J) const
	{
		static const char* comp[6] = { "xx", "yy", "zz", "xy", "xz", "yz" };
		for (int k = 0; k < NS; ++k)
			if (!std::isfinite(s.c[k])) return std::string("has non-finite stress σ") + comp[k] + " = " + fmt(s.c[k]);
		for (int a = 0; a < D; ++a)
			if (!std::isfinite(P.v[a][p])) return "has non-finite velocity component " + std::to_string(a) + " = " + fmt(P.v[a][p]);
		if (!(J > 0)) return "has non-positive volume change det(I + Δt∇v) = " + fmt(J) + " (element inverted)";
		return "has a non-finite position";
	}
	static void strainIncrement(const Real (&L)[D][D], Real dt, Sym<D>& de)
	{
		de.c[0] = L[0][0] * dt;
		de.c[1] = L[1][1] * dt;
		de.c[2] = D == 3 ? L[D - 1][D - 1] * dt : 0.0; // plane strain: Δε_zz = 0
		de.c[3] = 0.5 * (L[0][1] + L[1][0]) * dt;
		if constexpr (D == 3) {
			de.c[4] = 0.5 * (L[0][2] + L[2][0]) * dt;
			de.c[5] = 0.5 * (L[1][2] + L[2][1]) * dt;
		}
	}
	// Objective (Jaumann) rotation of the stress by the spin W = skew(∇v): σ += Δt(Wσ − σW).
	static void jaumannRotation(const Real (&L)[D][D], Real dt, Sym<D>& s)
	{
		if constexpr (D == 2) {
			const Real w  = 0.5 * (L[0][1] - L[1][0]) * dt; // W_xy
			const Real sx = s.c[0], sy = s.c[1], sxy = s.c[3];
			s.c[0] = sx + 2 * w * sxy;
			s.c[1] = sy - 2 * w * sxy;
			s.c[3] = sxy + w * (sy - sx);
		} else { // σ + WσΔt − σWΔt = σ + M + Mᵀ with M = WσΔt (W antisymmetric)
			const Real w01 = 0.5 * (L[0][1] - L[1][0]) * dt, w02 = 0.5 * (L[0][2] - L[2][0]) * dt, w12 = 0.5 * (L[1][2] - L[2][1]) * dt;
			const Real xx = s.c[0], yy = s.c[1], zz = s.c[2], xy = s.c[3], xz = s.c[4], yz = s.c[5];
			s.c[0] = xx + 2 * (w01 * xy + w02 * xz);
			s.c[1] = yy + 2 * (w12 * yz - w01 * xy);
			s.c[2] = zz - 2 * (w02 * xz + w12 * yz);
			s.c[3] = xy + w01 * (yy - xx) + w02 * yz + w12 * xz;
			s.c[4] = xz + w01 * yz + w02 * (zz - xx) - w12 * xy;
			s.c[5] = yz - w01 * xz - w02 * xy + w12 * (zz - yy);
		}
	}
	static Real jacobian(const Real (&L)[D][D], Real dt)
	{
		if constexpr (D == 2) return (1 + L[0][0] * dt) * (1 + L[1][1] * dt) - L[0][1] * L[1][0] * dt * dt;
		else {
			Eigen::Matrix3d F;
			for (int a = 0; a < 3; ++a)
				for (int b = 0; b < 3; ++b) F(a, b) = (a == b) + L[a][b] * dt;
			return F.determinant();
		}
	}

	void accumulateExternalWork(Real dt)
	{
		const Real s = loadScale(time + dt);
		Real       w = 0;
		for (size_t p = 0; p < P.n; ++p)
			for (int a = 0; a < D; ++a) w += (P.mass[p] * gravity[a] + (P.hasTraction() ? s * P.trac[a][p] : 0.0)) * P.v[a][p] * dt;
		externalWork += w;
	}
};

} // namespace mpm
