#!/usr/bin/python3
"""This build (and others) against the ceiling kernel of issue 19, one thread, in one interleaved run.

The kernel is ../shared/reference/perf-kernel/mpm_bench.cpp (a single-file USL WLS/MLS-MPM with the same cubic
B-spline stencil; not part of this repository), built here with the issue's flags
`g++ -O3 -march=native -fopenmp -std=c++17 -I/usr/include/eigen3`, patched only to print the CPU time of its
timed steps. Rounds alternate kernel, build A, build B, … and the reverse order, so a change of host load hits
them alike; each build runs its own scripts/tools/bench.py child (Solver.run of the benchmark block, 300 steps after
20). Printed per round and as medians: particle-steps per wall second and per CPU second, and each build's
ratio to the kernel of the same round (issue 19's bar: ≥ 0.7 for 2D elastic 80 k); the load averages.
With --float-kernel the rounds also run the kernel with every double in float (`float_source`, a textual patch of
the kernel: values, vectors and literals; timers stay double), an upper bound of what single precision can give a
code of the kernel's shape (its positions in float are unusable for the paper's Δt; the speed is the point).

    /usr/bin/python3 scripts/tools/bench_kernel.py now=py                                 # this build, 3 rounds
    /usr/bin/python3 scripts/tools/bench_kernel.py before=/tmp/wt-before/py now=py --rounds 5 --case dpgk2d_80k
    /usr/bin/python3 scripts/tools/bench_kernel.py now=py --float-kernel                  # + the all-float kernel
    /usr/bin/python3 scripts/tools/bench_kernel.py now=py damped=py@damping=0.05         # one build, two settings
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.normpath(os.path.join(HERE, "..", "..", "..", "shared", "reference", "perf-kernel", "mpm_bench.cpp"))
FLAGS = ["-O3", "-march=native", "-fopenmp", "-std=c++17", "-I/usr/include/eigen3"]
STEPS, WARMUP = 300, 20
ENV1 = dict(os.environ, OMP_NUM_THREADS="1", OMP_PROC_BIND="false", GOMP_SPINCOUNT="10000")


def float_source(src):
    """The kernel's text with every double (values, 4-lane vectors, literals) in float, timers kept double: an
    all-float ceiling, to bound what single precision could give a code of the kernel's shape (issue 19)."""
    s = re.sub(r"\bdouble\b", "float", src).replace("vector_size(32)", "vector_size(16)")
    s = re.sub(r"(?<![\w.%])(\d+\.\d*(?:[eE][-+]?\d+)?|\d+[eE][-+]?\d+)(?![\w.])", r"\1f", s)
    lines = s.split("\n")
    for i, line in enumerate(lines):
        if "omp_get_wtime" in line or "float t_p2g" in line:
            lines[i] = line.replace("float", "double")
    return "\n".join(lines)


def build_kernel(source, out_dir, precision="double"):
    """The kernel with a CPU-time print around its timed loop (the only change; precision 'float': also
    `float_source`), built once into out_dir."""
    exe = os.path.join(out_dir, "mpm_bench" + ("" if precision == "double" else "_float"))
    if os.path.exists(exe) and os.path.getmtime(exe) > max(os.path.getmtime(source), os.path.getmtime(__file__)):
        return exe
    src = open(source).read()
    if precision == "float":
        src = float_source(src)
    cpu = ("#include <ctime>\nstatic double cpu_now(){timespec t;clock_gettime(CLOCK_PROCESS_CPUTIME_ID,&t);"
           "return t.tv_sec+1e-9*t.tv_nsec;}\n")
    loop = "    double t0 = omp_get_wtime();\n    for (int it = prm.warmup; it < prm.warmup + prm.steps; it++) sim.step(it);\n"
    if "#include <omp.h>\n" not in src or loop not in src:
        raise SystemExit(f"{source}: the timed loop is not where this script expects it; update build_kernel()")
    src = src.replace("#include <omp.h>\n", "#include <omp.h>\n" + cpu, 1)
    src = src.replace(loop, "    double c0 = cpu_now();\n" + loop + '    printf("CPU %.6f\\n", cpu_now() - c0);\n', 1)
    os.makedirs(out_dir, exist_ok=True)
    patched = exe + ".cpp"
    open(patched, "w").write(src)
    r = subprocess.run(["g++", *FLAGS, patched, "-o", exe], capture_output=True, text=True)
    if r.returncode:
        raise SystemExit(f"building the {precision} kernel failed (the textual patch may no longer fit {source}):\n{r.stderr[-2000:]}")
    return exe


def run_kernel(exe, mat, threads=1, env=None):
    """(particle-steps per wall s, per CPU s, phase line) of the kernel's 2D 80 k block."""
    env = dict(env or ENV1, OMP_NUM_THREADS=str(threads))
    r = subprocess.run([exe, "--dim", "2", "--bx", "200", "--by", "100", "--mat", mat, "--steps", str(STEPS), "--warmup", str(WARMUP),
                        "--resort", "25"], env=env, capture_output=True, text=True, check=True).stdout
    n = 80000 * STEPS
    return n / float(re.search(r"wall=([\d.]+)s", r).group(1)), n / float(re.search(r"CPU ([\d.]+)", r).group(1)), re.search(r"phases: (.*)\|", r).group(1)


def run_build(spec, case):
    """spec: PATH of a build's py/, optionally PATH@key=value,key=value: solver settings for the timed scene."""
    py, _, sets = spec.partition("@")
    settings = {k: json.loads(v) for k, v in (kv.split("=", 1) for kv in sets.split(",") if kv)}
    bench = os.path.join(os.path.dirname(os.path.abspath(py)), "scripts", "tools", "bench.py")
    r = subprocess.run([sys.executable, bench, "--child", "--mode", "direct", "--case", case, "--steps", str(STEPS), "--warmup", str(WARMUP)],
                       env=dict(ENV1, PYTHONPATH=os.path.abspath(py), YADE_MPM_BENCH_SETTINGS=json.dumps(settings)), capture_output=True,
                       text=True)
    line = [x for x in r.stdout.splitlines() if x.startswith("BENCH ")]
    if not line:
        raise SystemExit(f"{py}: benchmark child failed\n{r.stdout[-1500:]}\n{r.stderr[-1500:]}")
    d = json.loads(line[0][6:])
    n = d["particles"] * d["steps"]
    return n / d["wall"], n / d["cpu"], " ".join(f"{k}={v / n * 1e9:.1f}" for k, v in d["phases"].items() if v > 0) + " ns/p-step (wall)"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("builds", nargs="+", help="NAME=PATH of a build's py/ directory; NAME=PATH@key=value,… also sets solver "
                    "settings of the timed scene (e.g. damped=py@damping=0.05)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--case", default="elastic2d_80k", choices=["elastic2d_80k", "dpgk2d_80k"])
    ap.add_argument("--kernel-source", default=SOURCE)
    ap.add_argument("--kernel-dir", default=os.path.join(HERE, "..", "..", "out", "kernel"), help="where the kernel is built (once)")
    ap.add_argument("--float-kernel", action="store_true", help="also run the kernel with every double in float (`float_source`) "
                    "and print its speed-up over the double kernel: what single precision can give a code of the kernel's shape")
    a = ap.parse_args()
    builds = [b.split("=", 1) for b in a.builds]
    if a.rounds < 1:
        raise SystemExit("--rounds must be >= 1")
    mat = "dp" if a.case.startswith("dpgk") else "elastic"
    kernels = [("kernel", "double")] + ([("float-kernel", "float")] if a.float_kernel else [])
    order = [(name, (lambda exe: lambda: run_kernel(exe, mat))(build_kernel(a.kernel_source, os.path.abspath(a.kernel_dir), prec)))
             for name, prec in kernels]
    order += [(name, (lambda py: lambda: run_build(py, a.case))(py)) for name, py in builds]
    compared = [name for name, _ in order[1:]]   # each against the double kernel of its round
    print(f"load average at start: {os.getloadavg()}", flush=True)
    ratios = {n: [] for n in compared}
    for k in range(a.rounds):
        row = {}
        for name, run1 in (order if k % 2 == 0 else order[::-1]):
            row[name] = run1()
            print(f"round {k} {name}: {row[name][0] / 1e6:.2f} M/s wall, {row[name][1] / 1e6:.2f} M/s CPU; {row[name][2]}", flush=True)
        for name in compared:
            r = (row[name][0] / row["kernel"][0], row[name][1] / row["kernel"][1])
            ratios[name].append(r)
            print(f"  round {k} {name} / kernel: wall {r[0]:.3f}, CPU {r[1]:.3f}", flush=True)
    print(f"load average at end: {os.getloadavg()}")
    for name in compared:
        print(f"MEDIAN {name} / kernel ({a.case}, 1 thread, {a.rounds} rounds): wall {statistics.median(r[0] for r in ratios[name]):.3f}, "
              f"CPU {statistics.median(r[1] for r in ratios[name]):.3f}" + ("  (the all-float kernel's speed-up)" if name == "float-kernel" else "  (issue 19 bar: 0.7)"))


if __name__ == "__main__":
    main()
