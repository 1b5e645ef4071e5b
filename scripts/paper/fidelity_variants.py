"""One-at-a-time variants of the named modelling choices (yade_mpm_paper.fidelity.VARIANTS) on one scene, for
the cause analysis of the fidelity table (issue 18, doc/validation/report.md): each run writes
OUT/<scene>_<case>_<variant>.json with what the rows need, and report.py builds the matrix choice × row.

    /usr/bin/python3 scripts/paper/fidelity_variants.py --scene uniaxial --case open --variants baseline,courant_0.25
    /usr/bin/python3 scripts/paper/fidelity_variants.py --scene tunnel --case filled_flaw --spacing 0.0025 --end-time 0.02

Screening runs: a coarse grid and a short loading are allowed (the JSON records both); compare variants
with their own baseline, not with the full runs of tunnel_spalling.py / uniaxial_flaw.py.
"""
import argparse
import json
import math
import os
import subprocess
import time

import numpy as np

import yade_mpm as ym
from yade_mpm import analysis, rocks, runner
from yade_mpm_paper import cases, fidelity

SNAP_MS = (8.0, 12.0, 20.0)


def parse():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", choices=("tunnel", "uniaxial"), required=True)
    ap.add_argument("--case", default=None, help="tunnel: intact, open_flaw, filled_flaw (default); uniaxial: open (default), filled")
    ap.add_argument("--variants", default="baseline", help=f"comma list of {', '.join(fidelity.VARIANTS)}")
    ap.add_argument("--spacing", type=float, default=None, help="grid spacing [m] (default: tunnel 0.0025, uniaxial 0.002)")
    ap.add_argument("--end-time", type=float, default=None, help="loading time [s] (default: tunnel 0.02, uniaxial 0.014)")
    ap.add_argument("--mu-con", type=float, default=0.6, help="filler friction of the uniaxial filled case (default 0.6)")
    ap.add_argument("--out", default="out/fidelity_variants")
    ap.add_argument("--baseline-from", default=None, metavar="CASE_DIR",
                    help="write the tunnel baseline row from a finished default run of scripts/paper/tunnel_spalling.py (its case folder, "
                         "e.g. out/tunnel/filled_flaw: case.json, axial_stress.csv, snapshot_*ms.npz) instead of running it again")
    a = ap.parse_args()
    a.case = a.case or ("filled_flaw" if a.scene == "tunnel" else "open")
    a.spacing = a.spacing or (0.0025 if a.scene == "tunnel" else 0.002)
    a.end_time = a.end_time or (0.02 if a.scene == "tunnel" else 0.014)
    a.variants = [v.strip() for v in a.variants.split(",") if v.strip()]
    for v in a.variants:
        try:
            fidelity.variant(v, a.scene)
        except ValueError as e:
            ap.error(str(e))
    return a


def build(a, v):
    mat = dict(v.get("material", {}))
    if a.scene == "tunnel":
        s, b = cases.arch_tunnel(a.case, a.spacing, material=rocks.pan2020_sandstone(**mat), floor=v.get("floor", cases.TUNNEL_FLOOR),
                                 flaw_angle=math.radians(v.get("flaw_angle", cases.FLAW_ANGLE_DEG)), flaw_toe_gap=v.get("flaw_toe_gap", cases.FLAW_TOE_GAP),
                                 flaw_toe_height=v.get("flaw_toe_height", cases.FLAW_TOE_HEIGHT), contact_law=v.get("contact_law"))
        return s, b, b["platen_displacement"], b["axial_stress"]
    s, b = cases.uniaxial_flaw(a.case, a.spacing, mu_con=a.mu_con if a.case == "filled" else 0.0, material=rocks.miao2018_sandstone(**mat),
                               contact_law=v.get("contact_law"))
    return s, b, lambda: b["axial_strain"]() * b["height"], b["axial_stress"]


def run_one(a, name):
    from yade import O
    v = fidelity.variant(name, a.scene)
    s, b, disp, stress = build(a, v)
    if "courant" in v:                        # else the solver's default C
        s.courant = v["courant"]
    if "velocity_update" in v:                # else the solver's default
        s.velocityUpdate = v["velocity_update"]
    x0 = ym.get(s, "pos")
    lat = analysis.Lattice(x0, s.spacing / 2, origin=(0, 0))
    soft_end = analysis.softening_end(s)
    curve, res = [], dict(scene=a.scene, case=a.case, variant=name, label=v["label"], spacing_m=a.spacing, end_time_s=a.end_time,
                          courant=s.courant, velocity_update=s.velocityUpdate, contact_law=v.get("contact_law", "default"),
                          particles=int(s.numParticles), snapshots={}, first_crack=None)
    fl = b["flaw"]
    times = fidelity.CrackTimes(lat, fl["toe"], fl["tip"], soft_end, 2 * s.spacing) if a.scene == "uniaxial" and fl else None

    def record(solver):
        curve.append((disp(), stress(), solver.time))

    def watch(solver):
        if res["first_crack"] is None and solver.view("damage").max() >= 1.0:
            D = ym.get(solver, "damage")
            res["first_crack"] = dict(time_s=solver.time, at=cases.tunnel_where(x0[D >= 1], fl, b.get("floor", cases.TUNNEL_FLOOR))
                                      if a.scene == "tunnel" else None)

    def snap(solver):
        f = ym.fields(solver, ["pos", "damage", "plastic_strain", "mass"])
        rep, _ = cases.tunnel_report(f, lat, fl, soft_end, floor=b["floor"])
        ep = np.asarray(f["plastic_strain"], float)          # how far the rock is from softening (Eq. 34 ends at soft_end)
        rep.update(eps_p_max=float(ep.max()), eps_p_p99=float(np.percentile(ep, 99)), eps_p_soft_end=float(np.min(soft_end)))
        res["snapshots"][f"{solver.time * 1e3:.0f}ms"] = rep

    def softened(solver):                       # uniaxial: stop after the peak as uniaxial_flaw.py does
        if a.scene != "uniaxial" or solver.steps % 50:
            return False
        st = [q[1] for q in curve]
        k = int(np.argmax(st))
        return st[k] > 5e6 and st[-1] < 0.6 * st[k] and solver.time > 1.2 * curve[k][2]
    outs = [runner.Output(record, steps=5), runner.Output(watch, steps=10)]
    if a.scene == "tunnel":
        outs.append(runner.Output(snap, times=[t * 1e-3 for t in SNAP_MS if t * 1e-3 <= a.end_time + 1e-12], at_end=True))
    if times:
        outs.append(runner.Output(times.update, steps=25))
    t0 = time.time()
    try:
        r = runner.run(s, end_time=a.end_time, progress=120, label=f"{a.scene}/{a.case}/{name}", advance=O.step, outputs=outs, stop=softened)
        reason = r.reason
    except (ym.MpmSimulationError, RuntimeError) as e:   # the solver refuses the state (e.g. an inverted element; through YADE a RuntimeError): recorded
        reason, res["error"] = "error", str(e).split("ERROR:")[-1].strip().splitlines()[0]
    res.update(wall_time_s=round(time.time() - t0, 1), steps=int(s.steps), end_reason=reason, time_reached_s=s.time)
    if len(curve) < 6:
        return res
    c = np.array(curve)
    res["curve_shape"] = fidelity.curve_shape(c[:, 0] * 1e3, c[:, 1] / 1e6)        # mm, MPa
    res["stress_MPa_at_mm"] = {f"{m:g}": float(np.interp(m, c[:, 0] * 1e3, c[:, 1] / 1e6)) for m in (0.25, 0.5, 1.0, 1.5, 2.0)
                               if m <= c[-1, 0] * 1e3 + 1e-9}
    if times:
        res["crack_times"] = times.result()
    res["build"] = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                  cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    return res


def baseline_from(a, folder):
    """The baseline JSON of the tunnel scene from tunnel_spalling.py's default run of the same case (same scene and
    defaults: cases.arch_tunnel, the solver's C): its snapshot reports, first crack, curve and the ε̄p statistics."""
    if a.scene != "tunnel":
        raise SystemExit("--baseline-from: only for --scene tunnel (a tunnel_spalling.py case folder)")
    cj = json.load(open(os.path.join(folder, "case.json")))
    if not cj.get("finished"):
        raise SystemExit(f"--baseline-from {folder}: the run is not finished (case.json: finished = false)")
    summ = json.load(open(os.path.join(os.path.dirname(os.path.normpath(folder)), "summary.json")))
    entry = next(e for e in summ["cases"] if e["case"] == a.case)
    soft_end = (1 - rocks.pan2020_sandstone().residualCohesion) * rocks.pan2020_sandstone().critPlasticStrain
    snaps = {}
    for key, rep in cj["snapshots"].items():
        with np.load(os.path.join(folder, f"snapshot_{key}.npz")) as z:
            ep = np.asarray(z["plastic_strain"], float)
        snaps[f"{float(key[:-2]):.0f}ms"] = dict(rep, eps_p_max=float(ep.max()), eps_p_p99=float(np.percentile(ep, 99)), eps_p_soft_end=soft_end)
    c = np.loadtxt(os.path.join(folder, "axial_stress.csv"), delimiter=",", skiprows=1, ndmin=2)    # time_s, displacement_mm, MPa
    fc = cj.get("first_crack")
    res = dict(scene="tunnel", case=a.case, variant="baseline", label=fidelity.VARIANTS["baseline"]["label"] + f" — the default run `{folder}`",
               spacing_m=entry["grid_spacing_m"], end_time_s=float(f"{c[-1, 0]:.4g}"), particles=entry["particles"], snapshots=snaps,
               first_crack=fc and dict(time_s=fc["time"], at=fc["location"]), wall_time_s=entry["wall_time_s"], steps=entry["steps"],
               curve_shape=fidelity.curve_shape(c[:, 1], c[:, 2]),
               stress_MPa_at_mm={f"{m:g}": float(np.interp(m, c[:, 1], c[:, 2])) for m in (0.25, 0.5, 1.0, 1.5, 2.0) if m <= c[-1, 1] + 1e-9})
    res["build"] = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                  cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    return res


def main():
    a = parse()
    os.makedirs(a.out, exist_ok=True)
    if a.baseline_from:
        res = baseline_from(a, a.baseline_from)
        path = os.path.join(a.out, f"{a.scene}_{a.case}_baseline.json")
        with open(path, "w") as f:
            json.dump(fidelity.json_safe(res), f, indent=1)
        print(f"RESULT {path}: from {a.baseline_from}")
        return
    for name in a.variants:
        res = run_one(a, name)
        path = os.path.join(a.out, f"{a.scene}_{a.case}_{name}.json")
        with open(path, "w") as f:
            json.dump(fidelity.json_safe(res), f, indent=1)
        print(f"RESULT {path}: wall {res['wall_time_s']} s, curve {res['curve_shape']}, crack times {res.get('crack_times', {})}",
              flush=True)


if __name__ == "__main__":
    main()
