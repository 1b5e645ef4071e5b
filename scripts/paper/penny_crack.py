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
from yade_mpm_paper.validation.line_crack import PAPER_CELL, PAPER_DA, crack_extension, interp_da, paper_comparison

from yade_mpm import rocks, runner
from yade_mpm_paper import batch, cases

ROCK = rocks.GRANITE                   # paper Sec. 3.2 rock (elastic part), DP–GK: rocks.GRANITE_DPGK
HALF_CRACK = cases.CRACK_HALF_LENGTH   # c [m]
PAPER_RAMP = 0.5                       # s
COURANT = ym.scene.setting_default("courant")   # --courant sets it (default: the solver's C)
SNAP_T = [0.05, 0.1, 0.2, 0.4]         # paper times of the damage-field figures [s]


def build(size, h, material, P, ramp, damping, crack_nodes="shared", edges="free", edge_set="topbottom"):
    """The cracked block (yade_mpm_paper.cases.line_crack) with the outer boundary `edges` on `edge_set`;
    returns (solver, crack geometry dict). Outer boundary: grid-node planes on the block faces (free =
    none); "slip" zeroes the normal velocity, "fixed" every component; "topbottom" acts on the faces
    y = 0, L only, "all" also on x = 0, L."""
    s, geo = cases.line_crack(size, h, material, P, ramp, damping, crack_nodes, HALF_CRACK)
    s.courant = COURANT
    if edges != "free":
        for axis in ((1,) if edge_set == "topbottom" else (0, 1)):
            s.addBoundaryPlane(axis, -1, 0.0, edges)
            s.addBoundaryPlane(axis, 1, size, edges)
    return s, geo


def face_opening(s, geo):
    """Half crack opening (u_top − u_bot)/2 per column along the crack: (x − xc, u_y)."""
    u = ym.get(s, "pos") - geo["x0"]
    t, b = geo["top"], geo["bot"]
    ot, ob = np.argsort(geo["x0"][t, 0]), np.argsort(geo["x0"][b, 0])
    x = geo["x0"][t[ot], 0] - geo["xc"]
    return x, 0.5 * (u[t[ot], 1] - u[b[ob], 1])


def run_elastic(size, h, P, args):
    """Quasi-static elastic run; returns a dict of profiles and errors."""
    mat = rocks.granite()
    cp = math.sqrt((mat.young * (1 - mat.poisson) / ((1 + mat.poisson) * (1 - 2 * mat.poisson))) / mat.density)
    transit = size / cp
    s, geo = build(size, h, mat, P, ramp=2 * transit, damping=args.elastic_damping, crack_nodes=args.crack_nodes,
                   edges=args.edges, edge_set=args.edge_set)
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
    x, uy = face_opening(s, geo)
    ua = sneddon.opening_displacement(x, P, ROCK["young"], ROCK["poisson"], HALF_CRACK)
    centre = np.argsort(np.abs(x))[:2]
    uy_centre_err = (uy[centre].mean() - ua[centre].mean()) / ua[centre].mean()
    uy_l2 = math.sqrt(np.sum((uy - ua) ** 2) / np.sum(ua ** 2))
    # σ on the crack line ahead of both tips: the two particle rows at y = yc ± dp/2
    pos, st = geo["x0"], ym.get(s, "stress")
    line = np.abs(pos[:, 1] - geo["yc"]) < geo["dp"] * 0.75
    xr = pos[line, 0] - geo["xc"]
    ahead = np.abs(xr) > HALF_CRACK
    xa = np.abs(xr[ahead])
    syy, sxx = st[line, 1][ahead], st[line, 0][ahead]
    order = np.argsort(xa)
    xa, syy, sxx = xa[order], syy[order], sxx[order]
    # mean over the 4 particles (2 rows × 2 tips) at each |x|
    xu, inv = np.unique(np.round(xa, 9), return_inverse=True)
    syy_m = np.bincount(inv, syy) / np.bincount(inv)
    sxx_m = np.bincount(inv, sxx) / np.bincount(inv)
    sa = sneddon.stress_ahead(xu, P, HALF_CRACK)
    far = (xu > HALF_CRACK + 2 * h) & (xu < HALF_CRACK + 1.0)   # beyond the smoothed tip zone
    syy_l2 = math.sqrt(np.sum((syy_m[far] - sa[far]) ** 2) / np.sum(sa[far] ** 2))
    return dict(h=h, size=size, particles=s.numParticles, steps=s.steps, t=s.time, wall=wall,
                uy_centre_err=uy_centre_err, uy_l2=uy_l2, syy_l2_far=syy_l2, x=x, uy=uy, ua=ua,
                xs=xu, syy=syy_m, sxx=sxx_m, sa=sa, ke=s.kineticEnergy())


def damage_png(s, geo, path, title, half_width=2.0, half_height=0.6):
    """Damage on the particles' initial lattice (one pixel per particle; the hole is white)."""
    plt = out.pyplot()
    x0, dmg, dp = geo["x0"], ym.get(s, "damage"), geo["dp"]
    ix, iy = np.floor(x0[:, 0] / dp).astype(int), np.floor(x0[:, 1] / dp).astype(int)
    img = np.full((iy.max() + 1, ix.max() + 1), np.nan)
    img[iy, ix] = dmg
    fig, ax = plt.subplots(figsize=(9, 3.2))
    im = ax.imshow(img, origin="lower", extent=(0, dp * img.shape[1], 0, dp * img.shape[0]), cmap="jet",
                   vmin=0, vmax=1, interpolation="nearest")
    fig.colorbar(im, ax=ax, label="damage D")
    ax.set_xlim(geo["xc"] - half_width, geo["xc"] + half_width)
    ax.set_ylim(geo["yc"] - half_height, geo["yc"] + half_height)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


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
                   edges=args.edges, edge_set=args.edge_set)
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
            damage_png(s, geo, os.path.join(outdir, f"damage_{tag}.png"),
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


def plot_elastic(e, outdir, P):
    plt = out.pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    xf = np.linspace(-HALF_CRACK, HALF_CRACK, 201)
    ax[0].plot(xf, 1e3 * sneddon.opening_displacement(xf, P, ROCK["young"], ROCK["poisson"], HALF_CRACK), "k-",
               label="Sneddon (Eq. 43)")
    ax[0].plot(e["x"], 1e3 * e["uy"], "s", mfc="none", ms=4, label=f"MPM, l = {e['h']} m")
    ax[0].set_xlabel("x − x_c [m]")
    ax[0].set_ylabel("u_y [mm]")
    ax[0].legend()
    xs = np.linspace(HALF_CRACK * 1.0005, HALF_CRACK + 1.0, 400)
    ax[1].plot(xs, sneddon.stress_ahead(xs, P, HALF_CRACK) / 1e6, "k-", label="Eq. 44")
    ax[1].plot(e["xs"], e["syy"] / 1e6, "s", mfc="none", ms=4, label="MPM σ_yy")
    ax[1].plot(e["xs"], e["sxx"] / 1e6, "o", mfc="none", ms=3, label="MPM σ_xx")
    ax[1].set_xlim(HALF_CRACK, HALF_CRACK + 1.0)
    ax[1].set_ylim(-5, 45)
    ax[1].set_xlabel("|x − x_c| [m]")
    ax[1].set_ylabel("σ [MPa]")
    ax[1].legend()
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "elastic_profiles.png"), dpi=150)
    plt.close(fig)


def plot_convergence(conv, outdir):
    plt = out.pyplot()
    fig, ax = plt.subplots(figsize=(5.5, 4))
    w = [c["wall"] for c in conv]
    ax.loglog(w, [abs(c["uy_centre_err"]) for c in conv], "o-", label="|u_y centre error|")
    ax.loglog(w, [c["uy_l2"] for c in conv], "s-", label="u_y rel. L2 error")
    for c in conv:
        ax.annotate(f"l={c['h']}", (c["wall"], c["uy_l2"]), fontsize=8)
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("relative error")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "error_vs_walltime.png"), dpi=150)
    plt.close(fig)


def plot_da(results, outdir):
    plt = out.pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    for r in results:
        t = [row[0] for row in r["rows"]]
        cells = PAPER_CELL / r["h"]
        ax.plot(t, [0.5 * (row[2] + row[3]) / cells for row in r["rows"]], "-",
                label=f"MPM, growth law {r['law']} ({'ε̄^(m/3)' if r['law'] == 'benz-asphaug' else 'ε̄^(1/3), as printed'})")
    ax.plot([p[0] for p in PAPER_DA], [p[1] for p in PAPER_DA], "ks", label="paper Fig. 9")
    ax.set_xlabel("t (paper time scale) [s]")
    ax.set_ylabel("Δa [cells of 0.02 m]")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "crack_extension.png"), dpi=150)
    plt.close(fig)


def main(argv=None):
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
    global HALF_CRACK
    HALF_CRACK = a.half_length            # every analysis below reads the crack half-length from here
    global COURANT
    try:
        COURANT = ym.scene.check_courant(a.courant)
    except ValueError as e:
        ap.error(str(e))
    if a.full:
        a.spacing = 0.02
    if a.threads > 0:
        ym.setThreads(a.threads)
    os.makedirs(a.out, exist_ok=True)
    summary = dict(config=dict(size_m=a.size, elastic_spacing_m=a.spacing, damage_spacing_m=a.damage_spacing,
                               ramp_time_s=PAPER_RAMP if a.full else a.ramp_time, paper_ramp_s=PAPER_RAMP,
                               full=a.full, elastic_damping=a.elastic_damping, damage_damping=a.damage_damping,
                               threshold_volume=rocks.granite_dpgk(**damage_options(a, "benz-asphaug")).thresholdVolume,
                               damage_strain=a.damage_strain,
                               threshold_cell_m=a.threshold_cell, flaws=a.flaws, flaw_seed=a.flaw_seed, crack_nodes=a.crack_nodes, half_length_m=a.half_length,
                               edges=a.edges, edge_set=a.edge_set, courant=COURANT, elastic_pressure_Pa=a.elastic_pressure, damage_pressure_Pa=a.damage_pressure,
                               threads=ym.getThreads()))
    wall0 = time.time()
    particles = 0
    stopped = []                        # runs the solver stopped: named with the message, the other runs still run

    def attempt(name, fn, *args):
        try:
            return fn(*args)
        except (ym.MpmSimulationError, RuntimeError) as err:
            stopped.append(dict(run=name, error=str(err)))
            print(f"[penny_crack] {name} stopped: {err}", flush=True)
            return None
    e = None
    if "elastic" in parts:
        e = attempt(f"elastic l={a.spacing:g}", run_elastic, a.size, a.spacing, a.elastic_pressure, a)
    if e is not None:
        particles = max(particles, e["particles"])
        out.write_csv(os.path.join(a.out, "elastic_uy.csv"), ["x_minus_xc_m", "uy_mpm_m", "uy_sneddon_m"],
                      zip(e["x"], e["uy"], e["ua"]))
        out.write_csv(os.path.join(a.out, "elastic_stress_ahead.csv"), ["abs_x_minus_xc_m", "syy_mpm_Pa", "sxx_mpm_Pa", "s_eq44_Pa"],
                      zip(e["xs"], e["syy"], e["sxx"], e["sa"]))
        plot_elastic(e, a.out, a.elastic_pressure)
        summary.update(uy_center_rel_error=e["uy_centre_err"], uy_l2_rel_error=e["uy_l2"],
                       syy_ahead_l2_rel_error=e["syy_l2_far"], elastic_wall_time_s=e["wall"],
                       elastic_particles=e["particles"], elastic_steps=e["steps"], elastic_time_s=e["t"],
                       elastic_final_kinetic_energy_J=e["ke"])
        print(f"elastic l={a.spacing}: u_y centre error {e['uy_centre_err']:+.4f}, L2 {e['uy_l2']:.4f}, "
              f"σyy L2 (2 cells..1 m ahead) {e['syy_l2_far']:.4f}, wall {e['wall']:.1f} s", flush=True)
    if "convergence" in parts:
        conv = []
        for h in [float(v) for v in a.conv_spacings.split(",")]:
            same = "elastic" in parts and abs(h - a.spacing) < 1e-12
            c = e if same else attempt(f"convergence l={h:g}", run_elastic, a.size, h, a.elastic_pressure, a)
            if c is None:
                continue
            conv.append(c)
            out.write_csv(os.path.join(a.out, f"elastic_uy_l{h:g}.csv"), ["x_minus_xc_m", "uy_mpm_m", "uy_sneddon_m"],
                          zip(c["x"], c["uy"], c["ua"]))
            print(f"convergence l={h}: centre {c['uy_centre_err']:+.4f}, L2 {c['uy_l2']:.4f}, wall {c['wall']:.1f} s", flush=True)
        out.write_csv(os.path.join(a.out, "error_vs_walltime.csv"),
                      ["spacing_m", "particles", "steps", "wall_s", "uy_center_rel_error", "uy_l2_rel_error", "syy_ahead_l2_rel_error"],
                      [(c["h"], c["particles"], c["steps"], c["wall"], c["uy_centre_err"], c["uy_l2"], c["syy_l2_far"]) for c in conv])
        if conv:
            plot_convergence(conv, a.out)
        summary["convergence"] = [dict(spacing_m=c["h"], particles=c["particles"], wall_time_s=c["wall"],
                                       uy_center_rel_error=c["uy_centre_err"], uy_l2_rel_error=c["uy_l2"]) for c in conv]
    results = []
    if "damage" in parts:
        for law in a.laws.split(","):
            r = attempt(f"damage {law}", run_damage, a, law, a.out)
            if r is None:
                continue
            results.append(r)
            particles = max(particles, r["particles"])
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
    if "damage" in parts and results:
        plot_da(results, a.out)
        first = summary[f"damage_{results[0]['law']}"]
        summary["default_law"] = results[0]["law"]
        summary["crack_extension_cells"] = first["crack_extension_cells"]
        summary["plastic_particles"] = first["plastic_particles"]
        summary["plastic_particles_not_cracked"] = first["plastic_particles_not_cracked"]
        if "paper_comparison" in first:
            summary["paper_comparison"] = first["paper_comparison"]
        summary["paper_crack_extension_cells"] = [dict(t_s=t, cells=n) for t, n in PAPER_DA]
    summary["stopped"] = stopped
    summary["wall_time_s"] = time.time() - wall0
    summary["particles"] = particles
    summary["parts_run"] = sorted(parts)
    old = os.path.join(a.out, "summary.json")
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
