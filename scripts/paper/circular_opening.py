"""Circular opening under biaxial in-situ stress, paper Sec. 3.1 (Figs. 3-5), against Kirsch (Eqs. 41-42).

Plane strain square of side L (paper: 5 m) with a hole of diameter 0.2 m at its centre (2.5 m, 2.5 m);
far-field σxx = 20 MPa, σyy = 10 MPa (compression); elastic rock E = 22.41 GPa, ν = 0.2313,
ρ = 2500 kg/m³. The centre stays at (2.5, 2.5) m for any L, so the lines y = 2.5 m and x = 2.5 m
are the paper's.

Quasi-static solution by explicit dynamics ("excavation"): every particle starts with the in-situ
stress σ0 = (−20, −10, ν(−20 −10), 0) MPa (tension positive inside the solver); the block faces carry
the far-field traction σ0·n, spread over the outer particle rows so that the intact block is in exact
discrete equilibrium (consistent_row_weights); only the hole wall is out of balance. Cundall local
damping relaxes the transient; the run stops when the stresses sampled along both lines change less
than --tol · 20 MPa per check interval (or at --max-time).

Sampling: the two particle rows straddling each line (at ±l/4 for ppc = 2) are compared with Kirsch
evaluated at each particle's own position; plots show the average of the two rows. Relative L2
errors ‖σ_MPM − σ_K‖/‖σ_K‖ over the particles of a line with r ≥ 2a (up to the outer boundary,
boundary rows included). Hoop stress at the wall (θ = 0°: σyy on y = 2.5 m, θ = 90°: σxx on
x = 2.5 m): straight-line extrapolation to r = a of the rows within one cell of the wall; the
nearest-row mean is reported too. Default: L = 4.8 m, l = 0.04 m, convergence table l = 0.08, 0.06,
0.04 m (doc/validation/circular_opening.md). A run of the ladder that the solver stops is named under "stopped" in
summary.json (with its message) and the others still run; the exit status is then 1.

    /usr/bin/python3 scripts/paper/circular_opening.py --out out/circular_opening             # default
    /usr/bin/python3 scripts/paper/circular_opening.py --out out/co_paper --spacing 0.01 --domain 5 --no-convergence
    yade-batch scripts/paper/circular_opening.table scripts/paper/circular_opening.py   # a study: one run per line (doc/guide/studies.md)
"""
import argparse
import math
import os
import sys
import time

import numpy as np

import yade_mpm as ym
import yade_mpm.output as out
from yade_mpm_paper.validation import kirsch

from yade_mpm import rocks, runner
from yade_mpm_paper import batch, cases, uncertainty
from yade_mpm_paper.cases import OPENING_CENTER as CENTER, OPENING_RADIUS as RADIUS, OPENING_SXX as SXX_FAR, OPENING_SYY as SYY_FAR

MPa = 1e6


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--spacing", type=float, default=0.04, help="grid spacing l of the main run [m] (paper: 0.01)")
    p.add_argument("--domain", type=float, default=4.8,
                   help="side L of the square block [m] (paper: 5.0; default 4.8 = a whole number of cells for l = 0.08, 0.06, 0.04, 0.03, 0.02, 0.01)")
    p.add_argument("--ppc", type=int, default=2, help="particles per cell per axis (paper: 2)")
    p.add_argument("--boundary-load", choices=("consistent", "outer-row"), default="consistent",
                   help="far-field traction on the outer 3·ppc particle rows with weights that keep the intact "
                        "block in exact discrete equilibrium (default), or on the outermost row only")
    p.add_argument("--damping", type=float, default=0.5, help="Cundall local damping α (the solver setting `damping`; range in its declaration)")
    p.add_argument("--tol", type=float, default=1e-3,
                   help="stop when line stresses change < tol·20 MPa over one check interval")
    p.add_argument("--max-time", type=float, default=None,
                   help="simulated time limit [s] (default: 40 P-wave transits of the block)")
    p.add_argument("--convergence", dest="convergence", action="store_true", default=True,
                   help="also run at 4l and 2l for the error-vs-run-time table (default)")
    p.add_argument("--no-convergence", dest="convergence", action="store_false")
    p.add_argument("--convergence-spacings", type=float, nargs="+", default=None,
                   help="grid spacings of the convergence table [m] (default: the three finest of 4l, 2l, 1.5l, l "
                        "that are ≤ a and divide L/2)")
    p.add_argument("--threads", type=int, default=0, help="OpenMP threads (0 = all cores)")
    p.add_argument("--progress", type=float, default=10.0, help="wall seconds between progress lines")
    ym.scene.courant_option(p)                      # default: the solver's C (pkg-mpm/core/SolverSettings.hpp)
    uncertainty.shift_option(p)                     # the grid moved against the block (every run of the ladder)
    p.add_argument("--far-field", choices=cases.FAR_FIELDS, default="uniform",
                   help="load on the block faces: 'uniform' far-field stress (the paper's; the finite block differs from Kirsch's "
                        "infinite plate by O((a/L)²)) or 'kirsch' (Kirsch's stress on the faces: the error is the discretisation's alone)")
    p.add_argument("--no-vtu", dest="vtu", action="store_false", help="skip the VTU particle file")
    p.add_argument("--vtu-every", type=float, default=0.0,
                   help="also write a VTU series of the main run (DIR/series/particles.pvd for ParaView) every this "
                        "many simulated seconds [s] (default 0: final state only)")
    a = batch.parse_args(p, argv)     # the command line, or a yade-batch / scripts/studies/sweep.py table line
    check_args(a)
    return a


def check_args(a):
    """Every bad input is refused before any work, naming the parameter and its range."""
    if not (math.isfinite(a.domain) and a.domain > 4 * RADIUS):
        raise ValueError(f"--domain = {a.domain} m must exceed 4a = {4 * RADIUS} m (the block must contain r ≥ 2a)")
    for name, l in [("--spacing", a.spacing)] + [("--convergence-spacings", x) for x in (a.convergence_spacings or [])]:
        if not (math.isfinite(l) and 0 < l <= RADIUS):
            raise ValueError(f"{name} = {l} m must be in (0, {RADIUS}] m (at least one cell per hole radius)")
        if abs(a.domain / 2 / l - round(a.domain / 2 / l)) > 1e-6:
            raise ValueError(f"{name} = {l} m must divide L/2 = {a.domain / 2} m (--domain) into whole cells")
    if a.ppc < 1 or a.ppc > 4:
        raise ValueError(f"--ppc = {a.ppc} must be in [1, 4]")
    if a.boundary_load == "consistent":
        ym.scene.consistent_row_weights(a.ppc)              # raises for ppc = 1
    ym.scene.check_setting("damping", a.damping, "--damping")  # the solver's declared range
    a.courant = ym.scene.check_courant(a.courant)
    if not (math.isfinite(a.tol) and a.tol > 0):
        raise ValueError(f"--tol = {a.tol} must be > 0")
    if a.max_time is not None and not (math.isfinite(a.max_time) and a.max_time > 0):
        raise ValueError(f"--max-time = {a.max_time} s must be > 0")
    if a.threads < 0:
        raise ValueError(f"--threads = {a.threads} must be ≥ 0 (0 = all cores)")
    if not (math.isfinite(a.vtu_every) and a.vtu_every >= 0):
        raise ValueError(f"--vtu-every = {a.vtu_every} s must be ≥ 0 (0 = no series)")
    if a.progress <= 0:
        raise ValueError(f"--progress = {a.progress} s must be > 0")
    a.grid_shift = uncertainty.parse_shift(a.grid_shift)


def fits(l, domain):
    """l resolves the hole (l ≤ a) and L/2 is a whole number of cells (grid line through the centre)."""
    return l <= RADIUS + 1e-12 and abs(domain / 2 / l - round(domain / 2 / l)) < 1e-6


def default_ladder(l, domain):
    """Convergence table spacings: the three finest of 4l, 2l, 1.5l, l that fit the block."""
    return [round(x, 12) for x in (4 * l, 2 * l, 1.5 * l, l) if fits(x, domain)][-3:]


class LineSamples:
    """Particles of the two rows straddling y = 2.5 m (x-line) and x = 2.5 m (y-line), by particle id,
    with Kirsch evaluated at their initial positions (displacements are ~1e-4 m, far below l)."""

    def __init__(self, s, spacing, ppc):
        pos = ym.get(s, "pos")
        dp = spacing / ppc
        self.dp = dp
        self.lines = {}
        for name, across, along in (("xline", 1, 0), ("yline", 0, 1)):
            ids = np.nonzero(np.abs(pos[:, across] - CENTER) <= 0.5 * dp + 1e-9 * spacing)[0]
            ids = ids[np.argsort(pos[ids, along], kind="stable")]
            p = pos[ids]
            kxx, kyy, _ = kirsch.cartesian(p[:, 0], p[:, 1], (CENTER, CENTER), RADIUS, SXX_FAR, SYY_FAR)
            self.lines[name] = dict(ids=ids, along=p[:, along] - CENTER, r=np.hypot(p[:, 0] - CENTER, p[:, 1] - CENTER),
                                    kxx=kxx, kyy=kyy, pos=p)

    def stresses(self, s):
        """Compression-positive (σxx, σyy) of every sampled particle, per line."""
        st = -ym.get(s, "stress")
        return {n: (st[L["ids"], 0], st[L["ids"], 1]) for n, L in self.lines.items()}

    def vector(self, s):
        return np.concatenate([np.concatenate(v) for v in self.stresses(s).values()])


def relax(s, samples, args, spacing, label, series=None):
    """Run to the quasi-static state; returns (converged, check history). series: an output.VtuSeries
    written every --vtu-every seconds, at the start and at the end."""
    cp = rocks.granite().pWaveSpeed()
    transit = args.domain / cp
    max_time = args.max_time or 40 * transit
    check_dt = 2 * RADIUS * 5 / cp             # P-wave time over 5 hole diameters between checks
    prev = [samples.vector(s)]
    history = []
    converged = [False]

    def check(s):
        cur = samples.vector(s)
        change = float(np.max(np.abs(cur - prev[0]))) / SXX_FAR
        history.append((s.steps, s.time, change, s.kineticEnergy()))
        prev[0] = cur
        if change < args.tol and s.time > 2 * transit:  # at least one P-wave round trip through the block
            converged[0] = True
            return runner.STOP

    outputs = [runner.Output(check, period=check_dt, at_end=True)]
    if series is not None:
        outputs.append(runner.Output(series.write, period=args.vtu_every, at_start=True, at_end=True))
    runner.run(s, end_time=max_time, progress=args.progress, label=label, outputs=outputs)
    return converged[0], history


def l2_rel(sim, ref, mask):
    return float(np.linalg.norm(sim[mask] - ref[mask]) / np.linalg.norm(ref[mask]))


def wall_hoop(along, r, sig, spacing, ppc):
    """Hoop stress at the wall from one side-averaged line: (nearest-row mean, linear extrapolation to
    r = a from the particles within one cell of the wall)."""
    dp = spacing / ppc
    rr = np.abs(along)
    near = rr < rr.min() + 0.5 * dp
    nearest = float(sig[near].mean())
    band = rr < RADIUS + spacing + 1e-12
    if np.unique(np.round(rr[band] / dp, 6)).size >= 2:
        c = np.polyfit(rr[band], sig[band], 1)
        extrap = float(np.polyval(c, RADIUS))
    else:
        extrap = nearest
    return nearest, extrap


def evaluate(s, samples, spacing, ppc, domain):
    """Errors, hoop stresses and side-averaged profiles."""
    st = samples.stresses(s)
    res, prof = {}, {}
    for name, L in samples.lines.items():
        sxx, syy = st[name]
        far = L["r"] >= 2 * RADIUS
        res[f"l2_rel_error_sxx_{name}"] = l2_rel(sxx, L["kxx"], far)
        res[f"l2_rel_error_syy_{name}"] = l2_rel(syy, L["kyy"], far)
        # without the outer boundary layer (one cell): how much of the error the traction boundary makes
        inner = far & (np.abs(L["along"]) < domain / 2 - spacing)
        res[f"l2_rel_error_sxx_{name}_interior"] = l2_rel(sxx, L["kxx"], inner)
        res[f"l2_rel_error_syy_{name}_interior"] = l2_rel(syy, L["kyy"], inner)
        # near field 2a ≤ r ≤ 5a: discretisation error, little of the finite-block effect (∝ (a/R)²)
        near = far & (L["r"] <= 5 * RADIUS)
        res[f"l2_rel_error_sxx_{name}_near"] = l2_rel(sxx, L["kxx"], near)
        res[f"l2_rel_error_syy_{name}_near"] = l2_rel(syy, L["kyy"], near)
        # average the two rows at the same station along the line
        key = np.round(L["along"] / samples.dp * 2).astype(int)
        _, inv = np.unique(key, return_inverse=True)
        cnt = np.bincount(inv)
        avg = lambda v: np.bincount(inv, weights=v) / cnt
        prof[name] = dict(along=avg(L["along"]), r=avg(L["r"]), sxx=avg(sxx), syy=avg(syy),
                          kxx=avg(L["kxx"]), kyy=avg(L["kyy"]))
    # θ = 0° (σH = σxx direction): wall point on the x-line, hoop stress = σyy
    # θ = 90°: wall point on the y-line, hoop stress = σxx
    for theta, name, comp, kcomp in ((0, "xline", "syy", "kyy"), (90, "yline", "sxx", "kxx")):
        P = prof[name]
        vals, kvals = [], []
        for sgn in (-1, 1):
            m = np.sign(P["along"]) == sgn
            vals.append(wall_hoop(P["along"][m], P["r"][m], P[comp][m], spacing, ppc))
            kvals.append(wall_hoop(P["along"][m], P["r"][m], P[kcomp][m], spacing, ppc))
        res[f"hoop_stress_theta{theta}_nearest_row_MPa"] = float(np.mean([v[0] for v in vals])) / MPa
        res[f"hoop_stress_theta{theta}_extrapolated_MPa"] = float(np.mean([v[1] for v in vals])) / MPa
        res[f"hoop_stress_theta{theta}_MPa"] = res[f"hoop_stress_theta{theta}_extrapolated_MPa"]
        res[f"hoop_stress_theta{theta}_nearest_row_r_m"] = float(np.min(P["r"]))
        # the same two estimators applied to Kirsch at the same particles: their own bias at this l
        res[f"kirsch_at_nearest_row_theta{theta}_MPa"] = float(np.mean([v[0] for v in kvals])) / MPa
        res[f"kirsch_extrapolated_same_rows_theta{theta}_MPa"] = float(np.mean([v[1] for v in kvals])) / MPa
    return res, prof


def run_case(spacing, args, label, series=None):
    t0 = time.time()
    s, _, _ = cases.circular_opening(spacing, args.domain, args.ppc, args.damping, args.boundary_load, grid_shift=args.grid_shift,
                                     far_field=args.far_field)
    s.courant = args.courant
    samples = LineSamples(s, spacing, args.ppc)
    converged, hist = relax(s, samples, args, spacing, label, series)
    wall = time.time() - t0
    res, prof = evaluate(s, samples, spacing, args.ppc, args.domain)
    res.update(grid_spacing_m=spacing, particles=int(s.numParticles), steps=int(s.steps), simulated_time_s=float(s.time),
               wall_time_s=wall, converged=converged, last_change_rel=hist[-1][2] if hist else None)
    res["l2_rel_error_max"] = max(res[f"l2_rel_error_{c}_{n}"] for c in ("sxx", "syy") for n in ("xline", "yline"))
    res["l2_rel_error_near_max"] = max(res[f"l2_rel_error_{c}_{n}_near"] for c in ("sxx", "syy") for n in ("xline", "yline"))
    print(f"[{label}] l = {spacing} m, {res['particles']} particles, {res['steps']} steps, {wall:.1f} s wall, "
          f"converged = {converged}; L2 errors (r ≥ 2a): "
          + ", ".join(f"{c} {n} {100 * res[f'l2_rel_error_{c}_{n}']:.2f} %" for n in ("xline", "yline") for c in ("sxx", "syy"))
          + f"; hoop 0° {res['hoop_stress_theta0_MPa']:.2f} MPa, 90° {res['hoop_stress_theta90_MPa']:.2f} MPa", flush=True)
    return s, res, prof, hist


def write_profiles(out_dir, prof, spacing):
    for name, P in prof.items():
        rows = zip(P["along"] + CENTER, P["r"], P["sxx"] / MPa, P["kxx"] / MPa, P["syy"] / MPa, P["kyy"] / MPa)
        coord = "x_m" if name == "xline" else "y_m"
        out.write_csv(os.path.join(out_dir, f"{name}_stress.csv"),
                      [coord, "r_m", "sxx_mpm_MPa", "sxx_kirsch_MPa", "syy_mpm_MPa", "syy_kirsch_MPa"], rows)
    plt = out.pyplot()
    fig, axs = plt.subplots(1, 2, figsize=(12, 4.5))
    for ax, (name, P) in zip(axs, prof.items()):
        coord = P["along"] + CENTER
        # analytical curve on a fine grid along the line (inside the hole: gap)
        u = np.linspace(coord.min(), coord.max(), 2000)
        x, y = (u, np.full_like(u, CENTER)) if name == "xline" else (np.full_like(u, CENTER), u)
        kxx, kyy, _ = kirsch.cartesian(x, y, (CENTER, CENTER), RADIUS, SXX_FAR, SYY_FAR)
        ax.plot(u, kxx / MPa, "b-", lw=1.2, label="σxx Kirsch")
        ax.plot(u, kyy / MPa, "r-", lw=1.2, label="σyy Kirsch")
        step = max(1, len(coord) // 150)
        ax.plot(coord[::step], P["sxx"][::step] / MPa, "bo", mfc="none", ms=4, label="σxx MPM")
        ax.plot(coord[::step], P["syy"][::step] / MPa, "rs", mfc="none", ms=4, label="σyy MPM")
        ax.set_xlabel(("x" if name == "xline" else "y") + " [m]")
        ax.set_ylabel("stress [MPa] (compression +)")
        ax.set_title(("along y = 2.5 m" if name == "xline" else "along x = 2.5 m") + f", l = {spacing} m")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "stress_lines.png"), dpi=130)
    # zoom near the hole
    for ax in axs:
        ax.set_xlim(CENTER - 6 * RADIUS, CENTER + 6 * RADIUS)
    fig.savefig(os.path.join(out_dir, "stress_lines_zoom.png"), dpi=130)
    plt.close(fig)


def write_convergence(out_dir, table):
    out.write_csv(os.path.join(out_dir, "convergence.csv"),
                  ["grid_spacing_m", "particles", "steps", "wall_time_s", "l2_rel_error_max", "l2_rel_error_near_max", "l2_sxx_xline", "l2_syy_xline",
                   "l2_sxx_yline", "l2_syy_yline", "hoop_theta0_MPa", "hoop_theta90_MPa"],
                  [(r["grid_spacing_m"], r["particles"], r["steps"], r["wall_time_s"], r["l2_rel_error_max"], r["l2_rel_error_near_max"],
                    r["l2_rel_error_sxx_xline"], r["l2_rel_error_syy_xline"], r["l2_rel_error_sxx_yline"],
                    r["l2_rel_error_syy_yline"], r["hoop_stress_theta0_MPa"], r["hoop_stress_theta90_MPa"]) for r in table])
    plt = out.pyplot()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4))
    wt = [r["wall_time_s"] for r in table]
    ax.loglog(wt, [100 * r["l2_rel_error_max"] for r in table], "ko-", label="max L2 error, r ≥ 2a")
    ax.loglog(wt, [100 * r["l2_rel_error_near_max"] for r in table], "bs--", mfc="none", label="max L2 error, 2a ≤ r ≤ 5a")
    for r in table:
        ax.annotate(f"l = {r['grid_spacing_m']} m", (r["wall_time_s"], 100 * r["l2_rel_error_max"]), fontsize=8,
                    xytext=(4, 4), textcoords="offset points")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("relative L2 error, worst of σxx, σyy on both lines [%]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    ls = [r["grid_spacing_m"] for r in table]
    bx.plot(ls, [r["hoop_stress_theta90_MPa"] for r in table], "ro-", label="θ = 90° (MPM, extrapolated)")
    bx.plot(ls, [r["hoop_stress_theta0_MPa"] for r in table], "bo-", label="θ = 0° (MPM, extrapolated)")
    bx.axhline(3 * SXX_FAR / MPa - SYY_FAR / MPa, color="r", ls=":", label="Kirsch 3σH − σh")
    bx.axhline(3 * SYY_FAR / MPa - SXX_FAR / MPa, color="b", ls=":", label="Kirsch 3σh − σH")
    bx.set_xlabel("grid spacing l [m]")
    bx.set_ylabel("hoop stress at the wall [MPa] (compression +)")
    bx.grid(alpha=0.3)
    bx.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "convergence.png"), dpi=130)
    plt.close(fig)


def main(argv=None):
    args = parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    if args.threads:
        ym.setThreads(args.threads)
    spacings = [args.spacing]
    if args.convergence:
        spacings = sorted(set(args.convergence_spacings or default_ladder(args.spacing, args.domain)) | {args.spacing},
                          reverse=True)
    table, main_res, stopped = [], None, []
    for l in spacings:
        series = out.VtuSeries(os.path.join(args.out, "series")) if (args.vtu_every > 0 and l == args.spacing) else None
        try:
            s, res, prof, hist = run_case(l, args, f"opening l={l}", series)
        except (ym.MpmSimulationError, RuntimeError) as e:   # the solver stopped: named, the other spacings still run
            stopped.append(dict(grid_spacing_m=l, error=str(e)))
            print(f"[circular_opening] l = {l} m stopped: {e}", flush=True)
            continue
        table.append(res)
        if l == args.spacing:
            main_res, main_prof, main_hist, main_s = res, prof, hist, s
    if main_res is None:                # the main run stopped: the reason and what did run, exit status 1
        if args.convergence and table:
            write_convergence(args.out, table)
        out.write_summary(args.out, dict(case="circular opening (paper Sec. 3.1) vs Kirsch (Eqs. 41-42)", domain_m=args.domain,
                                         stopped=stopped, convergence=[dict(grid_spacing_m=r["grid_spacing_m"],
                                                                            l2_rel_error_max=r["l2_rel_error_max"]) for r in table]))
        print(f"[circular_opening] the main run (l = {args.spacing} m) stopped; wrote {args.out}/summary.json", flush=True)
        sys.exit(1)
    write_profiles(args.out, main_prof, args.spacing)
    out.write_csv(os.path.join(args.out, "relaxation.csv"), ["step", "time_s", "max_line_stress_change_rel", "kinetic_energy_J"],
                  main_hist)
    if args.vtu:
        out.write_particles(os.path.join(args.out, "particles_final.vtu"), main_s)
    if args.convergence:
        write_convergence(args.out, table)
    summary = dict(case="circular opening (paper Sec. 3.1) vs Kirsch (Eqs. 41-42)", domain_m=args.domain,
                   hole_radius_m=RADIUS, far_field_MPa=dict(sxx=SXX_FAR / MPa, syy=SYY_FAR / MPa),
                   ppc=args.ppc, damping=args.damping, courant=args.courant, boundary_load=args.boundary_load, tol=args.tol, threads=ym.getThreads(),
                   grid_shift=args.grid_shift, far_field=args.far_field,
                   kirsch_hoop_theta0_MPa=3 * SYY_FAR / MPa - SXX_FAR / MPa,
                   kirsch_hoop_theta90_MPa=3 * SXX_FAR / MPa - SYY_FAR / MPa)
    summary.update(main_res)
    summary["convergence"] = [dict(grid_spacing_m=r["grid_spacing_m"], particles=r["particles"], steps=r["steps"],
                                   wall_time_s=r["wall_time_s"], l2_rel_error_max=r["l2_rel_error_max"],
                                   l2_rel_error_near_max=r["l2_rel_error_near_max"],
                                   hoop_stress_theta0_MPa=r["hoop_stress_theta0_MPa"],
                                   hoop_stress_theta90_MPa=r["hoop_stress_theta90_MPa"]) for r in table]
    summary["stopped"] = stopped        # runs of the ladder the solver stopped (named; the others ran)
    out.write_summary(args.out, summary)
    batch.write_summary(args.out, [dict(spacing_m=args.spacing, domain_m=args.domain, ppc=args.ppc, damping=args.damping,   # a study's row
                                        boundary_load=args.boundary_load, tol=args.tol, **{k: main_res[k] for k in ROW_KEYS})])
    print(f"[circular_opening] wrote {args.out}/summary.json", flush=True)
    if stopped:
        sys.exit(1)
    return summary


ROW_KEYS = ("particles", "steps", "simulated_time_s", "converged", "l2_rel_error_max", "l2_rel_error_near_max",
            "hoop_stress_theta0_MPa", "hoop_stress_theta90_MPa")

if __name__ == "__main__":
    batch.main(main)                  # bad input: one line "circular_opening.py: error: …", exit status 2
