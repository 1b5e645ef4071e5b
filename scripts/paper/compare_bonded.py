"""yade-mpm side by side with YADE's bonded-particle rock model JCFpm (Scholtès & Donzé 2012).

1. Uniaxial compression of the paper's Sec. 3.3 specimen (50 × 150 mm, Miao et al. 2018 sandstone),
   intact and with the 25 × 2 mm open flaw at 30° (cases.uniaxial_flaw_geometry, the paper's orientation),
   loaded from the top at --platen-speed, reached by a linear ramp over 1 ms; local damping 0.4 on both sides:
   - MPM: the scene of cases.uniaxial_flaw ("intact"/"open"): 2D plane strain WLS-MPM with DP–GK damage,
     free-slip base, frictionless rigid YADE platen in PTS contact (RigidBodies), grid nodes inside the flaw
     excluded, grid spacing --mpm-spacing, ppc = 2; end caps: no tensile damage within 3 cells of the base
     and the platen (--capped-ends; without them the layer under the penalty contact cracks first).
   - JCFpm: between two frictionless YADE walls, the top one closing as the MPM platen; a layer of bonded spheres, centres at z = 0, motion restricted to the plane
     (yade_mpm_paper.validation.bonded; plane strain: ε_zz = 0 exactly), mean radius --dem-radius, thickness mapping
     t = 2 r̄ (stress = platen force / (W t)).
   "E" on both sides is the apparent plane-strain modulus Δσ_yy/Δε_yy of the test (slope of the first
   rise between 25 % and 50 % of the peak, platen displacement / specimen height); for the elastic MPM
   rock it is E/(1 − ν²). Peak = the largest stress up to the strain cap (--max-strain for MPM,
   --dem-max-strain for JCFpm). JCFpm micro-parameters are calibrated on the intact specimen to the
   MPM's E and peak (fixed-point scaling: young ← young·E_mpm/E, tensile and cohesion ← ·σ_mpm/σ,
   ks/kn = 0.3, cohesion/tensile = 4, contact friction φ = 38°, until both are within --calib-tol),
   then used unchanged on the flawed specimen.
2. Circular opening (paper Sec. 3.1 loads) against Kirsch: stress error vs run time (CPU seconds, one
   thread) for both methods on one plot. MPM: scripts/paper/circular_opening.py at 2l, 1.5l, l on an
   --kirsch-domain block; JCFpm: unbreakable bonds, far-field forces on the edge spheres, Love–Weber
   stress in windows of radius a/2 along the two lines (Kirsch averaged over the same windows),
   several sphere sizes.

Outputs in --out: summary.json ({intact, open_flaw: {mpm, jcfpm: {youngs_modulus_GPa, peak_stress_MPa,
particles, wall_time_s, cpu_time_s, ...}}, kirsch: [{method, wall_time_s, cpu_time_s, l2_rel_error_max,
...}], calibration}), calibration.csv, curves_*.csv, stress_strain.png, cracks_intact.png,
cracks_open_flaw.png, kirsch_error_vs_time.png/.csv. An MPM run the solver stops keeps its curve up to the stop
(end_reason "error" and the message in summary.json); every part still runs, the stopped runs are listed under
"stopped" and the exit status is 1. Results and discussion: doc/validation/mpm_vs_bonded.md.

    PYTHONPATH=py OMP_NUM_THREADS=1 /usr/bin/python3 scripts/paper/compare_bonded.py --out out/compare_bonded
    ... --parts kirsch          # one part only (uniaxial, kirsch)
    ... --parts mpm_intact & ... --parts mpm_open_flaw; ... --parts uniaxial --reuse-mpm   # MPM in parallel
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

import yade_mpm as ym
from yade_mpm.fields import id_order
from yade_mpm import rocks
from yade_mpm_paper import cases
from yade_mpm_paper.validation import bonded
from yade_mpm import output as out

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_bonded_figures as figures  # noqa: E402  (the sibling module: this script's figures and curve files)

MPa, GPa = 1e6, 1e9
SAND = rocks.MIAO2018_SANDSTONE
# JCFpm choices kept fixed during the calibration (documented in doc/validation/mpm_vs_bonded.md)
KS_KN = 0.3              # ks/kn (JCFpmMat.poisson)
COH_OVER_TENS = 4.0      # bond cohesion / tensile strength
FRICTION_DEG = math.degrees(SAND["frictionAngle"])
# initial guess from one pilot run (this packing, r̄ = 1 mm, 1 m/s ramped, young = 16.5 GPa, tensile = 66 MPa):
# E_app = 0.5525·young, peak = 2.529·tensile; any guess within a factor of a few converges, in more runs
PILOT_E_RATIO, PILOT_PEAK_RATIO = 0.5525, 2.529


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--parts", default="uniaxial,kirsch",
                   help="comma list of: uniaxial, kirsch, mpm_intact, mpm_open_flaw (the last two only run and save one MPM "
                        "uniaxial test, for running them in parallel before 'uniaxial --reuse-mpm')")
    p.add_argument("--platen-speed", type=float, default=1.0, help="platen closing speed [m/s] (both methods)")
    p.add_argument("--mpm-spacing", type=float, default=1.25e-3, help="MPM grid spacing [m] (the 2 mm flaw spans 1.6 cells)")
    p.add_argument("--dem-radius", type=float, default=1.0e-3, help="JCFpm mean sphere radius [m]")
    p.add_argument("--calib-tol", type=float, default=0.05, help="calibration stops when E and peak are within this")
    p.add_argument("--calib-iters", type=int, default=4, help="maximum calibration runs")
    p.add_argument("--calib-ratios", type=float, nargs=2, default=[PILOT_E_RATIO, PILOT_PEAK_RATIO], metavar=("E_RATIO", "PEAK_RATIO"),
                   help="initial guess: E_app/young and peak/tensile of an earlier run (default: the pilot run's)")
    p.add_argument("--max-strain", type=float, default=0.02, help="axial strain limit of an MPM uniaxial run")
    p.add_argument("--dem-max-strain", type=float, default=0.03,
                   help="axial strain limit of a JCFpm uniaxial run (elastic-brittle: it stops after its peak)")
    p.add_argument("--kirsch-domain", type=float, default=1.2, help="side of the square block of the Kirsch test [m]")
    p.add_argument("--kirsch-mpm-spacing", type=float, default=0.02, help="finest MPM spacing [m] (runs: 2l, 1.5l, l)")
    p.add_argument("--kirsch-dem-radii", type=float, nargs="+", default=[0.02, 0.014, 0.01, 0.007],
                   help="JCFpm mean radii [m] of the Kirsch runs")
    p.add_argument("--capped-ends", action=argparse.BooleanOptionalAction, default=True,
                   help="MPM: no tensile damage within CAP_CELLS = 3 cells of the platens (default on)")
    p.add_argument("--reuse-mpm", action="store_true", help="reuse the MPM uniaxial runs saved in OUT (mpm_*.npz)")
    p.add_argument("--cache", default=None, help="directory for cached disc packings (default: OUT/packings)")
    a = p.parse_args(argv)
    parts = set(a.parts.split(","))
    if not parts <= {"uniaxial", "kirsch", "mpm_intact", "mpm_open_flaw"}:
        raise ValueError(f"--parts = {a.parts}: allowed uniaxial, kirsch, mpm_intact, mpm_open_flaw")
    for n in ("platen_speed", "mpm_spacing", "dem_radius", "calib_tol", "max_strain", "dem_max_strain", "kirsch_domain",
              "kirsch_mpm_spacing"):
        v = getattr(a, n)
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"--{n.replace('_', '-')} = {v} must be > 0")
    if not a.dem_radius < 0.005:
        raise ValueError(f"--dem-radius = {a.dem_radius} m must be < 5 mm (≥ 5 spheres across the 50 mm specimen)")
    if any(not (math.isfinite(x) and x > 0) for x in a.calib_ratios):
        raise ValueError(f"--calib-ratios = {a.calib_ratios} must be > 0")
    if a.calib_iters < 1:
        raise ValueError(f"--calib-iters = {a.calib_iters} must be ≥ 1")
    if any(not (0 < r <= 0.05) for r in a.kirsch_dem_radii):
        raise ValueError(f"--kirsch-dem-radii = {a.kirsch_dem_radii} m: each must be in (0, 0.05] m")
    a.parts = parts
    a.cache = a.cache or os.path.join(a.out, "packings")
    return a


def log(msg):
    print(f"[compare_bonded] {msg}", flush=True)


# ---------------------------------------------------------------------------------------------- MPM
SPECIMEN = (cases.UNIAXIAL_WIDTH, cases.UNIAXIAL_HEIGHT)     # width × height [m] (paper Sec. 3.3)
CAP_CELLS = 3                               # MPM end caps: no tensile damage within 3 cells of a platen
DAMPING = 0.4                               # local (Cundall) damping on both sides: MPM solver.damping, YADE Newton
RAMP_TIME = 1e-3                            # platen speed ramped linearly from 0 over this time [s] (both methods)


def mpm_uniaxial_saved(flaw, a):
    """mpm_uniaxial, saved to OUT/mpm_<case>.npz (reused with --reuse-mpm when the spacing and speed match)."""
    path = os.path.join(a.out, f"mpm_{'open_flaw' if flaw else 'intact'}.npz")
    if a.reuse_mpm and os.path.exists(path):
        z = dict(np.load(path))
        if float(z["spacing"]) == a.mpm_spacing and float(z["speed"]) == a.platen_speed:
            log(f"reusing {path}")
            return {k: (v.item() if v.ndim == 0 else v) for k, v in z.items()}
    r = mpm_uniaxial(flaw, a)
    np.savez(path, spacing=a.mpm_spacing, speed=a.platen_speed, **r)
    return r


def mpm_uniaxial(flaw, a):
    """MPM uniaxial run on the scene of ``cases.uniaxial_flaw`` ("intact" or "open": free-slip base, rigid
    frictionless YADE platen in PTS contact, the top moving down at platen_speed after a RAMP_TIME ramp),
    DP–GK sandstone, ppc = 2, local damping DAMPING, end caps of CAP_CELLS cells (--capped-ends), grid room
    of 8 cells beside the specimen. Returns dict(strain, stress [Pa] compression +, particles, wall_time_s,
    pos, damage)."""
    l = a.mpm_spacing
    s, sc = cases.uniaxial_flaw("open" if flaw else "intact", l, platen_speed=a.platen_speed, label="mpmUniax",
                                ramp_time=RAMP_TIME, end_cap_cells=CAP_CELLS if a.capped_ends else 0, side_room=8 * l)
    s.damping = DAMPING
    label = "mpm " + ("open flaw" if flaw else "intact")
    prog = ym.progress.Progress(a.max_strain, label, 20.0)
    strain, stress, peak = [0.0], [0.0], 0.0
    t0, c0 = time.time(), time.process_time()
    end_reason, error = "post_peak", ""
    while True:
        try:
            sc["advance"](100)
        except (ym.MpmSimulationError, RuntimeError) as e:   # the solver stopped (through YADE: a RuntimeError): keep the curve
            end_reason, error = "error", str(e).split("ERROR:")[-1].strip().splitlines()[0]
            log(f"{label}: stopped by the solver at strain {strain[-1]:.5f}: {error}")
            break
        strain.append(sc["axial_strain"]())
        stress.append(sc["axial_stress"]())
        peak = max(peak, stress[-1])
        prog.update(s.steps, strain[-1], solver=s)
        if strain[-1] >= a.max_strain:
            end_reason = "max_strain"
            break
        if len(stress) > 3 and max(stress[-3:]) < 0.7 * peak:   # 3 records past a 30 % drop
            break
    wall, cpu = time.time() - t0, time.process_time() - c0
    o = id_order(s)
    acc = ym.removed(s)                                   # debris that left the grid (Solver.outside)
    return dict(strain=np.array(strain), stress=np.array(stress), particles=int(s.numParticles + acc["count"]), wall_time_s=wall,
                cpu_time_s=cpu, pos=ym.get(s, "pos", o), damage=ym.get(s, "damage", o), steps=int(s.steps), dt=float(s.lastDt),
                end_reason=end_reason, error=error, removed_particles=int(acc["count"]), removed_mass_kg=float(acc["mass"]))


# ------------------------------------------------------------------------------------------- JCFpm
def packing(a, lo, hi, r):
    """Disc packing (cached) and the wall time it took to make it (0 when cached before)."""
    t0 = time.time()
    P = bonded.disc_packing(lo, hi, r, cache_dir=a.cache)
    return P, time.time() - t0


def jcfpm_uniaxial(P, micro, holes, a, label):
    prog = ym.progress.Progress(a.dem_max_strain, label, 20.0)
    res = bonded.uniaxial(P, micro, a.platen_speed, SAND["density"], holes=holes, max_strain=a.dem_max_strain, damping=DAMPING,
                          crack_dir=os.path.join(a.out, "jcfpm_cracks"), label=label, ramp_time=RAMP_TIME,
                          progress=lambda e, s: prog.update(0, e))
    res["youngs_modulus"] = bonded.apparent_modulus(res["strain"], res["stress"])
    res["peak_stress"] = float(np.max(res["stress"]))
    return res


def calibrate(P, target_E, target_peak, a):
    """Fixed-point scaling of (young) and (tensile, cohesion) until E and peak are within calib_tol."""
    er, pr = a.calib_ratios
    micro = bonded.JcfpmMicro(young=target_E / er, ks_kn=KS_KN, tensile=target_peak / pr,
                              cohesion=COH_OVER_TENS * target_peak / pr, friction_deg=FRICTION_DEG)
    rows, res = [], None
    t0 = time.time()
    for it in range(a.calib_iters):
        res = jcfpm_uniaxial(P, micro, (), a, f"calib{it}")
        eE, eP = res["youngs_modulus"] / target_E - 1, res["peak_stress"] / target_peak - 1
        rows.append(dict(iteration=it, **micro.as_dict(), youngs_modulus_GPa=res["youngs_modulus"] / GPa,
                         peak_stress_MPa=res["peak_stress"] / MPa, rel_error_E=eE, rel_error_peak=eP,
                         wall_time_s=res["wall_time_s"], cpu_time_s=res["cpu_time_s"]))
        log(f"calibration {it}: young = {micro.young / GPa:.3f} GPa, tensile = {micro.tensile / MPa:.3f} MPa → "
            f"E = {res['youngs_modulus'] / GPa:.3f} GPa ({100 * eE:+.1f} %), peak = {res['peak_stress'] / MPa:.2f} MPa "
            f"({100 * eP:+.1f} %), {res['wall_time_s']:.0f} s")
        if abs(eE) <= a.calib_tol and abs(eP) <= a.calib_tol:
            break
        s = target_peak / res["peak_stress"]
        micro = bonded.JcfpmMicro(young=micro.young * target_E / res["youngs_modulus"], ks_kn=micro.ks_kn,
                                  tensile=micro.tensile * s, cohesion=micro.cohesion * s, friction_deg=micro.friction_deg)
    return micro, res, rows, time.time() - t0


# ------------------------------------------------------------------------------------------- parts
def uniaxial_part(a, summary):
    lo, hi = (0.0, 0.0), SPECIMEN
    P, t_pack = packing(a, lo, hi, a.dem_radius)
    log(f"disc packing: {len(P)} spheres, r̄ = {a.dem_radius * 1e3} mm ({t_pack:.1f} s)")
    results = {}
    mpm_int = mpm_uniaxial_saved(False, a)
    mpm_int["youngs_modulus"] = bonded.apparent_modulus(mpm_int["strain"], mpm_int["stress"])
    mpm_int["peak_stress"] = float(np.max(mpm_int["stress"]))
    log(f"MPM intact: E = {mpm_int['youngs_modulus'] / GPa:.3f} GPa, peak = {mpm_int['peak_stress'] / MPa:.2f} MPa, "
        f"{mpm_int['wall_time_s']:.0f} s")
    micro, dem_int, rows, t_cal = calibrate(P, mpm_int["youngs_modulus"], mpm_int["peak_stress"], a)
    with open(os.path.join(a.out, "calibration.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    results["intact"] = dict(mpm=mpm_int, jcfpm=dem_int)
    holes = [cases.uniaxial_flaw_geometry()["polygon"]]
    mpm_fl = mpm_uniaxial_saved(True, a)
    mpm_fl["youngs_modulus"] = bonded.apparent_modulus(mpm_fl["strain"], mpm_fl["stress"])
    mpm_fl["peak_stress"] = float(np.max(mpm_fl["stress"]))
    dem_fl = jcfpm_uniaxial(P, micro, holes, a, "open_flaw")
    results["open_flaw"] = dict(mpm=mpm_fl, jcfpm=dem_fl)
    for case, r in results.items():
        for meth, q in r.items():
            figures.write_curve(os.path.join(a.out, f"curves_{case}_{meth}.csv"), q["strain"], q["stress"])
            summary.setdefault(case, {})[meth] = dict(youngs_modulus_GPa=q["youngs_modulus"] / GPa,
                                                      peak_stress_MPa=q["peak_stress"] / MPa,
                                                      particles=int(q["particles"]), wall_time_s=q["wall_time_s"],
                                                      cpu_time_s=q["cpu_time_s"], steps=int(q["steps"]))
            if meth == "mpm":                     # how the run ended; debris removed after leaving the grid
                summary[case][meth].update({k: (q[k].item() if isinstance(q.get(k), np.ndarray) else q.get(k))
                                            for k in ("end_reason", "error", "removed_particles", "removed_mass_kg")})
                if q.get("end_reason") == "error":
                    summary.setdefault("stopped", []).append(f"{case}/mpm: {q.get('error')}")
        keep = np.ones(len(P), bool)
        for h in (holes if case == "open_flaw" else ()):
            keep &= ~bonded.overlapping(h, P[:, :2], P[:, 2])
        r["jcfpm"]["discs"] = P[keep]
        figures.plot_cracks(os.path.join(a.out, f"cracks_{case}.png"), r["mpm"], r["jcfpm"], holes if case == "open_flaw" else [],
                            f"{case.replace('_', ' ')}: end of the run (MPM ε = {100 * r['mpm']['strain'][-1]:.2f} %, "
                            f"JCFpm ε = {100 * r['jcfpm']['strain'][-1]:.2f} %)")
        for meth in ("jcfpm",):
            q = r[meth]
            summary[case][meth].update(tensile_cracks=q["tensile_cracks"], shear_cracks=q["shear_cracks"], bonds=q["bonds"])
    figures.plot_curves(os.path.join(a.out, "stress_strain.png"), results)
    summary["calibration"] = dict(procedure="fixed-point scaling: young *= E_mpm/E, tensile and cohesion *= peak_mpm/peak; "
                                            f"ks/kn = {KS_KN}, cohesion/tensile = {COH_OVER_TENS}, friction = {FRICTION_DEG:.1f} deg",
                                  runs=rows, wall_time_s=t_cal, micro=micro.as_dict(), packing_wall_time_s=t_pack,
                                  packing_spheres=int(len(P)), mean_radius_m=a.dem_radius,
                                  layer_thickness_m=bonded.layer_thickness(P), platen_speed_m_s=a.platen_speed,
                                  mpm_spacing_m=a.mpm_spacing)


def kirsch_part(a, summary):
    """Both methods on the same block, one thread; run time = CPU seconds of the run (insensitive to other
    processes on a shared host; equal to the wall time on an idle core), wall seconds kept too."""
    import resource
    rows = []
    # MPM: scripts/paper/circular_opening.py, one subprocess per spacing (its own errors; CPU time from rusage)
    l = a.kirsch_mpm_spacing
    for sp in (2 * l, 1.5 * l, l):
        mdir = os.path.join(a.out, f"kirsch_mpm_{sp * 1e3:g}mm")
        cmd = [sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "circular_opening.py"), "--out", mdir,
               "--domain", str(a.kirsch_domain), "--spacing", str(sp), "--no-vtu", "--threads", "1", "--no-convergence"]
        log("MPM circular opening: " + " ".join(cmd[2:]))
        c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        if subprocess.run(cmd, env=dict(os.environ, OMP_NUM_THREADS="1")).returncode != 0:   # the next run still goes
            summary.setdefault("stopped", []).append(f"kirsch/mpm {sp * 1e3:g} mm: circular_opening.py failed (see its output in {mdir})")
            log(f"MPM circular opening at {sp * 1e3:g} mm failed; going on")
            continue
        c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        with open(os.path.join(mdir, "summary.json")) as f:
            ms = json.load(f)
        rows.append(dict(method="mpm", resolution_m=sp, particles=ms["particles"], wall_time_s=ms["wall_time_s"],
                         cpu_time_s=(c1.ru_utime + c1.ru_stime) - (c0.ru_utime + c0.ru_stime),
                         l2_rel_error_max=ms["l2_rel_error_max"], l2_rel_error_near_max=ms["l2_rel_error_near_max"]))
    # JCFpm
    c, L = cases.OPENING_CENTER, a.kirsch_domain
    micro = bonded.JcfpmMicro(young=rocks.GRANITE["young"], ks_kn=KS_KN, tensile=1e15, cohesion=1e15, friction_deg=30.0)
    for r in sorted(a.kirsch_dem_radii, reverse=True):
        P, t_pack = packing(a, (c - L / 2, c - L / 2), (c + L / 2, c + L / 2), r)
        res = bonded.circular_opening(P, micro, (c, c), cases.OPENING_RADIUS, cases.OPENING_SXX, cases.OPENING_SYY,
                                      rocks.GRANITE["density"])
        log(f"JCFpm circular opening r̄ = {r} m: {res['particles']} spheres, {res['steps']} steps, "
            f"{res['cpu_time_s']:.1f} s CPU, max L2 error {100 * res['l2_rel_error_max']:.1f} % "
            f"(2a ≤ r ≤ 5a: {100 * res['l2_rel_error_near_max']:.1f} %)")
        rows.append(dict(method="jcfpm", resolution_m=r, particles=res["particles"], wall_time_s=res["wall_time_s"],
                         cpu_time_s=res["cpu_time_s"], l2_rel_error_max=res["l2_rel_error_max"],
                         l2_rel_error_near_max=res["l2_rel_error_near_max"], packing_wall_time_s=t_pack))
    keys = ["method", "resolution_m", "particles", "wall_time_s", "cpu_time_s", "l2_rel_error_max", "l2_rel_error_near_max",
            "packing_wall_time_s"]
    with open(os.path.join(a.out, "kirsch_error_vs_time.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    summary["kirsch"] = [{k: r[k] for k in keys if k in r} for r in rows]
    summary["kirsch_setup"] = dict(domain_m=L, hole_radius_m=cases.OPENING_RADIUS, far_field_MPa=[cases.OPENING_SXX / MPa,
                                   cases.OPENING_SYY / MPa], jcfpm_window_radius_m=0.5 * cases.OPENING_RADIUS,
                                   time="cpu_time_s: CPU seconds of the one-thread run; wall_time_s depends on the host load")
    figures.plot_kirsch_error_vs_time(os.path.join(a.out, "kirsch_error_vs_time.png"), rows, L, cases.OPENING_RADIUS)


def main(argv=None):
    a = parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    path = os.path.join(a.out, "summary.json")
    summary = json.load(open(path)) if os.path.exists(path) else {}
    summary["case"] = "yade-mpm (WLS-MPM, DP-GK) vs YADE JCFpm bonded particles: Sec. 3.3 uniaxial + Sec. 3.1 Kirsch"
    summary["stopped"] = []                       # runs stopped by an error (named; the others still run)
    for case in ("mpm_intact", "mpm_open_flaw"):
        if case in a.parts:
            mpm_uniaxial_saved(case == "mpm_open_flaw", a)
    if "kirsch" in a.parts:
        kirsch_part(a, summary)
        out.write_summary(a.out, summary)
    if "uniaxial" in a.parts:
        uniaxial_part(a, summary)
        out.write_summary(a.out, summary)
    out.write_summary(a.out, summary)
    log(f"wrote {path}")
    if summary["stopped"]:
        log("stopped by an error: " + "; ".join(summary["stopped"]))
        sys.exit(1)
    return summary


if __name__ == "__main__":
    main()
