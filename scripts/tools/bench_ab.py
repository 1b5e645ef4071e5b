#!/usr/bin/python3
"""Speed of two (or more) builds of the core, measured in turn on a shared host (issue 7).

Builds are compared as ratios within one run: for each case and thread count the builds run one after
the other, repeat after repeat, in rotating order (A B C, C B A, B C A, …), so a change of host load hits
them alike. Each run is a fresh subprocess with PYTHONPATH set to the build's py/ directory.

Cases: the benchmark scenes of scripts/tools/bench.py (run through that build's own bench.py child, same
scene and steps: elastic2d_80k, dpgk2d_80k, …), and `free_elastic` / `free_dpgk`, the same 200 × 100-cell
block with no boundary plane at all (no one-sided fits, no mirror folds) and the DP–GK parameters of the
benchmark with V = particle volume in Eq. 37, built with calls every build since issue 4 has — so that
an old and a new build run the same code paths and physics; `tunnel_paper` / `tunnel_2mm`, the paper's arch
tunnel (cases.arch_tunnel "intact", 1 mm / 2 mm grid) stepped through YADE with its rigid platen, as
scripts/paper/tunnel_spalling.py runs it (builds with cases.arch_tunnel only).

    git -C . worktree add /tmp/wt-before before-session        # build it there: cmake -S . -B build && cmake --build build
    flock /work/bench.lock /usr/bin/python3 scripts/tools/bench_ab.py --out out/ab \\
        before=/tmp/wt-before/py now=py --cases elastic2d_80k,dpgk2d_80k,free_elastic,free_dpgk --threads 1,2

Writes OUT/summary.json and OUT/table.md: medians of particle-steps per wall second and per CPU second
(all threads; less sensitive to time-slicing), each build's ratio to the first, the phases of the median
run, and the host load averages."""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))

FREE_CHILD = r'''
import json, time, yade_mpm as ym
rock = ROCK                                                    # rocks.GRANITE or GRANITE_DPGK of this repository
if "frictionAngle" not in rock:
    mat = ym.ElasticMat(**rock)
else:
    try:
        mat = ym.DpGkMat(**rock)
    except TypeError:                                          # builds before issue 7: the paper's dilatancyAngle
        rock["dilatancyAngle"] = rock.pop("dilationAngle")
        mat = ym.DpGkMat(**rock)
    if hasattr(mat, "thresholdVolume"):
        mat.thresholdVolume = "particle" if isinstance(mat.thresholdVolume, str) else 0   # V = particle volume (old builds: code 0)
s = ym.make_solver((0.0, 0.0), (2.0, 1.0), 0.01, margin=3)
ym.add_region(s, mat, (0.0, 0.0), (2.0, 1.0), ppc=2)
x0, x1 = s.view("x0"), s.view("x1")
s.view("v0")[:] = 40.0 * (x0 - 1.0)                            # the benchmark's pure shear, ε̇ = 40/s
s.view("v1")[:] = -40.0 * (x1 - 0.5)
del x0, x1
s.run(WARMUP)
s._resetPhaseTimes()
c0, t0 = time.process_time(), time.perf_counter()
s.run(STEPS)
wall, cpu = time.perf_counter() - t0, time.process_time() - c0
print("BENCH " + json.dumps(dict(steps=STEPS, wall=wall, cpu=cpu, particles=s.numParticles, phases=s._phaseTimes())))
'''
FREE_STEPS = (250, 20)

# The paper's tunnel (Sec. 4) as scripts/paper/tunnel_spalling.py runs it: cases.arch_tunnel in YADE (rigid platen in PTS
# contact, MpmEngine, O.step), timed over a few hundred steps from the start (little damage yet).
TUNNEL_CHILD = r'''
import json, time, yade_mpm as ym
from yade_mpm_paper import cases
from yade import O
s, b = cases.arch_tunnel("intact", SPACING)
for _ in range(WARMUP):
    O.step()
s._resetPhaseTimes()
c0, t0 = time.process_time(), time.perf_counter()
for _ in range(STEPS):
    O.step()
wall, cpu = time.perf_counter() - t0, time.process_time() - c0
print("BENCH " + json.dumps(dict(steps=STEPS, wall=wall, cpu=cpu, particles=s.numParticles, phases=s._phaseTimes())))
'''
TUNNEL_CASES = {"tunnel_paper": (0.001, 200, 20), "tunnel_2mm": (0.002, 400, 20)}   # spacing [m], timed and warm-up steps


def run_one(case, build, threads):
    """One timed run of `case` with build (name, pydir, benchpy) and `threads` OpenMP threads."""
    _, pydir, benchpy = build
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), OMP_PROC_BIND="false", PYTHONPATH=pydir)
    if case in TUNNEL_CASES:
        sp, steps, warm = TUNNEL_CASES[case]
        code = TUNNEL_CHILD.replace("SPACING", repr(sp)).replace("WARMUP", str(warm)).replace("STEPS", str(steps))
        cmd = [sys.executable, "-c", code]
    elif case.startswith("free_"):
        sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "py"))
        from yade_mpm import rocks                                # the parameter sets, written once
        rock = dict(elastic=rocks.GRANITE, dpgk=rocks.GRANITE_DPGK)[case[5:]]
        code = FREE_CHILD.replace("ROCK", repr(dict(rock))).replace("WARMUP", str(FREE_STEPS[1])).replace("STEPS", str(FREE_STEPS[0]))
        cmd = [sys.executable, "-c", code]
    else:
        sys.path.insert(0, HERE)
        from bench_scenes import CASES                            # timed and warm-up steps of the case
        cmd = [sys.executable, benchpy, "--child", "--mode", "direct", "--case", case, "--steps", str(CASES[case][3]),
               "--warmup", str(CASES[case][4])]
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    line = [l for l in r.stdout.splitlines() if l.startswith("BENCH ")]
    if r.returncode or not line:
        raise RuntimeError(f"{case} with {pydir}, {threads} threads failed:\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}")
    return json.loads(line[0][6:])


def parse_build(text):
    name, sep, pydir = text.partition("=")
    if not sep or not name or not os.path.isdir(pydir):
        raise ValueError(f"build {text!r} must be NAME=PYDIR with PYDIR a directory holding yade_mpm")
    pydir = os.path.abspath(pydir)
    own = os.path.join(os.path.dirname(pydir), "scripts", "tools", "bench.py")   # the build's own benchmark child
    own = own if os.path.isfile(own) else os.path.join(os.path.dirname(pydir), "scripts", "bench.py")   # builds before scripts/tools
    return name, pydir, own if os.path.isfile(own) else os.path.join(HERE, "bench.py")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("builds", nargs="+", help="NAME=PYDIR (the first is the reference of the ratios)")
    ap.add_argument("--out", required=True, help="output directory (summary.json, table.md)")
    ap.add_argument("--cases", default="elastic2d_80k,dpgk2d_80k")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    if len(a.builds) < 2:
        raise ValueError("builds: give at least two NAME=PYDIR")
    if a.repeats < 1:
        raise ValueError(f"--repeats = {a.repeats} must be ≥ 1")
    builds = [parse_build(b) for b in a.builds]
    names = [b[0] for b in builds]
    threads = [int(t) for t in a.threads.split(",")]
    if any(t < 1 for t in threads):
        raise ValueError(f"--threads = {a.threads}: each thread count must be ≥ 1")
    runs, load = {}, [os.getloadavg()]
    for case in a.cases.split(","):
        for t in threads:
            for rep in range(a.repeats):
                k = rep % len(builds)
                order = builds[k:] + builds[:k]
                for b in (order[::-1] if rep % 2 else order):
                    r = run_one(case, b, t)
                    runs.setdefault((case, t), {}).setdefault(b[0], []).append(r)
                    print(f"{case} {t}T {b[0]} repeat {rep}: {r['particles'] * r['steps'] / r['wall'] / 1e6:.2f} M p-steps/s", flush=True)
            load.append(os.getloadavg())
    rows = []
    for (case, t), by in runs.items():
        row = dict(case=case, threads=t, wall={}, cpu={}, phases={})
        for n in names:
            rs = by[n]
            rates = [r["particles"] * r["steps"] / r["wall"] for r in rs]
            med = statistics.median(rates)
            rep = min(rs, key=lambda r: abs(r["particles"] * r["steps"] / r["wall"] - med))
            row["wall"][n] = med / 1e6
            row["cpu"][n] = statistics.median(r["particles"] * r["steps"] / r["cpu"] for r in rs) / 1e6
            row["phases"][n] = {k: v / (rep["particles"] * rep["steps"]) * 1e9 for k, v in rep["phases"].items()}
        rows.append(row)
    ref = names[0]
    lines = ["| case | threads | " + " | ".join(f"{n} [M p-steps/s]" for n in names) + " | "
             + " | ".join(f"{n}/{ref} (per CPU-s)" for n in names[1:]) + " |",
             "|---|---|" + "---|" * (2 * len(names) - 1)]
    for r in rows:
        lines.append(f"| {r['case']} | {r['threads']} | " + " | ".join(f"{r['wall'][n]:.2f}" for n in names) + " | "
                     + " | ".join(f"{r['wall'][n] / r['wall'][ref]:.3f} ({r['cpu'][n] / r['cpu'][ref]:.3f})" for n in names[1:]) + " |")
    lines.append("")
    lines.append(f"{a.repeats} repeats per build, medians; load averages (1, 5, 15 min) before and after each case: "
                 + "; ".join("/".join(f"{x:.1f}" for x in l) for l in load))
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "table.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(a.out, "summary.json"), "w") as f:
        json.dump(dict(date=time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()), builds={b[0]: b[1] for b in builds},
                       repeats=a.repeats, rows=rows, load=load), f, indent=1)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
