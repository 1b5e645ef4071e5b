"""Compare line-crack damage runs of scripts/paper/penny_crack.py with the paper's Fig. 9.

Reads `crack_extension_<growth law>.csv` and `summary.json` of each run directory and writes
  <out>.csv   one row per run: Δa at t_paper = 0.05, 0.1, 0.2, 0.3, 0.4 s in cells of the paper's grid
              (0.02 m; runs on other grids are converted through their spacing), initiation time,
              deviation from 7 / 22 / 72 cells (RMS, largest), wall time;
  <out>.png   Δa(t_paper) of every run against the paper's points;
and prints the same table as Markdown (for doc/validation/penny_crack.md).

    /usr/bin/python3 scripts/paper/penny_crack_compare.py --out doc/figures/penny_da "label a=out/run_a" "label b=out/run_b"
"""
import argparse
import json
import os
import sys

import numpy as np

import yade_mpm.output as out
from yade_mpm_paper.validation import line_crack as pc   # Fig. 9 points and Δa(t) reading, shared with penny_crack.py

TIMES = [0.05, 0.1, 0.2, 0.3, 0.4]


def load(path, law):
    with open(os.path.join(path, "summary.json")) as f:
        summ = json.load(f)
    rows = np.loadtxt(os.path.join(path, f"crack_extension_{law}.csv"), delimiter=",", skiprows=1, ndmin=2)
    h = summ[f"damage_{law}"]["spacing_m"]
    return summ, rows, h


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="output path without extension (CSV and PNG are written)")
    ap.add_argument("--law", default="benz-asphaug", help="growth law (DpGkMat.growthLaw) of the CSV to read")
    ap.add_argument("--title", default="line crack, Δa(t) against the paper's Fig. 9")
    ap.add_argument("runs", nargs="+", help="label=directory of a penny_crack.py damage run")
    a = ap.parse_args(argv)
    table, curves = [], []
    for spec in a.runs:
        if "=" not in spec:
            ap.error(f"run '{spec}' must be label=directory")
        label, path = spec.rsplit("=", 1)
        summ, rows, h = load(path, a.law)
        cells = h / pc.PAPER_CELL
        rl = [tuple(r) for r in rows]
        end = rows[-1, 0]
        da = [0.5 * sum(pc.interp_da(rl, t)) * cells if t <= end + 1e-9 else float("nan") for t in TIMES]
        init = next((r[0] for r in rows if max(r[2], r[3]) >= 1), float("nan"))
        dev = [da[TIMES.index(t)] - n for t, n in pc.PAPER_DA]
        ok = [d for d in dev if np.isfinite(d)]
        rms = float(np.sqrt(np.mean(np.square(ok)))) if ok else float("nan")
        mx = float(np.max(np.abs(ok))) if ok else float("nan")
        wall = summ[f"damage_{a.law}"]["wall_time_s"]
        table.append([label, h, summ["config"].get("ramp_time_s"), *da, init, rms, mx, wall])
        curves.append((label, rows[:, 0], 0.5 * (rows[:, 2] + rows[:, 3]) * cells))
    header = ["run", "spacing_m", "ramp_s"] + [f"da_t{t}_cells002" for t in TIMES] + [
        "initiation_t_paper_s", "rms_dev_cells", "max_abs_dev_cells", "wall_s"]
    out.write_csv(a.out + ".csv", header, table)
    plt = out.pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label, t, d in curves:
        ax.plot(t, d, "-", label=label)
    ax.plot([p[0] for p in pc.PAPER_DA], [p[1] for p in pc.PAPER_DA], "ks", ms=7, label="paper Fig. 9")
    ax.set_xlabel("t (paper time scale; P = 150 MPa/s · t) [s]")
    ax.set_ylabel("Δa [cells of 0.02 m]")
    ax.set_title(a.title, fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(a.out + ".png", dpi=130)
    plt.close(fig)
    fmt = lambda v: "–" if not np.isfinite(v) else (f"{v:.0f}" if abs(v - round(v)) < 1e-9 else f"{v:.1f}")
    print("| run | l [m] | ramp [ms] | Δa 0.05 / 0.1 / 0.2 / 0.3 / 0.4 s [0.02 m cells] | initiation [s] | RMS / max dev. | wall [s] |")
    print("|---|---|---|---|---|---|---|")
    for r in table:
        print(f"| {r[0]} | {r[1]:g} | {1e3 * r[2]:g} | {' / '.join(fmt(v) for v in r[3:8])} | {r[8]:.3f} | {fmt(r[9])} / {fmt(r[10])} | {r[11]:.0f} |")
    return table


if __name__ == "__main__":
    main(sys.argv[1:])
