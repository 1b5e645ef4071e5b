"""The 2 mm DP–GK arch tunnel (intact; paper Sec. 4, ``cases.arch_tunnel``) on N MPI ranks against 1
process (doc/developer/scaling.md, issue 22's bar: axial stress at 0.5 / 1 / 2 mm within 0.5 %, the first crack at
the same place). Two modes:

    scripts/tools/mpi_run.sh 2 1 scripts/tools/mpi_tunnel.py run --out out/mpi_tunnel/two    # 2 ranks × 1 thread
    OMP_NUM_THREADS=1 /usr/bin/python3 scripts/tools/mpi_tunnel.py run --out out/mpi_tunnel/one   # serial core
    /usr/bin/python3 scripts/tools/mpi_tunnel.py compare out/mpi_tunnel/one out/mpi_tunnel/two

`run` writes OUT/rankK.npz per rank: the platen stress and displacement of every step (the reaction is
global: the same on every rank) and the first step at which this rank held a particle with D = 1 (checked
every 10 steps, as scripts/paper/tunnel_spalling.py does) with those particles' ids. `compare` takes the global
first crack (the earliest rank's step; the union of the ranks that cracked at that step), its place
(``cases.tunnel_where`` of the initial positions, as ``tunnel_results.first_crack``) and the axial stress
at 0.5, 1 and 2 mm read as ``scripts/paper/tunnel_spalling.py`` reads it (``stress_at``)."""
import argparse
import glob
import json
import os
import sys
import time

import numpy as np

AT_MM = (0.5, 1.0, 2.0)
BIN_MM = 0.01


def run(a):
    import yade_mpm as ym
    from yade import O
    from yade_mpm_paper import cases
    s, b = cases.arch_tunnel("intact", a.spacing)
    rank = ym.parallel.rank()
    x0 = ym.get(s, "pos")                               # the whole scene, before the first step splits it
    rec, crack, t0 = [], None, time.time()
    while s.time < a.end_time:
        O.step()
        rec.append((s.time, b["platen_displacement"](), b["axial_stress"]()))
        if crack is None and s.steps % 10 == 0:
            d = np.array(s.view("damage"))
            if d.size and d.max() >= 1.0:
                crack = (s.steps, s.time, np.array(s.view("id"))[d >= 1.0])
        if rank == 0 and s.steps % 2000 == 0:
            print(f"step {s.steps}, t = {s.time * 1e3:.3f} ms, σ = {rec[-1][2] / 1e6:.3f} MPa, {time.time() - t0:.0f} s", flush=True)
    os.makedirs(a.out, exist_ok=True)
    np.savez(os.path.join(a.out, f"rank{rank}.npz"), curve=np.array(rec), x0=x0, size=ym.parallel.size(), wall=time.time() - t0,
             crack_step=crack[0] if crack else -1, crack_time=crack[1] if crack else np.nan,
             crack_ids=crack[2] if crack else np.zeros(0, int))


def load(folder):
    parts = [dict(np.load(f)) for f in sorted(glob.glob(os.path.join(folder, "rank*.npz")))]
    if not parts or len(parts) != int(parts[0]["size"]):
        raise SystemExit(f"{folder}: expected one rankK.npz per rank")
    curve = parts[0]["curve"]
    for p in parts[1:]:
        if p["curve"].tobytes() != curve.tobytes():
            raise SystemExit(f"{folder}: the ranks' platen records differ (the YADE scenes diverged)")
    from yade_mpm_paper import cases
    steps = [int(p["crack_step"]) for p in parts if int(p["crack_step"]) >= 0]
    crack = None
    if steps:
        k = min(steps)
        ids = np.concatenate([p["crack_ids"] for p in parts if int(p["crack_step"]) == k])
        pts = parts[0]["x0"][ids]
        crack = dict(step=k, time_ms=float(curve[k - 1, 0]) * 1e3, displacement_mm=float(curve[k - 1, 1]) * 1e3, particles=len(ids),
                     centroid_mm=(pts.mean(axis=0) * 1e3).tolist(), location=cases.tunnel_where(pts, None))
    stress = stress_at(curve)
    return dict(ranks=len(parts), steps=len(curve), wall_s=[float(p["wall"]) for p in parts], stress_Pa=stress, first_crack=crack)


def stress_at(curve):
    """Axial stress [Pa] at AT_MM as scripts/paper/tunnel_spalling.py (and scripts/regress.py) read it: the mean
    over every BIN_MM of platen travel (``output.CurveRecorder`` replayed on the per-step record), sampled
    every 0.1 mm (``tunnel_results.sample_curve``)."""
    from yade_mpm import output
    from yade_mpm_paper.cases import tunnel_results
    row = [0]
    rec = output.CurveRecorder(lambda: curve[row[0], 1], lambda: curve[row[0], 2], BIN_MM * 1e-3)
    clock = type("Clock", (), {})()
    for row[0] in range(len(curve)):
        clock.time = curve[row[0], 0]
        rec.record(clock)
    at = {round(p["displacement_mm"], 6): p["stress_MPa"] * 1e6 for p in tunnel_results.sample_curve(rec.state["curve"], 0.1)}
    return {d: at.get(d, float("nan")) for d in AT_MM}


def compare(a):
    one, two = load(a.one), load(a.two)
    rows = {f"{d} mm": dict(one_MPa=one["stress_Pa"][d] / 1e6, many_MPa=two["stress_Pa"][d] / 1e6,
                            rel=two["stress_Pa"][d] / one["stress_Pa"][d] - 1) for d in AT_MM}
    c1, c2 = one["first_crack"], two["first_crack"]
    same = bool(c1 and c2 and c1["location"] == c2["location"])
    out = dict(one=one, many=two, stress=rows, crack_same_place=same,
               stress_within_0_5_percent=all(abs(r["rel"]) <= 5e-3 for r in rows.values()))
    print(json.dumps(out, indent=1, default=str))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1, default=str)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="mode", required=True)
    r = sub.add_parser("run")
    r.add_argument("--out", required=True)
    r.add_argument("--spacing", type=float, default=2e-3, help="grid spacing l [m] (default 0.002)")
    r.add_argument("--end-time", type=float, default=0.02, help="loading time [s] (default 0.02: 2 mm)")
    c = sub.add_parser("compare")
    c.add_argument("one"), c.add_argument("two"), c.add_argument("--json")
    a = ap.parse_args()
    if a.mode == "run":
        if not (0 < a.end_time <= 0.1):
            ap.error(f"--end-time = {a.end_time} s must be in (0, 0.1]")
        run(a)
    else:
        compare(a)


if __name__ == "__main__":
    sys.exit(main())
