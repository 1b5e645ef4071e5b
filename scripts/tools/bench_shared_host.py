#!/usr/bin/python3
"""The default thread count on a shared host: the tunnel of `./run.sh` (2 mm grid, intact, stepped through YADE
with its platen, as scripts/paper/tunnel_spalling.py runs it) beside another single-threaded job, three ways:

    auto   no thread count chosen: the governor (yade_mpm.threads) picks the faster of all / half the cores
    all    OMP_NUM_THREADS = all cores (the governor is off)
    one    OMP_NUM_THREADS = 1

    /usr/bin/python3 scripts/tools/bench_shared_host.py --out out/shared_host              # with a busy-loop neighbour
    /usr/bin/python3 scripts/tools/bench_shared_host.py --out out/shared_host --no-neighbour   # idle host (check: auto ≈ all)

The modes run in turn (auto all one, one all auto, …) so a change of the host's own load hits them alike; each run is
a fresh process stepping `--steps` steps after 50 warm-up steps. The neighbour is a Python busy loop started before
and stopped after the runs. Writes OUT/summary.json (wall seconds per mode and repeat, medians, the thread counts the
governor used) and OUT/table.md."""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
PY = os.path.join(os.path.dirname(os.path.dirname(HERE)), "py")
CHILD = r'''
import json, sys, time
import yade_mpm as ym
from yade import O
from yade_mpm import threads
from yade_mpm_paper import cases
s, b = cases.arch_tunnel("intact", 0.002)
for _ in range(50):
    O.step()
seen = {}
t0 = time.time()
for _ in range(STEPS):
    O.step()
    n = ym.getThreads()
    seen[n] = seen.get(n, 0) + 1
print(json.dumps(dict(wall_s=time.time() - t0, steps_at_threads=seen)))
'''


def one_run(mode, steps, cores):
    env = dict(os.environ, PYTHONPATH=PY)
    env.pop("OMP_NUM_THREADS", None)
    if mode != "auto":
        env["OMP_NUM_THREADS"] = str(cores if mode == "all" else 1)
    out = subprocess.run([sys.executable, "-c", CHILD.replace("STEPS", str(steps))], env=env, capture_output=True, text=True, timeout=3600)
    if out.returncode != 0:
        raise RuntimeError(f"{mode}: exit {out.returncode}: {out.stderr.strip().splitlines()[-1:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--steps", type=int, default=3000, help="timed steps per run (default %(default)s)")
    ap.add_argument("--repeats", type=int, default=3, help="runs per mode (default %(default)s)")
    ap.add_argument("--no-neighbour", dest="neighbour", action="store_false", help="no busy-loop job beside the runs")
    a = ap.parse_args()
    if a.steps < 100 or a.repeats < 1:
        ap.error("--steps must be ≥ 100 and --repeats ≥ 1")
    os.makedirs(a.out, exist_ok=True)
    sys.path.insert(0, PY)
    from yade_mpm.threads import available_cores
    cores = available_cores()
    modes = ["auto", "all", "one"]
    neighbour = subprocess.Popen([sys.executable, "-c", "while True: pass"]) if a.neighbour else None
    runs = {m: [] for m in modes}
    try:
        for r in range(a.repeats):
            order = modes[r % 3:] + modes[:r % 3]
            for m in (order if r % 2 == 0 else order[::-1]):
                res = one_run(m, a.steps, cores)
                runs[m].append(res)
                print(f"[shared-host] repeat {r + 1} {m}: {res['wall_s']:.1f} s, steps by thread count {res['steps_at_threads']}", flush=True)
    finally:
        if neighbour is not None:
            neighbour.kill()
    med = {m: statistics.median(x["wall_s"] for x in runs[m]) for m in modes}
    summary = dict(cores=cores, steps=a.steps, neighbour=a.neighbour, runs=runs, median_wall_s=med,
                   auto_over_one=med["auto"] / med["one"], auto_over_all=med["auto"] / med["all"], load_after=os.getloadavg())
    json.dump(summary, open(os.path.join(a.out, "summary.json"), "w"), indent=1)
    lines = ["| mode | median wall [s] | runs [s] | steps by thread count (last run) |", "|---|---|---|---|"]
    for m in modes:
        walls = ", ".join("%.1f" % x["wall_s"] for x in runs[m])
        lines.append(f"| {m} | {med[m]:.1f} | {walls} | {runs[m][-1]['steps_at_threads']} |")
    lines.append(f"\n{'With' if a.neighbour else 'Without'} a busy-loop neighbour, {cores} cores, {a.steps} steps of the 2 mm tunnel: "
                 f"auto / one thread = {summary['auto_over_one']:.2f}, auto / all cores = {summary['auto_over_all']:.2f}.")
    open(os.path.join(a.out, "table.md"), "w").write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
