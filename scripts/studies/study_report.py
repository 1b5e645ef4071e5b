"""One report of a study (a yade-batch table run by yade-batch or scripts/studies/sweep.py): every line's
summary.csv merged into STUDY/study.csv with the line's status (ok / failed / incomplete / not run), its
error message and wall time; STUDY/study.md (status table, failures with their messages); plots of a
result against a parameter per group (e.g. the tunnel's axial stress at 1 mm vs flaw angle per filler).
STUDY is the folder that holds the lines' folders (the table's `out`).

    /usr/bin/python3 scripts/studies/study_report.py TABLE [--plot X:Y[:GROUP,...]] ...
"""
import argparse
import csv
import json
import math
import os
import sys

from yade_mpm import output
from yade_mpm_paper import batch

# Default plots (x, y, groups), made when the study has the columns and some numbers in them. The tunnel's
# stress at 1 mm falls back to the peak when no run reached 1 mm.
DEFAULT_PLOTS = (
    ("flaw_angle_deg", "stress_MPa_at_1mm|peak_stress_MPa", ("case", "filler_mu", "grout_young_GPa")),
    ("filler_mu", "spalled_area_mm2", ("case", "flaw_angle_deg")),
    ("grout_young_GPa", "stress_MPa_at_1mm|peak_stress_MPa", ("case", "flaw_angle_deg")),
    ("mu_con", "peak_stress_MPa", ("variant", "c_con_MPa")),
    ("spacing_m", "l2_rel_error_max", ("boundary_load",)),
    ("flaws", "crack_extension_cells_left_t0.4", ("edges",)),
)
FIRST = ("line", "description", "status", "message", "wall_time_s", "host")


def line_status(run_dir):
    """(status, message, job dict) of a line's folder."""
    job = {}
    if os.path.exists(os.path.join(run_dir, batch.JOB)):
        with open(os.path.join(run_dir, batch.JOB)) as f:
            job = json.load(f)
    if os.path.exists(os.path.join(run_dir, batch.SUMMARY)):
        return "ok", "", job
    if os.path.exists(os.path.join(run_dir, batch.ERROR)):
        with open(os.path.join(run_dir, batch.ERROR)) as f:
            msg = f.read().strip()
        return ("interrupted" if msg.startswith("interrupted") else "failed"), msg, job
    return ("incomplete" if os.path.isdir(run_dir) else "not run"), "", job


def merge(table):
    """Rows of the study: one per summary row of each line (one row for a line without a summary)."""
    rows = []
    for ln, desc, run_dir in batch.lines(table):
        status, msg, job = line_status(run_dir)
        head = dict(line=ln, description=desc, status=status, message=msg, wall_time_s=job.get("wall_time_s"), host=job.get("host"))
        rows += [dict(head, **{k: batch.literal(v) for k, v in r.items()}) for r in batch.read_summary(run_dir)] or [head]
    return rows


def _num(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def plot(rows, x, ys, groups, path):
    """y (first of `ys`, '|'-separated, with numbers) vs x, one line per group; False when nothing to plot."""
    ok = [r for r in rows if r["status"] == "ok" and _num(r.get(x))]
    y = next((c for c in ys.split("|") if any(_num(r.get(c)) for r in ok)), None)
    if y is None:
        return False
    ok = [r for r in ok if _num(r.get(y))]
    plt = output.pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.3))
    keys = {}
    for r in ok:
        label = ", ".join(f"{g} = {r[g]}" if g not in ("case", "variant", "edges", "boundary_load") else str(r[g])
                          for g in groups if r.get(g) not in (None, ""))
        keys.setdefault(label, []).append((r[x], r[y]))
    for label, pts in sorted(keys.items()):
        pts.sort()
        ax.plot(*zip(*pts), "o-", lw=1.2, ms=4, label=label or "all")
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title(f"{y} vs {x}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def write(table, plots=None, folder=None):
    """Writes study.csv, study.md and the plots into the study folder; returns their paths."""
    rows = merge(table)
    folder = folder or os.path.commonpath([os.path.abspath(os.path.dirname(r)) for _, _, r in batch.lines(table)])
    os.makedirs(folder, exist_ok=True)
    keys = list(FIRST) + [k for k in dict.fromkeys(k for r in rows for k in r) if k not in FIRST]
    csv_path = os.path.join(folder, "study.csv")
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(keys)
        for r in rows:
            w.writerow(["" if r.get(k) is None else (repr(r[k]) if isinstance(r[k], float) else r[k]) for k in keys])
    made = []
    for x, ys, groups in plots or DEFAULT_PLOTS:
        name = f"study_{ys.split('|')[0]}_vs_{x}.png".replace("/", "_")
        if plot(rows, x, ys, groups, os.path.join(folder, name)):
            made.append(os.path.join(folder, name))
    lines = {}
    for r in rows:
        lines.setdefault(r["line"], r)
    count = {s: sum(1 for r in lines.values() if r["status"] == s) for s in ("ok", "failed", "interrupted", "incomplete", "not run")}
    md = [f"# Study {os.path.basename(table)}", "",
          f"{len(lines)} lines: " + ", ".join(f"{n} {s}" for s, n in count.items() if n), "",
          "| line | description | status | wall [s] | message |", "|---|---|---|---|---|"]
    for r in lines.values():
        md.append(f"| {r['line']} | {r['description']} | {r['status']} | {'' if r['wall_time_s'] is None else round(r['wall_time_s'], 1)} | "
                  f"{r['message'].splitlines()[0] if r['message'] else ''} |")
    md += ["", "Merged rows: study.csv. Plots: " + (", ".join(os.path.basename(p) for p in made) or "none (no numbers to plot)")]
    md_path = os.path.join(folder, "study.md")
    with open(md_path, "w") as f:
        f.write("\n".join(md) + "\n")
    return [csv_path, md_path] + made


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("table", help="the study's parameter table")
    ap.add_argument("--plot", action="append", default=None,
                    help="X:Y[:GROUP,...] (columns of study.csv; Y may be A|B = the first with numbers); repeatable")
    ap.add_argument("--folder", default=None, help="where to write (default: the folder holding the lines' folders)")
    a = ap.parse_args(argv)
    plots = None
    if a.plot:
        plots = []
        for p in a.plot:
            parts = p.split(":")
            if len(parts) not in (2, 3):
                ap.error(f"--plot {p!r} must be X:Y or X:Y:GROUP,...")
            plots.append((parts[0], parts[1], tuple(parts[2].split(",")) if len(parts) == 3 else ()))
    paths = write(a.table, plots, a.folder)
    print(open(paths[1]).read())
    print("written: " + ", ".join(paths))


if __name__ == "__main__":
    sys.exit(main())
