"""Uniaxial compression of a sandstone specimen with an open or rigid-filled flaw (paper Sec. 3.3,
Figs. 10–15): 50 × 150 mm Miao (2018) sandstone (DP–GK), a 25 × 2 mm flaw inclined 30° at the centre,
a rigid YADE platen pushed down at 0.1 m/s, free-slip top and bottom. The scene is
``yade_mpm_paper.cases.uniaxial_flaw``; the filler is a free YADE Box in PTS contact (μ_con, c_con).

Runs (default: all): intact; open flaw; filled flaw with μ_con ∈ {0, 0.2, 0.4, 0.6, 0.8} (c_con = 0) and
c_con ∈ {0, 1, 5, 10} MPa (μ_con = 0). Each run writes OUT/runs/NAME/: curve.csv (axial strain, axial
stress = platen reaction / width), particles.pvd + .vtu series, snapshots.npz, run.json. Then the
summary: OUT/summary.json (`runs`: variant, mu_con, c_con_MPa, peak_stress_MPa, strain_at_peak,
youngs_modulus_GPa, wall_time_s, particles, steps, particle_steps_per_s), curves.csv, peaks.md,
curves_mu.png and curves_c.png (with open and intact), damage_plastic_NAME.png at t = 1, 2, 3, 4 ms,
sigma_max_open_vs_filled.png.

    PYTHONPATH=py /usr/bin/python3 scripts/paper/uniaxial_flaw.py [--out DIR] [--paper | --spacing L]
        [--runs intact,open,filled:0.4:0] [--end-time T] [--summary-only]
    yade-batch scripts/paper/uniaxial_flaw.table scripts/paper/uniaxial_flaw.py    # one job per line, OUT/<description>/
    /usr/bin/python3 scripts/studies/sweep.py scripts/paper/uniaxial_flaw.table scripts/paper/uniaxial_flaw.py   # the same on Dask

Each invocation also writes OUT/summary.csv, one row per run (doc/guide/studies.md).
"""
import argparse
import json
import os
import sys
import time

import numpy as np

import yade_mpm as ym
from yade_mpm import analysis, output, runner
from yade_mpm_paper import batch, cases, fidelity, uncertainty
from yade_mpm_paper.cases import uniaxial_results as results
from yade_mpm_paper.cases.uniaxial_results import find_run as _find, read_curve as _curve, read_snapshot as _snap

DEFAULT_SPACING = 2.0e-3       # coarse default grid [m]: the whole set in < 15 min on 2 idle cores
END_TIME = 0.014               # simulated loading time [s] (1.4 mm of platen travel); runs stop earlier once softened
SNAP_TIMES = (1e-3, 2e-3, 3e-3, 4e-3)
MU_SWEEP = (0.0, 0.2, 0.4, 0.6, 0.8)
C_SWEEP_MPA = (0.0, 1.0, 5.0, 10.0)
DEFAULT_OUT = "out/uniaxial_flaw"


def all_runs():
    runs = [("intact", 0.0, 0.0), ("open", 0.0, 0.0)]
    runs += [("filled", mu, 0.0) for mu in MU_SWEEP]
    runs += [("filled", 0.0, c) for c in C_SWEEP_MPA if c != 0.0]
    return runs


def parse_runs(text):
    out = []
    for item in text.split(","):
        parts = item.strip().split(":")
        if parts[0] not in cases.UNIAXIAL_VARIANTS:
            raise ValueError(f"--runs: variant {parts[0]!r} must be one of {cases.UNIAXIAL_VARIANTS}")
        mu = float(parts[1]) if len(parts) > 1 else 0.0
        c = float(parts[2]) if len(parts) > 2 else 0.0
        out.append((parts[0], mu, c))
    return out


def parse(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default=DEFAULT_OUT, help="output folder (default %(default)s)")
    p.add_argument("--paper", action="store_true", help="the paper's grid, 0.5 mm (slow)")
    p.add_argument("--spacing", type=float, default=None, help=f"grid spacing [m] (default {DEFAULT_SPACING})")
    p.add_argument("--end-time", type=float, default=END_TIME, help="loading time [s] (default %(default)s)")
    p.add_argument("--runs", default=None, help="subset, e.g. intact,open,filled:0.4:0 (variant:mu_con:c_con_MPa)")
    p.add_argument("--vtu-every", type=float, default=1e-3, help="VTU period [s] (default %(default)s)")
    p.add_argument("--progress", type=float, default=30.0, help="wall seconds between progress lines")
    ym.scene.courant_option(p)                      # default: the solver's C (pkg-mpm/core/SolverSettings.hpp)
    p.add_argument("--summary-only", action="store_true", help="only collect OUT/runs/*/run.json (and a study's OUT/*/runs/*/run.json) "
                   "into the summary")
    uncertainty.shift_option(p)
    p.add_argument("--filler-blocked-dofs", default="zXY", help="blockedDOFs of the filler (default %(default)s: free in the "
                   "plane; zXYZ: no rotation)")
    a = batch.parse_args(p, argv)     # the command line, or a yade-batch / scripts/studies/sweep.py table line
    if a.paper and a.spacing is not None:
        p.error("--paper and --spacing exclude each other")
    a.spacing = cases.UNIAXIAL_PAPER_SPACING if a.paper else (a.spacing or DEFAULT_SPACING)
    if not (a.spacing > 0 and a.end_time > 0 and a.vtu_every > 0):
        p.error("--spacing, --end-time and --vtu-every must be > 0")
    a.run_list = parse_runs(a.runs) if a.runs else all_runs()
    try:
        a.courant = ym.scene.check_courant(a.courant)
        a.grid_shift = uncertainty.parse_shift(a.grid_shift)
    except ValueError as e:
        p.error(str(e))
    return a


# ------------------------------------------------------------------------------------------------ one run
def one_run(variant, mu, c_mpa, a):
    from yade import O
    name = results.run_name(variant, mu, c_mpa)
    d = os.path.join(a.out, "runs", name)
    os.makedirs(d, exist_ok=True)
    s, sc = cases.uniaxial_flaw(variant, a.spacing, mu_con=mu, c_con=c_mpa * 1e6, label="mpm_" + name.replace(".", "_"),
                                filler_blocked=a.filler_blocked_dofs, grid_shift=a.grid_shift)
    step_options = ym.scene.apply_step_options(s, a)
    snaps = {}
    snapshot = results.field_snapshots(snaps, ("pos", "damage", "plastic_strain", "max_principal_stress"))
    lattice = analysis.Lattice(ym.get(s, "pos"), s.spacing / 2, origin=(0, 0))   # ppc = 2, for the crack analytics
    snap_times = sorted(set(SNAP_TIMES) | {k * 0.5e-3 for k in range(1, int(a.end_time / 0.5e-3) + 1)})
    fl = sc["flaw"]                                # crack sequence at the flaw ends (Fig. 11b), every 25 steps
    times = fidelity.CrackTimes(lattice, fl["toe"], fl["tip"], analysis.softening_end(s), 2 * a.spacing) if fl else None
    watch = [runner.Output(times.update, steps=25)] if times else []
    r = results.compression_run(s, sc, d, a.end_time, a.progress, name, snapshot, dict(times=snap_times),
                                dict(period=a.vtu_every, at_end=True), watch)
    wall, t, eps, sig, k, E = r["wall_s"], r["t"], r["eps"], r["sig"], r["peak"], r["E"]
    np.savez_compressed(os.path.join(d, "snapshots.npz"), **snaps)
    # cracks and shear bands at the end (yade_mpm.analysis); σ̃max within 2 particle rows of the flaw (Figs. 14–15)
    try:
        end = results.end_analytics(s, lattice, fl, snaps, a.spacing)
    except (ym.MpmSimulationError, RuntimeError, ValueError) as e:   # the run keeps its curve and peak; the reason is recorded
        print(f"[{name}] end analytics failed: {e}", flush=True)
        end = dict.fromkeys(("damaged_fraction_end", "cracks_end", "shear_bands_end", "near_flaw_sigma_max", "flaw_end_cracks_end"))
        end["error"] = str(e)
    entry = dict(variant=variant, mu_con=mu, c_con_MPa=c_mpa, **results.peak_fields(t, eps, sig, k, E),
                 wall_time_s=wall, particles=int(s.numParticles), steps=int(s.steps),
                 particle_steps_per_s=s.numParticles * s.steps / wall, end_reason=r["result"].reason,
                 error=getattr(r["result"], "error", None), time_reached_s=float(t[-1]),
                 softened=bool(r["result"].reason == "stop"), spacing_m=a.spacing, **step_options, grid_shift=a.grid_shift,
                 filler_motion=results.filler_motion(O.bodies[sc["filler"]]) if sc["filler"] is not None else None,
                 **{q: end[q] for q in ("damaged_fraction_end", "cracks_end", "shear_bands_end")},
                 crack_times=times.result() if times else None, near_flaw_sigma_max=end["near_flaw_sigma_max"],
                 plastic_before_peak=results.plastic_before(snaps, t[k]), flaw_end_cracks_end=end["flaw_end_cracks_end"],
                 removed_particles=int(ym.removed(s)["count"]), removed_mass_kg=float(ym.removed(s)["mass"]),   # debris off the grid
                 end_analytics_error=end.get("error"))
    with open(os.path.join(d, "run.json"), "w") as f:
        json.dump(entry, f, indent=1)
    print(f"[{name}] peak {entry['peak_stress_MPa']:.2f} MPa at ε = {entry['strain_at_peak']:.4g}, E = {entry['youngs_modulus_GPa']:.2f} GPa, "
          f"{s.steps} steps, {wall:.0f} s, {entry['particle_steps_per_s'] / 1e6:.2f} M particle-steps/s", flush=True)
    return entry


# ------------------------------------------------------------------------------------------------ summary
def sweep_png(runs, out, key, values, fname, title):
    plt = output.pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for v, style in ((_find(runs, "intact"), "k-"), (_find(runs, "open"), "k--")):
        if v is not None:
            e, s = _curve(v)
            ax.plot(e * 1e3, s, style, lw=1.5, label=v["variant"])
    cmap = plt.get_cmap("viridis")
    for i, val in enumerate(values):
        v = _find(runs, "filled", **({"mu": val} if key == "mu" else {"c": val}))
        if v is None:
            continue
        e, s = _curve(v)
        lab = f"filled, μ_con = {val:g}" if key == "mu" else f"filled, c_con = {val:g} MPa"
        ax.plot(e * 1e3, s, color=cmap(i / max(1, len(values) - 1)), lw=1.2, label=lab)
    ax.set_xlabel("axial strain [‰]")
    ax.set_ylabel("axial stress [MPa]")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, fname), dpi=130)
    plt.close(fig)


def damage_png(e, out):
    if not results.has_snapshots(e):
        return
    plt = output.pyplot()
    fig, axs = plt.subplots(2, len(SNAP_TIMES), figsize=(2.2 * len(SNAP_TIMES), 9.5), sharey=True)
    for j, t in enumerate(SNAP_TIMES):
        tt, a = _snap(e, t)
        for i, (col, lab, vmax) in enumerate(((2, "damage D", 1.0), (3, "plastic strain ε̄p", None))):
            ax = axs[i, j]
            sc = ax.scatter(a[:, 0] * 1e3, a[:, 1] * 1e3, c=a[:, col], s=1.5, cmap="inferno_r", vmin=0,
                            vmax=vmax or max(1e-6, a[:, col].max()))
            ax.set_aspect("equal")
            ax.set_title(f"{lab}\nt = {tt * 1e3:.1f} ms", fontsize=8)
            ax.set_xlabel("x [mm]")
            if j == 0:
                ax.set_ylabel("y [mm]")
            fig.colorbar(sc, ax=ax, shrink=0.6)
    fig.suptitle(f"{os.path.basename(e['dir'])}: damage (top) and plastic strain (bottom)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"damage_plastic_{os.path.basename(e['dir'])}.png"), dpi=110)
    plt.close(fig)


def sigma_png(runs, out):
    op, fi = _find(runs, "open"), _find(runs, "filled", mu=0.4) or _find(runs, "filled")
    if op is None or fi is None or not (results.has_snapshots(op) and results.has_snapshots(fi)):
        return None
    plt = output.pyplot()
    t = op["time_at_peak_s"]
    fig, axs = plt.subplots(1, 2, figsize=(7, 9), sharey=True)
    lim = None
    for ax, e in zip(axs, (op, fi)):
        tt, a = _snap(e, t)
        s = a[:, 4] / 1e6             # σ̃max: maximum principal stress carried (damaged), tension positive
        lim = lim or np.percentile(np.abs(s), 99)
        sc = ax.scatter(a[:, 0] * 1e3, a[:, 1] * 1e3, c=s, s=1.5, cmap="coolwarm", vmin=-lim, vmax=lim)
        ax.set_aspect("equal")
        ax.set_title(f"{os.path.basename(e['dir'])}\nσ̃max at t = {tt * 1e3:.1f} ms [MPa]", fontsize=9)
        ax.set_xlabel("x [mm]")
        fig.colorbar(sc, ax=ax, shrink=0.6)
    axs[0].set_ylabel("y [mm]")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "sigma_max_open_vs_filled.png"), dpi=110)
    plt.close(fig)
    return t


def summarize(out):
    runs = results.load_runs(out)
    if not runs:
        print(f"no runs under {out}/runs")
        return None
    for e in runs:                                 # records from before reaction spikes were told apart
        if results.rescore(e):
            print(f"{e['dir']}: peak and modulus derived again from curve.csv (reaction spikes: {e['reaction_spikes']})")
    sweep_png(runs, out, "mu", MU_SWEEP, "curves_mu.png", "filled flaw, c_con = 0 (Fig. 13a-like)")
    sweep_png(runs, out, "c", C_SWEEP_MPA, "curves_c.png", "filled flaw, μ_con = 0 (Fig. 13b-like)")
    for e in runs:
        damage_png(e, out)
    t_sig = sigma_png(runs, out)
    keys = results.SUMMARY_KEYS
    results.sort_runs(runs)
    output.write_csv(os.path.join(out, "peaks.csv"), keys, [[e[k] for k in keys] for e in runs])
    long = []
    for e in runs:                                 # every curve in one file (every 10th recorded step)
        eps, sig = _curve(e)
        long += [[os.path.basename(e["dir"]), a, b] for a, b in zip(eps[::10], sig[::10])]
    output.write_csv(os.path.join(out, "curves.csv"), ["run", "axial_strain", "axial_stress_MPa"], long)
    with open(os.path.join(out, "peaks.md"), "w") as f:
        f.write(results.peaks_markdown(runs))
    summary = results.summary(runs, t_sig)
    summary["stopped"] = [f"{os.path.basename(e['dir'])}: {e.get('error')}" for e in runs if e.get("end_reason") == "error"]
    output.write_summary(out, summary)
    print(open(os.path.join(out, "peaks.md")).read())
    return summary


def main(argv=None):
    a = parse(argv)
    if not a.summary_only:
        t0 = time.time()
        entries = [one_run(variant, mu, c, a) for variant, mu, c in a.run_list]
        print(f"all runs: {time.time() - t0:.0f} s wall")
    summarize(a.out)
    if not a.summary_only:                         # a study's rows (scripts/studies/study_report.py): no wall times
        batch.write_summary(a.out, [dict({k: e[k] for k in results.ROW_KEYS}, end_time_s=a.end_time) for e in entries])
        stopped = [results.run_name(e["variant"], e["mu_con"], e["c_con_MPa"]) for e in entries if e["end_reason"] == "error"]
        if stopped:                                # every run ran; the ones the solver stopped are named
            print(f"stopped by the solver in: {', '.join(stopped)} (outputs written up to the stop)", file=sys.stderr)
            sys.exit(1)


if __name__ == "__main__":
    batch.main(lambda: main(sys.argv[1:]))
