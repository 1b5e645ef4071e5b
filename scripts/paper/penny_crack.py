"""Penny-shaped (line) crack under internal pressure, paper Sec. 3.2 (Figs. 7–9).

Plane strain square of side L with a 2c = 0.4 m line crack at its centre, made by removing the particles
of two cell layers; the crack faces carry the pressure P as a particle traction. Three parts:

  elastic      P = 15 MPa, elastic rock, quasi-static (ramp + Cundall damping): u_y along the crack vs
               Sneddon (Eq. 43), σ ahead of the tip vs Eq. 44.
  convergence  the elastic run at several grid spacings: error against wall time.
  damage       DP–GK rock, P = 75 MPa ramped linearly: crack extension Δa(t) [cells] vs the paper's
               7, 22, 72 cells at t = 0.1, 0.2, 0.4 s; damage fields; plastic particle count.

Outer boundary (--edges, --edge-set): slip on the top and bottom faces by default — a supported block,
whose crack grows stably; "free" is the unsupported block, whose crack runs to the edge once K(a) passes
its minimum (doc/validation/penny_crack.md). Damage options map onto DpGkMat parameters: --threshold-volume
(thresholdVolume, V of Eq. 37), --damage-strain (damageStrain, Eq. 36), --threshold-cell (thresholdCell,
regularised threshold), --flaws/--flaw-seed (flawCount/flawSeed, Benz–Asphaug population).

The paper ramps P over 0.5 s (≈ 160 k steps at l = 0.02 m). The load is quasi-static (the P-wave
crosses the 5 m block in 1.5 ms), so by default the ramp is compressed to --ramp-time seconds and
results are reported on the paper's time axis t_paper = t · 0.5 s / ramp-time (= the same pressure
P(t)). `--full` runs the paper's 0.5 s ramp (hours). summary.json says which configuration ran; a run the solver
stops is named under "stopped" with its message, the other runs still run, and the exit status is 1.

    /usr/bin/python3 scripts/paper/penny_crack.py --out out/penny            # default
    /usr/bin/python3 scripts/paper/penny_crack.py --out out/penny --full     # paper time scale
    yade-batch scripts/paper/penny_crack.table scripts/paper/penny_crack.py   # a study: one run per line (doc/guide/studies.md)
"""
import argparse
import math
import os
import sys
import time

import numpy as np

import yade_mpm as ym
import yade_mpm.output as out
from yade_mpm_paper.validation import sneddon
from yade_mpm_paper.validation.line_crack import PAPER_DA, crack_extension, elastic_profiles, face_opening, interp_da, paper_comparison

from yade_mpm import rocks, runner
from yade_mpm_paper import batch, cases, uncertainty

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import penny_crack_figures as figures  # noqa: E402  (the sibling module: this script's figures)

ROCK = rocks.GRANITE                   # paper Sec. 3.2 rock (elastic part), DP–GK: rocks.GRANITE_DPGK
HALF_CRACK = cases.CRACK_HALF_LENGTH   # c [m]
PAPER_RAMP = 0.5                       # s
COURANT = ym.scene.setting_default("courant")   # --courant sets it (default: the solver's C)
SNAP_T = [0.05, 0.1, 0.2, 0.4]         # paper times of the damage-field figures [s]


def build(size, h, material, P, ramp, damping, crack_nodes="shared", edges="free", edge_set="topbottom", grid_shift=None):
    """The cracked block (yade_mpm_paper.cases.line_crack) with the outer boundary `edges` on `edge_set`;
    returns (solver, crack geometry dict). Outer boundary: grid-node planes on the block faces (free =
    none); "slip" zeroes the normal velocity, "fixed" every component; "topbottom" acts on the faces
    y = 0, L only, "all" also on x = 0, L. grid_shift: (fx, fy) fractions of a cell by which the grid is moved
    against the block (a slip or fixed face takes 0 or 0.5 along its axis)."""
    s, geo = cases.line_crack(size, h, material, P, ramp, damping, crack_nodes, HALF_CRACK, grid_shift=grid_shift)
    s.courant = COURANT
    if edges != "free":
        for axis in ((1,) if edge_set == "topbottom" else (0, 1)):
            s.addBoundaryPlane(axis, -1, 0.0, edges)
            s.addBoundaryPlane(axis, 1, size, edges)
    return s, geo


def run_elastic(size, h, P, args):
    """Quasi-static elastic run; returns a dict of profiles and errors."""
    mat = rocks.granite()
    cp = math.sqrt((mat.young * (1 - mat.poisson) / ((1 + mat.poisson) * (1 - 2 * mat.poisson))) / mat.density)
    transit = size / cp
    s, geo = build(size, h, mat, P, ramp=2 * transit, damping=args.elastic_damping, crack_nodes=args.crack_nodes,
                   edges=args.edges, edge_set=args.edge_set, grid_shift=args.grid_shift)
    t0 = time.time()
    ref = sneddon.opening_displacement(0.0, P, ROCK["young"], ROCK["poisson"], HALF_CRACK)
    hist = []

    def check(s):
        hist.append(face_opening(s, geo)[1].max())
        # converged once the load is on and the centre opening varies by < tol·u_Sneddon over the last
        # transit (4 samples, so a sample pair at the two turning points of an oscillation cannot pass)
        if s.time > 3 * transit and len(hist) >= 5 and np.ptp(hist[-5:]) < args.elastic_tol * ref:
            return runner.STOP

    runner.run(s, end_time=args.elastic_max_transits * transit, progress=args.progress, label=f"elastic h={h}",
               every=[(0.25 * transit, check)])
    wall = time.time() - t0
    prof = elastic_profiles(s, geo, P, h, HALF_CRACK, ROCK["young"], ROCK["poisson"])
    return dict(h=h, size=size, particles=s.numParticles, steps=s.steps, t=s.time, wall=wall, **prof, ke=s.kineticEnergy())


CHOICES = {p["name"]: p["choices"] for p in ym.DpGkMat.paramTable() if p["type"] == "choice"}   # named options


def damage_options(args, law):
    """DpGkMat keyword overrides of the damage run selected on the command line."""
    kw = dict(growthLaw=law, damageStrain=args.damage_strain, thresholdCell=args.threshold_cell,
              flawCount=args.flaws, flawSeed=args.flaw_seed)
    if args.threshold_volume is not None:
        kw["thresholdVolume"] = args.threshold_volume
    return kw


def run_damage(args, law, outdir):
    size, h = args.size, args.damage_spacing
    ramp = PAPER_RAMP if args.full else args.ramp_time
    scale = PAPER_RAMP / ramp                                  # t_paper = scale · t
    mat = rocks.granite_dpgk(**damage_options(args, law))
    s, geo = build(size, h, mat, args.damage_pressure, ramp=ramp, damping=args.damage_damping, crack_nodes=args.crack_nodes,
                   edges=args.edges, edge_set=args.edge_set, grid_shift=args.grid_shift)
    t_end = args.end_time / scale
    rec_dt = args.record_every / scale
    rows = []
    t0 = time.time()

    def record(s):
        left, right = crack_extension(s, geo, args.band)
        dm = s.view("damage")
        rows.append((s.time * scale, args.damage_pressure * min(1.0, s.time / ramp), left, right,
                     int(np.count_nonzero(dm >= 1)), int(np.count_nonzero(dm > 0)),
                     int(np.count_nonzero(s.view("epsP") > 0)), time.time() - t0))

    def snapshot(tp):
        def write(s):
            tag = f"{law}_t{tp:.2f}s"
            figures.damage_png(s, geo, os.path.join(outdir, f"damage_{tag}.png"),
                               f"D, growth law {law}, t_paper = {tp} s (P = {args.damage_pressure * tp / PAPER_RAMP / 1e6:.0f} MPa)")
            if args.vtu:
                out.write_particles(os.path.join(outdir, f"damage_{tag}.vtu"), s)
        return runner.Output(write, times=[tp / scale])

    n_rec = int(math.ceil(t_end / rec_dt))
    runner.run(s, end_time=t_end, progress=args.progress, label=f"damage law {law}",
               outputs=[runner.Output(record, times=np.arange(n_rec) * rec_dt, at_end=True)]
               + [snapshot(tp) for tp in SNAP_T])
    wall = time.time() - t0
    header = ["t_paper_s", "P_Pa", "da_left_cells", "da_right_cells", "broken_particles", "damaged_particles",
              "plastic_particles", "wall_s"]
    out.write_csv(os.path.join(outdir, f"crack_extension_{law}.csv"), header, rows)
    plastic = int(np.count_nonzero(s.view("epsP") > 0))
    # ε̄p is plastic strain of rock (a fully damaged particle keeps no tension, so an opening crack does not
    # yield); the second count says how many of the yielded particles are not (yet) fully cracked
    plastic_intact = int(np.count_nonzero((s.view("epsP") > 0) & (s.view("damage") < 1)))
    return dict(law=law, rows=rows, wall=wall, particles=s.numParticles, steps=s.steps, plastic=plastic,
                plastic_intact=plastic_intact,
                ramp=ramp, scale=scale, h=h, size=size)


def option_parser():
    """The command line (every option; a yade-batch / sweep table line sets the same names)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="output directory")
    ap.add_argument("--parts", default="elastic,convergence,damage", help="comma list of elastic, convergence, damage")
    ap.add_argument("--size", type=float, default=5.0, help="side of the square block L [m] (paper 5.0)")
    ap.add_argument("--spacing", type=float, default=0.04, help="grid spacing of the elastic run [m] (paper 0.02)")
    ap.add_argument("--conv-spacings", default="0.08,0.04", help="grid spacings of the convergence study [m]")
    ap.add_argument("--elastic-pressure", type=float, default=15e6, help="P of the elastic run [Pa]")
    ap.add_argument("--elastic-damping", type=float, default=0.3, help="local damping of the quasi-static elastic run")
    ap.add_argument("--elastic-tol", type=float, default=1e-3, help="stop when the centre opening varies < tol·u_Sneddon over one transit")
    ap.add_argument("--elastic-max-transits", type=float, default=60, help="time limit of the elastic run [P-wave transits of L]")
    ap.add_argument("--damage-spacing", type=float, default=0.02, help="grid spacing of the damage run [m] (paper 0.02)")
    ap.add_argument("--damage-pressure", type=float, default=75e6, help="final P of the damage run [Pa]")
    ap.add_argument("--damage-damping", type=float, default=0.05, help="local damping of the damage run")
    ap.add_argument("--ramp-time", type=float, default=0.02, help="simulated ramp time replacing the paper's 0.5 s [s]")
    ap.add_argument("--end-time", type=float, default=0.4, help="end of the damage run on the paper time axis [s]")
    ap.add_argument("--record-every", type=float, default=0.005, help="Δa record interval on the paper time axis [s]")
    ap.add_argument("--laws", default="benz-asphaug,as-printed",
                    help="damage growth laws to run (DpGkMat.growthLaw): benz-asphaug = ε̄^(m/3) (default law), as-printed = Eq. 38 as printed")
    ap.add_argument("--threshold-volume", choices=CHOICES["thresholdVolume"], default=None,
                    help="V of Eq. 37 (DpGkMat.thresholdVolume): particle = particle area × 1 m (literal), cube = dp³, "
                         "cell = l²·dp; default: the material's default (particle, doc/reference/damage_growth_law.md)")
    ap.add_argument("--damage-strain", choices=CHOICES["damageStrain"], default="uniaxial",
                    help="ε̄ of Eq. 36 (DpGkMat.damageStrain): uniaxial = σ̃max/(K + 4G/3) as printed, principal = max principal strain")
    ap.add_argument("--threshold-cell", type=float, default=0.0,
                    help="regularised threshold: ε_D⁰ of a grid of this spacing [m] scaled by √(l_ref/l) (DpGkMat.thresholdCell); 0 = off")
    ap.add_argument("--flaws", type=int, default=0, help="Benz–Asphaug flaws per particle (DpGkMat.flawCount); 0 = one threshold")
    ap.add_argument("--flaw-seed", type=int, default=0, help="seed of the flaw population (DpGkMat.flawSeed)")
    ap.add_argument("--crack-nodes", choices=("shared", "excluded"), default="shared",
                    help="grid nodes on the crack mid-line: shared by both faces (paper) or excluded from the WLS fits "
                         "(cases.line_crack's default, converges to Sneddon: doc/reference/boundaries.md)")
    ap.add_argument("--half-length", type=float, default=cases.CRACK_HALF_LENGTH, help="crack half-length c [m] (paper 0.2)")
    ap.add_argument("--edges", choices=("free", "slip", "fixed"), default="slip",
                    help="outer boundary of the block: slip (normal velocity 0, default: a supported block, "
                         "doc/validation/penny_crack.md), fixed, or free (the figure's unsupported block)")
    ap.add_argument("--edge-set", choices=("topbottom", "all"), default="topbottom",
                    help="faces the --edges condition acts on: top and bottom (y = 0, L) or all four")
    ap.add_argument("--band", type=float, default=0.2, help="half height of the band around the crack line searched for D = 1 [m]")
    ap.add_argument("--full", action="store_true", help="paper configuration: 0.5 s ramp, l = 0.02 m elastic run (hours)")
    ap.add_argument("--vtu", action="store_true", help="also write VTU particle files of the damage snapshots")
    ap.add_argument("--threads", type=int, default=0, help="OpenMP threads (0 = all)")
    ap.add_argument("--progress", type=float, default=20.0, help="progress line interval [s wall]")
    ym.scene.courant_option(ap)
    uncertainty.shift_option(ap)   # the grid moved against the block (every run)
    return ap


def parse_options(argv):
    """The checked options, the parts to run and the Courant number; a bad option exits (status 2) before any run."""
    ap = option_parser()
    a = batch.parse_args(ap, argv)    # the command line, or a yade-batch / scripts/studies/sweep.py table line
    parts = set(a.parts.split(","))
    if not parts <= {"elastic", "convergence", "damage"}:
        ap.error(f"--parts: unknown part in {a.parts}; allowed elastic, convergence, damage")
    for name in ("size", "spacing", "damage_spacing", "ramp_time", "end_time", "record_every", "band"):
        if not getattr(a, name) > 0:
            ap.error(f"--{name.replace('_', '-')} must be > 0")
    if not 0 < a.end_time <= PAPER_RAMP:
        ap.error(f"--end-time must lie in (0, {PAPER_RAMP}] s")
    if not 0 < a.half_length < a.size / 4:
        ap.error(f"--half-length must lie in (0, size/4) = (0, {a.size / 4:g}) m")
    for law in a.laws.split(","):
        if law not in CHOICES["growthLaw"]:
            ap.error(f"--laws: {law!r} is not one of {CHOICES['growthLaw']}")
    try:
        courant = ym.scene.check_courant(a.courant)
        a.grid_shift = uncertainty.parse_shift(a.grid_shift)
    except ValueError as e:
        ap.error(str(e))
    return a, parts, courant


def run_config(a):
    """summary.json's "config": which configuration ran."""
    return dict(size_m=a.size, elastic_spacing_m=a.spacing, damage_spacing_m=a.damage_spacing,
                ramp_time_s=PAPER_RAMP if a.full else a.ramp_time, paper_ramp_s=PAPER_RAMP,
                full=a.full, elastic_damping=a.elastic_damping, damage_damping=a.damage_damping,
                threshold_volume=rocks.granite_dpgk(**damage_options(a, "benz-asphaug")).thresholdVolume,
                damage_strain=a.damage_strain,
                threshold_cell_m=a.threshold_cell, flaws=a.flaws, flaw_seed=a.flaw_seed, crack_nodes=a.crack_nodes, half_length_m=a.half_length,
                edges=a.edges, edge_set=a.edge_set, grid_shift=a.grid_shift, courant=COURANT, elastic_pressure_Pa=a.elastic_pressure, damage_pressure_Pa=a.damage_pressure,
                threads=ym.getThreads())


def attempt(stopped, name, fn, *args):
    """fn(*args), or None when the solver stops it: the run is named in `stopped` with its message and the other runs still run."""
    try:
        return fn(*args)
    except (ym.MpmSimulationError, RuntimeError) as err:
        stopped.append(dict(run=name, error=str(err)))
        print(f"[penny_crack] {name} stopped: {err}", flush=True)
        return None


def write_uy(path, run):
    """The opening along the crack of an elastic run beside Sneddon's."""
    out.write_csv(path, ["x_minus_xc_m", "uy_mpm_m", "uy_sneddon_m"], zip(run["x"], run["uy"], run["ua"]))


def elastic_part(a, stopped, summary):
    """The elastic run at --spacing: profiles (CSV, figure) and errors into the summary; returns the run or None."""
    e = attempt(stopped, f"elastic l={a.spacing:g}", run_elastic, a.size, a.spacing, a.elastic_pressure, a)
    if e is None:
        return None
    write_uy(os.path.join(a.out, "elastic_uy.csv"), e)
    out.write_csv(os.path.join(a.out, "elastic_stress_ahead.csv"), ["abs_x_minus_xc_m", "syy_mpm_Pa", "sxx_mpm_Pa", "s_eq44_Pa"],
                  zip(e["xs"], e["syy"], e["sxx"], e["sa"]))
    figures.plot_elastic(e, a.out, a.elastic_pressure, HALF_CRACK, ROCK)
    summary.update(uy_center_rel_error=e["uy_centre_err"], uy_l2_rel_error=e["uy_l2"],
                   syy_ahead_l2_rel_error=e["syy_l2_far"], elastic_wall_time_s=e["wall"],
                   elastic_particles=e["particles"], elastic_steps=e["steps"], elastic_time_s=e["t"],
                   elastic_final_kinetic_energy_J=e["ke"])
    print(f"elastic l={a.spacing}: u_y centre error {e['uy_centre_err']:+.4f}, L2 {e['uy_l2']:.4f}, "
          f"σyy L2 (2 cells..1 m ahead) {e['syy_l2_far']:.4f}, wall {e['wall']:.1f} s", flush=True)
    return e


def convergence_part(a, parts, e, stopped, summary):
    """The elastic run at each --conv-spacings (the elastic part's run reused at its spacing): error against wall time."""
    conv = []
    for h in [float(v) for v in a.conv_spacings.split(",")]:
        same = "elastic" in parts and abs(h - a.spacing) < 1e-12
        c = e if same else attempt(stopped, f"convergence l={h:g}", run_elastic, a.size, h, a.elastic_pressure, a)
        if c is None:
            continue
        conv.append(c)
        write_uy(os.path.join(a.out, f"elastic_uy_l{h:g}.csv"), c)
        print(f"convergence l={h}: centre {c['uy_centre_err']:+.4f}, L2 {c['uy_l2']:.4f}, wall {c['wall']:.1f} s", flush=True)
    out.write_csv(os.path.join(a.out, "error_vs_walltime.csv"),
                  ["spacing_m", "particles", "steps", "wall_s", "uy_center_rel_error", "uy_l2_rel_error", "syy_ahead_l2_rel_error"],
                  [(c["h"], c["particles"], c["steps"], c["wall"], c["uy_centre_err"], c["uy_l2"], c["syy_l2_far"]) for c in conv])
    if conv:
        figures.plot_convergence(conv, a.out)
    summary["convergence"] = [dict(spacing_m=c["h"], particles=c["particles"], wall_time_s=c["wall"],
                                   uy_center_rel_error=c["uy_centre_err"], uy_l2_rel_error=c["uy_l2"]) for c in conv]


def damage_part(a, stopped, summary):
    """The damage run of each growth law in --laws: crack extension against the paper's Fig. 9; the first law's
    numbers also at the top level of the summary. Returns the runs."""
    results = []
    for law in a.laws.split(","):
        r = attempt(stopped, f"damage {law}", run_damage, a, law, a.out)
        if r is None:
            continue
        results.append(r)
        table = [dict(t_s=t, left=interp_da(r["rows"], t)[0], right=interp_da(r["rows"], t)[1])
                 for t in [0.05, 0.1, 0.2, 0.3, 0.4] if t <= a.end_time + 1e-9]
        summary[f"damage_{law}"] = dict(crack_extension_cells=table, plastic_particles=r["plastic"],
                                        plastic_particles_not_cracked=r["plastic_intact"],
                                        wall_time_s=r["wall"], steps=r["steps"], ramp_time_s=r["ramp"],
                                        spacing_m=r["h"], particles=r["particles"])
        if a.end_time >= PAPER_DA[-1][0] - 1e-9:
            summary[f"damage_{law}"]["paper_comparison"] = paper_comparison(r["rows"], r["h"])
        print(f"damage law {law}: " + ", ".join(f"t={d['t_s']}: {d['left']}/{d['right']}" for d in table)
              + f"; plastic {r['plastic']} (not cracked {r['plastic_intact']}); wall {r['wall']:.0f} s", flush=True)
    if results:
        figures.plot_da(results, a.out)
        first = summary[f"damage_{results[0]['law']}"]
        summary["default_law"] = results[0]["law"]
        summary["crack_extension_cells"] = first["crack_extension_cells"]
        summary["plastic_particles"] = first["plastic_particles"]
        summary["plastic_particles_not_cracked"] = first["plastic_particles_not_cracked"]
        if "paper_comparison" in first:
            summary["paper_comparison"] = first["paper_comparison"]
        summary["paper_crack_extension_cells"] = [dict(t_s=t, cells=n) for t, n in PAPER_DA]
    return results


def merged_with_earlier_parts(outdir, summary, parts, particles):
    """summary, merged with the summary.json of parts run separately into the same directory (their keys kept)."""
    old = os.path.join(outdir, "summary.json")
    if os.path.exists(old):            # parts run separately into one directory: keep the others' keys
        import json
        with open(old) as f:
            prev = json.load(f)
        prev_parts = set(prev.get("parts_run", ["elastic", "convergence", "damage"])) - parts
        if prev_parts:
            merged = {k: v for k, v in prev.items() if k not in summary}
            merged.update(summary)
            merged["config_" + "_".join(sorted(prev_parts))] = prev.get("config")
            merged["parts_run"] = sorted(parts | prev_parts)
            merged["wall_time_s"] = summary["wall_time_s"] + prev.get("wall_time_s", 0.0)
            merged["particles"] = max(particles, prev.get("particles", 0))
            summary = merged
    return summary


def main(argv=None):
    global HALF_CRACK, COURANT
    a, parts, COURANT = parse_options(argv)
    HALF_CRACK = a.half_length            # every analysis below reads the crack half-length from here
    if a.full:
        a.spacing = 0.02
    if a.threads > 0:
        ym.setThreads(a.threads)
    os.makedirs(a.out, exist_ok=True)
    summary = dict(config=run_config(a))
    wall0 = time.time()
    stopped = []                        # runs the solver stopped: named with the message, the other runs still run
    e = elastic_part(a, stopped, summary) if "elastic" in parts else None
    if "convergence" in parts:
        convergence_part(a, parts, e, stopped, summary)
    results = damage_part(a, stopped, summary) if "damage" in parts else []
    particles = max([0] + [r["particles"] for r in ([e] if e is not None else []) + results])
    summary["stopped"] = stopped
    summary["wall_time_s"] = time.time() - wall0
    summary["particles"] = particles
    summary["parts_run"] = sorted(parts)
    summary = merged_with_earlier_parts(a.out, summary, parts, particles)
    out.write_summary(a.out, summary)
    batch.write_summary(a.out, [study_row(a, parts, summary)])
    if stopped:
        print(f"[penny_crack] stopped: {', '.join(x['run'] for x in stopped)} (summary.json)", flush=True)
        sys.exit(1)
    return summary


def study_row(a, parts, s):
    """This invocation's row of OUT/summary.csv (a study's line, scripts/studies/study_report.py): parameters and results, no wall time."""
    row = dict(parts="+".join(sorted(parts)), size_m=a.size, spacing_m=a.spacing, damage_spacing_m=a.damage_spacing,
               damage_pressure_MPa=a.damage_pressure / 1e6, ramp_time_s=a.ramp_time, end_time_s=a.end_time, laws=a.laws,
               edges=a.edges, edge_set=a.edge_set, threshold_volume=s["config"]["threshold_volume"], flaws=a.flaws, flaw_seed=a.flaw_seed,
               uy_center_rel_error=s.get("uy_center_rel_error"), uy_l2_rel_error=s.get("uy_l2_rel_error"),
               syy_ahead_l2_rel_error=s.get("syy_ahead_l2_rel_error"), plastic_particles=s.get("plastic_particles"))
    for d in s.get("crack_extension_cells", []) if "damage" in parts else []:
        row[f"crack_extension_cells_left_t{d['t_s']:g}"], row[f"crack_extension_cells_right_t{d['t_s']:g}"] = d["left"], d["right"]
    return row


if __name__ == "__main__":
    batch.main(lambda: main(sys.argv[1:]))
