"""Error against run time for the reference cases: each case at three or more grid spacings (each half the
last) and two Courant numbers, every run in its own one-thread process, with its wall time, CPU time and particle-steps.

    /usr/bin/python3 scripts/paper/convergence.py --out out/convergence                  # the default families (~1.5 h)
    /usr/bin/python3 scripts/paper/convergence.py --out out/convergence --families kirsch,sneddon

Families (yade_mpm_paper.uncertainty for the orders and the Richardson limit):
    kirsch           circular opening (relaxed to a 1e-4 change) with Kirsch's stress on the block faces (--far-field kirsch:
                     the block's exact solution is then Kirsch's, not the finite block's, which differs by O((a/L)²) ≈ 0.5 %):
                     max L2 relative error of σxx, σyy on the x and y lines against Kirsch (Eqs. 41–42), the same within
                     5 radii, the hoop stress at the wall (θ = 90°)
    sneddon          pressurised line crack (crack nodes excluded), L2 relative error of the opening against Sneddon (Eq. 43)
    uniaxial_intact  intact specimen (DP–GK): apparent modulus against the plane-strain E/(1 − ν²); the peak against
                     its Richardson limit
    tunnel_elastic   the arch tunnel with the rock elastic (E, ν, ρ of the Pan 2020 sandstone): axial stress at 0.5 mm
                     of platen travel, four grids down to 0.5 mm (~1 h of the study), against its Richardson limit where the
                     last three give one (observed order ≥ 0.5), else against the finest run
    tunnel_intact    (not in the default list: ~1 h) the intact DP–GK tunnel: σ at 2 mm of travel, first crack time

A run whose OUT/FAMILY/l<l>_c<C>/summary.json exists is not run again (resume = the same command); a run that fails
leaves its log and the reason in OUT/runs.csv and the next one runs. Outputs: OUT/runs.csv, OUT/summary.json,
OUT/error_vs_time.png (error against the run's CPU time, one line per refinement path), OUT/table.md.
"""
import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "py"))
from yade_mpm_paper import uncertainty  # noqa: E402

QUIET = ["--progress", "600"]
FAMILIES = {   # name: (spacings [m] coarse → fine, Courant numbers, command of one run)
    "kirsch": ((0.08, 0.04, 0.02), (0.5, 0.25),
               lambda l, c, d: ["circular_opening.py", "--out", d, "--spacing", f"{l:g}", "--courant", f"{c:g}", "--no-convergence", "--no-vtu",
                                 "--tol", "1e-4", "--far-field", "kirsch"]),   # relaxed 10× further than the script's default: the discretisation error shows
    "sneddon": ((0.08, 0.04, 0.02), (0.5, 0.25),
                lambda l, c, d: ["penny_crack.py", "--out", d, "--parts", "elastic", "--spacing", f"{l:g}", "--courant", f"{c:g}",
                                 "--crack-nodes", "excluded"]),
    "uniaxial_intact": ((0.004, 0.002, 0.001), (1.0, 0.5),
                        lambda l, c, d: ["uniaxial_flaw.py", "--out", d, "--runs", "intact", "--spacing", f"{l:g}", "--courant", f"{c:g}",
                                         "--vtu-every", "1"]),
    "tunnel_elastic": ((0.004, 0.002, 0.001, 0.0005), (1.0, 0.5),   # four grids: its error is against the finest run
                       lambda l, c, d: ["convergence.py", "--point", "tunnel_elastic", "--out", d, "--spacing", f"{l:g}", "--courant", f"{c:g}"]),
    "tunnel_intact": ((0.004, 0.002, 0.001), (1.0, 0.5),
                      lambda l, c, d: ["tunnel_spalling.py", "--out", d, "--cases", "intact", "--spacing", f"{l:g}", "--courant", f"{c:g}",
                                       "--no-pictures", "--checkpoint-every", "0", "--vtu-every", "1"]),
}
DEFAULT = "kirsch,sneddon,uniaxial_intact,tunnel_elastic"
TRAVEL_MM = (0.25, 0.5)          # tunnel_elastic: σ recorded at these platen displacements


def quantities(family, d):
    """The run's numbers: dict(particles, steps, error or value quantities) from its summary.json."""
    s = json.load(open(os.path.join(d, "summary.json")))
    if family == "kirsch":
        return dict(particles=s["particles"], steps=s["steps"], error=s["l2_rel_error_max"], near_error=s["l2_rel_error_near_max"],
                    hoop90_error=s["hoop_stress_theta90_MPa"] / s["kirsch_hoop_theta90_MPa"] - 1)
    if family == "sneddon":
        return dict(particles=s["elastic_particles"], steps=s["elastic_steps"], error=s["uy_l2_rel_error"], centre_error=s["uy_center_rel_error"])
    if family == "uniaxial_intact":
        from yade_mpm import rocks
        r, m = s["runs"][0], rocks.MIAO2018_SANDSTONE
        plane = m["young"] / (1 - m["poisson"] ** 2)
        return dict(particles=r["particles"], steps=r["steps"], error=r["youngs_modulus_GPa"] * 1e9 / plane - 1, peak_MPa=r["peak_stress_MPa"])
    if family == "tunnel_elastic":
        return dict(particles=s["particles"], steps=s["steps"], **{f"stress_{t:g}mm_MPa": s["stress_MPa_at_mm"][f"{t:g}"] for t in TRAVEL_MM})
    e = s["cases"][0]
    return dict(particles=e.get("particles"), steps=e.get("steps"), stress_2mm_MPa=e["stress_MPa_at_mm"]["2"],
                first_crack_ms=(e.get("first_crack") or {}).get("time_s", math.nan) * 1e3)


MEASURES = {   # family: (quantity, "analytic" = the quantity is the signed relative error | "richardson" = a value, its label)
    "kirsch": (("error", "analytic", "max L2 rel. error of σ vs Kirsch, r ≥ 2a"), ("near_error", "analytic", "same, 2a ≤ r ≤ 5a"),
               ("hoop90_error", "analytic", "hoop stress at the wall, θ = 90°")),
    "sneddon": (("error", "analytic", "L2 rel. error of the opening vs Sneddon"),),
    "uniaxial_intact": (("error", "analytic", "apparent modulus vs E/(1−ν²)"), ("peak_MPa", "richardson", "peak stress")),
    "tunnel_elastic": (("stress_0.5mm_MPa", "richardson", "σ at 0.5 mm of travel"),),
    "tunnel_intact": (("stress_2mm_MPa", "richardson", "σ at 2 mm of travel"), ("first_crack_ms", "richardson", "first crack time")),
}


# ------------------------------------------------------------------------------- one elastic tunnel run (--point)
def tunnel_elastic_point(a):
    """The tunnel of paper Sec. 4 with the rock elastic, loaded to 0.5 mm of platen travel; summary.json."""
    from yade import O
    import yade_mpm as ym
    from yade_mpm import rocks
    from yade_mpm_paper import cases
    rock = ym.ElasticMat(**{k: rocks.PAN2020_SANDSTONE[k] for k in ("young", "poisson", "density")})
    s, b = cases.arch_tunnel("intact", a.spacing, material=rock)
    s.courant = a.courant
    got, targets, t0 = {}, list(TRAVEL_MM), time.time()
    while targets:
        O.step()
        u = b["platen_displacement"]() * 1e3
        if u >= targets[0]:
            got[f"{targets.pop(0):g}"] = b["axial_stress"]() / 1e6
    os.makedirs(a.out, exist_ok=True)
    json.dump(dict(case="tunnel_elastic", spacing_m=a.spacing, courant=a.courant, particles=int(s.numParticles), steps=int(s.steps),
                   wall_time_s=time.time() - t0, stress_MPa_at_mm=got), open(os.path.join(a.out, "summary.json"), "w"), indent=1)


# ----------------------------------------------------------------------------------------------- the study
def run_point(family, l, c, out):
    d = os.path.join(out, family, f"l{l:g}_c{c:g}")
    row = dict(family=family, spacing_m=l, courant=c, folder=os.path.relpath(d, out))
    if not os.path.exists(os.path.join(d, "summary.json")):
        os.makedirs(d, exist_ok=True)
        cmd = FAMILIES[family][2](l, c, d)
        env = dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=os.path.join(os.path.dirname(os.path.dirname(HERE)), "py"))
        script = os.path.join(HERE, cmd[0])
        before, t0 = resource.getrusage(resource.RUSAGE_CHILDREN), time.time()
        with open(os.path.join(d, "log.txt"), "w") as log:
            rc = subprocess.call([sys.executable, script] + cmd[1:] + QUIET, stdout=log, stderr=subprocess.STDOUT, env=env)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cost = dict(wall_s=time.time() - t0, cpu_s=(after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), rc=rc)
        json.dump(cost, open(os.path.join(d, "cost.json"), "w"))
        if rc != 0 or not os.path.exists(os.path.join(d, "summary.json")):
            tail = open(os.path.join(d, "log.txt")).read().strip().splitlines()[-3:]
            return dict(row, failed=f"exit {rc}: " + " | ".join(tail))
    row.update(json.load(open(os.path.join(d, "cost.json"))) if os.path.exists(os.path.join(d, "cost.json")) else {})
    try:
        row.update(quantities(family, d))
    except (KeyError, IndexError, TypeError, ValueError) as e:
        return dict(row, failed=f"summary.json unreadable: {e!r}")
    row["particle_steps"] = row["particles"] * row["steps"]
    return row


def paths(family, rows):
    """One refinement path per measure and Courant number: spacings coarse → fine, the error of each run (analytic,
    or against the path's Richardson limit; the finest run then has none) and the observed orders."""
    out = []
    for key, kind, label in MEASURES[family]:
        for c in FAMILIES[family][1]:
            rs = sorted((r for r in rows if r["courant"] == c and not r.get("failed") and r.get(key) is not None), key=lambda r: -r["spacing_m"])
            h = [r["spacing_m"] for r in rs]
            q = [r[key] for r in rs]
            if kind == "richardson":
                rich = uncertainty.richardson(h, q)
                ref = rich["limit"]
                err = [abs(x / ref - 1) for x in q] if ref else [abs(x / q[-1] - 1) for x in q[:-1]] + [None] if q else []
                path = dict(value=q, reference=ref if ref else (q[-1] if q else None), richardson=rich,
                            reference_kind="Richardson limit" if ref else "finest run")
            else:
                err = [abs(x) for x in q]
                path = dict(reference_kind="analytic")
            path.update(measure=label, key=key, courant=c, spacing_m=h, error=err, cpu_s=[r.get("cpu_s") for r in rs],
                        wall_s=[r.get("wall_s") for r in rs], particle_steps=[r["particle_steps"] for r in rs],
                        orders=uncertainty.observed_order(h, [e or 0.0 for e in err]))
            out.append(path)
    return out


def figure(summary, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    panels = {}
    for f, fs in summary["families"].items():
        for p in fs["paths"]:
            panels.setdefault((f, p["measure"]), []).append(p)
    if not panels:
        return
    cols = min(2, len(panels))
    rows = math.ceil(len(panels) / cols)
    fig, axs = plt.subplots(rows, cols, figsize=(6.2 * cols, 4.0 * rows), squeeze=False)
    for ax, ((f, m), ps) in zip(axs.flat, panels.items()):
        for p in ps:
            pts = [(t, e, h) for t, e, h in zip(p["cpu_s"], p["error"], p["spacing_m"]) if t and e]
            if pts:
                ax.loglog([x[0] for x in pts], [x[1] for x in pts], "o-", label=f"C = {p['courant']:g}, grid halved (vs {p['reference_kind']})")
                for t, e, h in pts:
                    ax.annotate(f"l = {h * 1e3:g} mm", (t, e), fontsize=7, xytext=(3, 3), textcoords="offset points")
        ax.set_title(f"{f}: {m}", fontsize=9)
        ax.set_xlabel("CPU time of the run, one thread [s]")
        ax.set_ylabel("relative error")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    for ax in list(axs.flat)[len(panels):]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def table(summary):
    out = ["| case | measure (reference) | C | l [mm] | value | particle-steps | CPU [s] | wall [s] | rel. error | observed order |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for f, fs in summary["families"].items():
        for p in fs["paths"]:
            for i, h in enumerate(p["spacing_m"]):
                o, e, v = p["orders"][i - 1] if i else None, p["error"][i], (p.get("value") or [None] * (i + 1))[i]
                out.append(f"| {f} | {p['measure']} ({p['reference_kind']}) | {p['courant']:g} | {h * 1e3:g} | {'—' if v is None else f'{v:.5g}'} | "
                           f"{p['particle_steps'][i]:,} | {p['cpu_s'][i] or 0:.1f} | {p['wall_s'][i] or 0:.1f} | {'—' if e is None else f'{e:.3g}'} | "
                           f"{'—' if o is None else f'{o:.2f}'} |")
            rich = p.get("richardson")
            if rich and rich.get("limit") is not None:
                out.append(f"| {f} | {p['measure']}: Richardson limit {rich['limit']:.5g}, observed order {rich['order']:.2f} | {p['courant']:g} | | | | | | | |")
        for r in fs["failed"]:
            out.append(f"| {f} | **failed**: {r['failed'][:160]} | {r['courant']:g} | {r['spacing_m'] * 1e3:g} | | | | | | |")
    return "\n".join(out) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--out", default="out/convergence", help="output folder (default %(default)s)")
    ap.add_argument("--families", default=DEFAULT, help=f"comma list of {', '.join(FAMILIES)} (default {DEFAULT})")
    ap.add_argument("--point", choices=("tunnel_elastic",), help=argparse.SUPPRESS)     # one run, started by the study itself
    ap.add_argument("--spacing", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--courant", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--progress", type=float, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.point:
        return tunnel_elastic_point(a)
    fams = [f.strip() for f in a.families.split(",") if f.strip()]
    bad = [f for f in fams if f not in FAMILIES]
    if bad or not fams:
        ap.error(f"--families: unknown {bad}; allowed {', '.join(FAMILIES)}")
    os.makedirs(a.out, exist_ok=True)
    rows = []
    todo = sorted(((f, l, c) for f in fams for l in FAMILIES[f][0] for c in FAMILIES[f][1]), key=lambda x: (-x[1] / FAMILIES[x[0]][0][0], -x[2]))
    try:
        for i, (f, l, c) in enumerate(todo):
            print(f"[convergence] {i + 1}/{len(todo)} {f} l = {l:g} m C = {c:g}", flush=True)
            rows.append(run_point(f, l, c, a.out))
            r = rows[-1]
            print(f"[convergence]   " + (f"FAILED {r['failed']}" if r.get("failed") else f"cpu {r.get('cpu_s', 0):.1f} s"), flush=True)
    except KeyboardInterrupt:
        print("[convergence] interrupted: the finished runs are kept; the same command continues", flush=True)
    keys = sorted({k for r in rows for k in r})
    with open(os.path.join(a.out, "runs.csv"), "w") as fh:
        fh.write(",".join(keys) + "\n")
        for r in rows:
            fh.write(",".join(str(r.get(k, "")).replace(",", ";") for k in keys) + "\n")
    summary = dict(families={f: dict(paths=paths(f, [r for r in rows if r["family"] == f]),
                                      failed=[r for r in rows if r["family"] == f and r.get("failed")]) for f in fams})
    json.dump(summary, open(os.path.join(a.out, "summary.json"), "w"), indent=1, default=float)
    figure(summary, os.path.join(a.out, "error_vs_time.png"))
    open(os.path.join(a.out, "table.md"), "w").write(table(summary))
    print(f"[convergence] wrote {a.out}/summary.json, runs.csv, table.md, error_vs_time.png", flush=True)
    return 0 if all(not r.get("failed") for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
