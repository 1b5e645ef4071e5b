#!/usr/bin/python3
"""Stability suite (issue 3, part 3): small scenes that push the explicit WLS-MPM step to its limits.

The scenes live in yade_mpm_paper.validation.stability_cases, the per-step checks (finite state, energy bound,
Δt within the stable limit, clear stop messages) in yade_mpm_paper.validation.stability; this script runs them
and writes the table and plots.

Usage: /usr/bin/python3 scripts/paper/stability.py --out DIR [--fast] [--cases a,b]
Writes DIR/summary.json ("cases": list of {case, outcome, nan_seen, max_energy_ratio, steps,
wall_time_s, message, ...}), DIR/stability_table.csv, DIR/energy_ratio.png and prints the table.
"""
import argparse
import os
import sys

import numpy as np
import yade_mpm as ym
from yade_mpm_paper.validation.stability import ENERGY_FLOOR, ENERGY_TOL, run_case
from yade_mpm_paper.validation.stability_cases import CASES


def print_table(rows, stream=sys.stdout):
    head = (f"{'case':22s} {'steps':>7s} {'max E ratio':>11s} {'dt/lim':>7s} {'dt/lim1':>7s} {'outcome':20s} {'NaN':>4s} "
            f"{'wall [s]':>8s} {'removed (expected)':>22s}  pass")
    print(head, file=stream)
    print("-" * len(head), file=stream)
    for r in rows:
        print(f"{r['case']:22s} {r['steps']:7d} {r['max_energy_ratio']:11.4f} {r['max_dt_over_stable']:7.4f} "
              f"{r['max_dt_over_paper_limit_after_step']:7.4f} "
              f"{r['outcome']:20s} {'yes' if r['nan_seen'] else 'no':>4s} {r['wall_time_s']:8.2f} "
              f"{str(r.get('removed_particles', 0)) + ' (' + r.get('removed_expected', 'none') + ')':>22s}  "
              f"{'ok' if r['passed'] else 'FAIL'}", file=stream)
    print("removed: particles removed after leaving the grid (Solver.outside = 'remove-debris'), against the case's expectation",
          file=stream)
    print("dt/lim: max Δt / stableDt() before the step (C = s.courant); dt/lim1: max Δt / (l/(v_c + max‖v‖)) after "
          "the step (paper's limit, C = 1)", file=stream)
    for r in rows:
        if r["message"]:
            print(f"  {r['case']}: {r['message']}", file=stream)


def plot_ratios(path, hists):
    import yade_mpm.output as out
    plt = out.pyplot()
    fig, ax = plt.subplots(figsize=(8, 5))
    for name, h in hists.items():
        if len(h["ratio"]):
            ax.plot(np.arange(1, len(h["ratio"]) + 1) / len(h["ratio"]), h["ratio"], label=name, lw=1)
    ax.axhline(1 + ENERGY_TOL, color="k", ls="--", lw=0.8, label=f"1 + tol ({ENERGY_TOL})")
    ax.set_xlabel("fraction of the run (steps)")
    ax.set_ylabel("(KE + U_el) / (E0 + W_ext)")
    ax.set_ylim(0, 1.2)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_final_states(path, hists):
    """Particles at the end of each case (coloured by damage for DP–GK, else plain)."""
    import yade_mpm.output as out
    plt = out.pyplot()
    n = len(hists)
    cols = min(3, n)
    rows = (n + cols - 1) // cols
    fig, axs = plt.subplots(rows, cols, figsize=(4 * cols, 3.6 * rows), squeeze=False)
    for ax, (name, h) in zip(axs.flat, hists.items()):
        p = h["pos"]
        if h["damage"] is not None:
            ax.scatter(p[:, 0], p[:, 1], s=1, c=h["damage"], cmap="viridis", vmin=0, vmax=1)
        else:
            ax.scatter(p[:, 0], p[:, 1], s=1, color="tab:blue")
        ax.set_aspect("equal")
        ax.set_title(name, fontsize=9)
    for ax in list(axs.flat)[n:]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True, help="output directory")
    ap.add_argument("--fast", action="store_true", help="coarse grids (the test-suite versions)")
    ap.add_argument("--threads", type=int, default=1,
                    help="OpenMP threads (default 1: the cases are small, and spinning threads on a loaded machine distort wall times)")
    ap.add_argument("--courant", type=float, default=None, help="Courant number C for every case (default: solver's 0.5)")
    ap.add_argument("--cases", default="", help="comma-separated subset of: " + ", ".join(CASES))
    args = ap.parse_args(argv)
    names = [c for c in args.cases.split(",") if c] or list(CASES)
    for n in names:
        if n not in CASES:
            ap.error(f"unknown case '{n}'; choose from {', '.join(CASES)}")
    import yade_mpm.output as out
    ym.setThreads(args.threads)
    rows, hists = [], {}
    for n in names:
        build, desc = CASES[n]
        print(f"== {n}: {desc}", flush=True)
        r, h = run_case(n, build, fast=args.fast, courant=args.courant)
        r["description"] = desc
        rows.append(r)
        hists[n] = h
        out.write_csv(os.path.join(args.out, f"energy_{n}.csv"), ["t_s", "KE_plus_Uel_J", "E0_plus_Wext_J", "ratio", "dt_over_stable"],
                      zip(h["t"], h["total"], h["input"], h["ratio"], h["dt_ratio"]))
    print()
    print_table(rows)
    out.write_csv(os.path.join(args.out, "stability_table.csv"),
                  ["case", "steps", "max_energy_ratio", "max_dt_over_stable", "outcome", "nan_seen", "wall_time_s", "removed_particles",
                   "removed_mass_kg", "momentum_error_rel", "passed"],
                  [[r["case"], r["steps"], r["max_energy_ratio"], r["max_dt_over_stable"], r["outcome"], r["nan_seen"],
                    r["wall_time_s"], r["removed_particles"], r["removed_mass_kg"], r.get("momentum_error_rel", ""), r["passed"]] for r in rows])
    plot_ratios(os.path.join(args.out, "energy_ratio.png"), hists)
    plot_final_states(os.path.join(args.out, "final_states.png"), hists)
    out.write_summary(args.out, {
        "energy_ratio_definition": "max over steps of (KE + U_el) / max(E0 + W_ext, %g * max_steps(E0 + W_ext)); "
                                   "KE from particle velocities, U_el = sum V (s:s/4G + p^2/2K) of the carried stress, "
                                   "W_ext = work of gravity and surface forces on the particles" % ENERGY_FLOOR,
        "energy_tol": ENERGY_TOL,
        "fast": args.fast,
        "threads": args.threads,
        "all_passed": all(r["passed"] for r in rows),
        "cases": rows,
    })
    return 0 if all(r["passed"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
