#!/usr/bin/python3
"""Regression check between builds (issue 19, "the promise about bits").

One build gives the same bits for any thread count (tests/test_determinism.py). Between builds, results
may change in the last bits (FMA contraction, reordered sums, fused loops) as long as the reference
results stay within these tolerances of the numbers a reference build stored:

    Kirsch (circular opening, 2.4 m block, l = 0.04 m, 8 ms of damped relaxation): the four L2 errors of σxx, σyy on the x and y
        lines                                                       relative change ≤ 1e-3
    Sneddon (pressurised line crack, 2.5 m block, l = 0.04 m, 5 P-wave transits of damped loading): centre
        opening error and L2 opening error                          relative change ≤ 1e-3
    tunnel, default 2 mm grid, intact: axial stress at 0.5, 1 and 2 mm of platen travel    ≤ 0.5 %
        first crack (first particle at D = 1): time ≤ 2 %; location, each coordinate within 2 % of
        the 150 mm specimen (3 mm), same place (floor, roof, wall); damage symmetry at 8 ms          absolute change ≤ 0.02
    uniaxial flaw, default 2 mm grid: peak stress of intact, open and filled (μ_con = 0.4)   ≤ 1 %

    /usr/bin/python3 scripts/regress.py --out /tmp/reg --check            # against scripts/regress_reference.json
    /usr/bin/python3 scripts/regress.py --out /tmp/reg --record FILE      # store this build's numbers
    ... --tree DIR      run another checkout's scripts and package (e.g. a worktree of the reference build)
    ... --only kirsch,sneddon   a subset (tunnel and uniaxial take minutes)
    ... --courant C     every case at the Courant number C (a Δt study; the reference is at the solver's default)

Re-recorded (not a tolerance miss): tunnel and uniaxial on main 90d5a68, issue 18's modelling change of the ε̄p
increment (DpGkMat.plasticStrainIncrement = 'reference-code', doc/reference/damage_growth_law.md): uniaxial peaks intact
95.497 → 95.401, open 37.208 → 36.151, filled μ_con = 0.4 45.104 → 44.487 MPa; tunnel σ at 2 mm 202.889 → 202.449 MPa
(within tolerance; first crack unchanged). Kirsch and Sneddon (elastic) passed unchanged and were not re-recorded.
Re-recorded again for the kinematic contact law becoming the default (ContactParams.law, doc/reference/contact.md "Contact
laws"; the penalty law of Eq. 23 stays as law='penalty'): uniaxial peaks intact 95.401 → 95.657 (+0.27 %), open
36.151 → 37.117 (+2.7 %), filled μ_con = 0.4 44.487 → 46.929 MPa (+5.5 %); tunnel σ at 0.5 / 1 / 2 mm 52.189 → 52.474,
104.560 → 105.141, 202.449 → 203.354 MPa (+0.55, +0.56, +0.45 %); first crack time −0.22 %, same place (floor, x 75,
y 54.5 mm); Kirsch and Sneddon (no bodies) within 1.2e-4.
Re-recorded for the kinematic law's correction of the MUSL remap (KinematicContact::constrainRemap, doc/reference/contact.md):
uniaxial filled μ_con = 0.4 46.929 → 45.259 MPa (−3.6 %, the one miss), intact 95.657 → 95.612, open 37.117 → 37.165;
tunnel σ at 0.5 / 1 / 2 mm −0.07, −0.08, −0.09 %, first crack unchanged; Kirsch and Sneddon within 3.5e-8.
Re-recorded for FLIP (Solver.velocityUpdate = 'flip') and C = 1 becoming the default, with the remap correction on the
tangential part only (doc/reference/algorithm.md "The particle velocity update and C"): uniaxial open 37.165 → 21.325
(−42.6 %), filled μ_con = 0.4 45.259 → 32.696 MPa (−27.8 %; the tangential-only correction alone, under Eq. 6 at
C = 0.5: 49.71), intact 95.612 → 95.651; tunnel σ +0.05 / −0.06 / +0.03 %, first crack −0.26 %, same place; Kirsch
and Sneddon (damped, a fixed 8 ms / 5 transits: a step with damping takes Eq. 6, and at C = 1 the per-step damping has
relaxed less) up to 3.3 % (Kirsch σyy on the y line) and 7.7 % (Sneddon L2) in their errors against the analytic
solutions. Against --courant 0.25 (the same build): tunnel and intact within 0.03 %, filled μ_con = 0.4 −0.64 %, open
+1.28 % (at C = 0.5 +3.0 %: no trend, the open flaw's crack start scatters), Kirsch and Sneddon up to 9 % and 17 %
(fixed-time relaxation; relaxed to convergence both are C-independent: Kirsch's four L2 errors within 0.02 points at
C = 1, 0.5, 0.25, Sneddon after 60 transits centre −2.94 / −3.11 %, L2 7.20 / 7.18 % at C = 1 / 0.25).

Each case runs in its own subprocess with one thread (results do not depend on the thread count);
--jobs of them at a time. Exit code 0 when every checked number is within its tolerance, 1 otherwise.
"""
import argparse
import json
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REFERENCE = os.path.join(ROOT, "scripts", "regress_reference.json")
UNIAXIAL_RUNS = ("intact", "open", "filled_mu0.4_c0MPa")
TUNNEL_SIZE_MM = 150.0
REUSE = False   # --reuse: read the outputs already in OUT instead of running
COURANT = None  # --courant: every case at this C (default: each script's default, the solver's C)

# case: (script, arguments); {out} is the case's output folder
CASES = {
    # a fixed simulated time (tol never met): the default stop "changes < tol" ends at a step that moves with the last bit
    "kirsch": ("circular_opening.py", ["--domain", "2.4", "--spacing", "0.04", "--no-vtu", "--progress", "600", "--tol", "1e-12",
                                       "--max-time", "0.008"]),
    # a fixed time too: the default stop (the centre opening settled, sampled every quarter transit) moved from step 608
    # to 576 with a last-bit change, and the opening still creeps then (L2 error 0.0625 → 0.0621)
    "sneddon": ("penny_crack.py", ["--parts", "elastic", "--size", "2.5", "--spacing", "0.04", "--progress", "600",
                                   "--crack-nodes", "shared", "--elastic-tol", "1e-12", "--elastic-max-transits", "5"]),
    "tunnel": ("tunnel_spalling.py", ["--cases", "intact", "--checkpoint-every", "0", "--vtu-every", "1", "--progress", "600"]),
    "uniaxial": ("uniaxial_flaw.py", ["--runs", "intact,open,filled:0.4:0", "--vtu-every", "1", "--progress", "600"]),
}
# (quantity, kind, tolerance): kind "rel" = |new − ref| ≤ tol·|ref|, "abs" = |new − ref| ≤ tol
TOLERANCES = {
    "kirsch": [(f"l2_rel_error_{c}_{n}", "rel", 1e-3) for n in ("xline", "yline") for c in ("sxx", "syy")],
    "sneddon": [("uy_center_rel_error", "rel", 1e-3), ("uy_l2_rel_error", "rel", 1e-3)],
    "tunnel": [(f"axial_stress_MPa_at_{d}mm", "rel", 5e-3) for d in ("0.5", "1", "2")]
    + [("first_crack_time_s", "rel", 0.02), ("first_crack_x_mm", "abs", 0.02 * TUNNEL_SIZE_MM),
       ("first_crack_y_mm", "abs", 0.02 * TUNNEL_SIZE_MM), ("symmetry_damage", "abs", 0.02)],
    "uniaxial": [(f"peak_stress_MPa_{r}", "rel", 0.01) for r in UNIAXIAL_RUNS],
}


def run_case(tree, name, out):
    """Runs one case of `tree` into out/name; returns (its numbers, wall seconds)."""
    script, argv = CASES[name]
    d = os.path.join(out, name)
    if REUSE and os.path.exists(os.path.join(d, "summary.json")):
        return read_numbers(name, d), 0.0
    env = dict(os.environ, PYTHONPATH=os.path.join(tree, "py"), OMP_NUM_THREADS="1")
    t0 = time.time()
    extra = ["--courant", f"{COURANT:g}"] if COURANT is not None else []
    path = os.path.join(tree, "scripts", "paper", script)
    path = path if os.path.exists(path) else os.path.join(tree, "scripts", script)      # trees before scripts/paper
    r = subprocess.run([sys.executable, path, "--out", d, *argv, *extra], env=env, capture_output=True,
                       text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{name}: {script} failed (exit {r.returncode}):\n{r.stdout[-1500:]}\n{r.stderr[-3000:]}")
    return read_numbers(name, d), time.time() - t0


def read_numbers(name, d):
    s = json.load(open(os.path.join(d, "summary.json")))
    if name in ("kirsch", "sneddon"):
        return {q: float(s[q]) for q, _, _ in TOLERANCES[name]}
    if name == "tunnel":
        e = s["cases"][0]
        at = {round(p["displacement_mm"], 6): p["stress_MPa"] for p in e["axial_stress_MPa_at"]}
        fc = json.load(open(os.path.join(d, "intact", "case.json")))["first_crack"]
        out = {f"axial_stress_MPa_at_{k:g}mm": float(at[k]) for k in (0.5, 1.0, 2.0)}
        out.update(first_crack_time_s=fc["time"], first_crack_x_mm=fc["centroid"][0] * 1e3, first_crack_y_mm=fc["centroid"][1] * 1e3,
                   first_crack_place=fc["location"],
                   symmetry_damage=e["symmetry_damage"])
        return out
    runs = {r["variant"] if r["variant"] != "filled" else f"filled_mu{r['mu_con']:g}_c{r['c_con_MPa']:g}MPa": r for r in s["runs"]}
    return {f"peak_stress_MPa_{k}": float(runs[k]["peak_stress_MPa"]) for k in UNIAXIAL_RUNS}


def compare(ref, new):
    """Rows (case, quantity, reference, new, change, tolerance text, ok)."""
    rows = []
    for case, qs in TOLERANCES.items():
        if case not in new:
            continue
        for q, kind, tol in qs:
            a, b = ref[case][q], new[case][q]
            if kind == "rel":
                ch = abs(b - a) / abs(a) if a != 0 else (0.0 if b == 0 else float("inf"))
            else:
                ch = abs(b - a)
            rows.append((case, q, a, b, ch, f"{'rel' if kind == 'rel' else 'abs'} ≤ {tol:g}", ch <= tol))
        if case == "tunnel":
            a, b = ref[case]["first_crack_place"], new[case]["first_crack_place"]
            rows.append((case, "first_crack_place", a, b, float(a != b), "same", a == b))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="output folder of the runs")
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--check", nargs="?", const=REFERENCE, metavar="FILE", help="compare with stored numbers (default scripts/regress_reference.json)")
    g.add_argument("--record", metavar="FILE", help="store this build's numbers in FILE")
    ap.add_argument("--tree", default=ROOT, help="checkout whose scripts and py/ are run (default: this one)")
    ap.add_argument("--only", default=",".join(CASES), help=f"comma-separated subset of {', '.join(CASES)}")
    ap.add_argument("--jobs", type=int, default=2, help="cases run at a time (default 2)")
    ap.add_argument("--reuse", action="store_true", help="read the outputs already in OUT (a finished earlier run) instead of running")
    ap.add_argument("--courant", type=float, default=None, help="run every case at this Courant number (a study of Δt; default: the solver's)")
    ap.add_argument("--note", default="", help="--record: text stored with the numbers (e.g. the commit)")
    a = ap.parse_args()
    global REUSE, COURANT
    REUSE, COURANT = a.reuse, a.courant
    names = [n.strip() for n in a.only.split(",") if n.strip()]
    if not names or any(n not in CASES for n in names):
        ap.error(f"--only: allowed {', '.join(CASES)}")
    if a.jobs < 1:
        ap.error("--jobs must be ≥ 1")
    ref = None
    if a.check:
        ref = json.load(open(a.check))
        missing = [n for n in names if n not in ref.get("cases", {})]
        if missing:
            ap.error(f"--check: {a.check} has no numbers for {missing}")
    os.makedirs(a.out, exist_ok=True)
    with ThreadPoolExecutor(a.jobs) as ex:
        res = dict(zip(names, ex.map(lambda n: run_case(a.tree, n, a.out), names)))
    new = {n: v for n, (v, _) in res.items()}
    for n, (_, w) in res.items():
        print(f"[regress] {n}: {w:.0f} s  {json.dumps(new[n])}", flush=True)
    if a.record:
        old = json.load(open(a.record)) if os.path.exists(a.record) else {"cases": {}}
        old["cases"].update(new)
        old.setdefault("notes", {}).update({n: a.note for n in names})
        with open(a.record, "w") as f:
            json.dump(old, f, indent=1)
        print(f"[regress] recorded {', '.join(names)} in {a.record}")
        return 0
    rows = compare(ref["cases"], new)
    for case, q, x, y, ch, tol, ok in rows:
        print(f"{'ok  ' if ok else 'FAIL'} {case:9s} {q:32s} ref {x:.6g}  new {y:.6g}  change {ch:.3g} ({tol})" if q != "first_crack_place"
              else f"{'ok  ' if ok else 'FAIL'} {case:9s} {q:32s} ref {x}  new {y}")
    bad = [r for r in rows if not r[-1]]
    print(f"[regress] {len(rows) - len(bad)} of {len(rows)} within tolerance" + (": PASSED" if not bad else ": FAILED"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
