"""The validation report's uncertainty sections (scripts/paper/report.py): error against run time for the
reference cases (scripts/paper/convergence.py) and the spread of the damage quantities over the grid-shift
ensembles (scripts/paper/*_shifts.table run by scripts/studies/sweep.py; yade_mpm_paper.uncertainty)."""
import glob
import json
import os

from .. import uncertainty
from .document import include_notes, shown

# scene → (folder under the output root, sweep table, script); fidelity_sections.ensemble_rows maps each to its fidelity rows
ENSEMBLES = {"uniaxial": ("ensemble/uniaxial", "scripts/paper/uniaxial_shifts.table", "scripts/paper/uniaxial_flaw.py"),
             "tunnel": ("ensemble/tunnel", "scripts/paper/tunnel_shifts.table", "scripts/paper/tunnel_spalling.py"),
             "circular_opening": ("ensemble/circular_opening", "scripts/paper/circular_shifts.table", "scripts/paper/circular_opening.py"),
             "penny_crack": ("ensemble/penny_crack", "scripts/paper/penny_shifts.table", "scripts/paper/penny_crack.py")}


def command(scene):
    _, table, script = ENSEMBLES[scene]
    return f"/usr/bin/python3 scripts/studies/sweep.py {table} {script} --runner python"


def members(R, scene):
    """[(shift name, folder)] of the ensemble's finished runs, the unshifted one first (none: [])."""
    d = os.path.join(R.root, ENSEMBLES[scene][0])
    found = sorted(os.path.dirname(p) for p in glob.glob(os.path.join(d, "s*", "summary.json")))
    return sorted(((os.path.basename(f), f) for f in found), key=lambda m: (m[0] != "s0.00_0.00", m[0]))


def convergence_section(R):
    R.w("## Error against run time", "")
    d = os.path.join(R.root, "convergence")
    path = os.path.join(d, "summary.json")
    if not os.path.exists(path):
        R.w(f"*Not run here* — `/usr/bin/python3 scripts/paper/convergence.py --out {shown(d)}` writes `{shown(d)}/`.", "")
        return
    s = json.load(open(path))
    R.w(f"Each case at three or more grid spacings (each half the last; the table lists them) and two Courant numbers, every run in its own one-thread process "
        f"(`/usr/bin/python3 scripts/paper/convergence.py --out {shown(d)}`). The cost is the run's CPU time (on an idle host its wall "
        "time with one thread; the wall times are in the table) and its particle-steps. The error is against the analytic solution "
        "where there is one (Kirsch, Sneddon, the plane-strain modulus E/(1 − ν²)), otherwise against the Richardson limit of the "
        "last three grids (`yade_mpm_paper.uncertainty.richardson`, only for a monotone sequence whose changes shrink with an observed "
        "order ≥ 0.5), else against the finest run; the run the error is taken against has no error of its own.", "")
    include_notes(R, os.path.join(d, "notes.md"))
    R.figure(os.path.join(d, "error_vs_time.png"), "error_vs_time.png", "error against the run's CPU time, one line per refinement path")
    R.w(open(os.path.join(d, "table.md")).read().rstrip(), "")
    lines = []
    for f, fs in s["families"].items():
        for p in fs["paths"]:
            o = [x for x in p["orders"] if x is not None]
            if o:
                lines.append(f"- {f}, {p['measure']}, C = {p['courant']:g}: observed order " + ", ".join(f"{x:.2f}" for x in o)
                             + " (between successive halvings)")
    R.w(*(lines or ["- no path has two points yet"]), "")


# ------------------------------------------------------------------------------------------- ensembles
def _uniaxial_quantities(summary):
    """name → value of one uniaxial sweep (a run.json per run): peaks and the crack sequence at the flaw ends."""
    q = {}
    for e in summary.get("runs", []):
        name = e["variant"] + ("" if e["variant"] != "filled" else f" μ_con {e['mu_con']:g} c_con {e['c_con_MPa']:g} MPa")
        q[f"peak [MPa], {name}"] = e.get("peak_stress_MPa")
        ct = e.get("crack_times") or {}
        for k, label in (("first_tip_damage_s", "first D = 1 at a flaw end"), ("wing_longer_than_flaw_s", "wing longer than the flaw"),
                         ("through_to_a_face_s", "through to a face")):
            if k in ct:
                q[f"{label} [ms], {name}"] = None if ct[k] is None else ct[k] * 1e3
    return q


def _tunnel_quantities(folder, summary):
    """name → value of one tunnel run (the four cases): σ at 2 mm, first crack, and at the end the spalled area by place,
    the left waist and the failed zone from the flaw toe (case.json)."""
    q = {}
    for e in summary.get("cases", []):
        c = e["case"]
        at = {round(r["displacement_mm"], 6): r["stress_MPa"] for r in e.get("axial_stress_MPa_at") or []}   # tunnel_spalling.py's summary
        q[f"σ at 2 mm [MPa], {c}"] = at.get(2.0)
        cj = os.path.join(folder, c, "case.json")
        if not os.path.exists(cj):
            continue
        info = json.load(open(cj))
        fc = info.get("first_crack") or {}                      # case.json: time [s], location
        q[f"first crack [ms], {c}"] = None if fc.get("time") is None else fc["time"] * 1e3
        snaps = info.get("snapshots") or {}
        last = snaps.get(max(snaps, key=lambda k: float(k.rstrip("ms")))) if snaps else None
        if not last:
            continue
        for place, a in (last.get("spalled_by_place_mm2") or {}).items():
            q[f"spalled at the {place} [mm²], {c}"] = a
        q[f"left waist moved in, p90 [mm], {c}"] = (last.get("left_waist_inward_mm") or {}).get("p90")
        if last.get("toe_failed_gap_mm") is not None:
            q[f"failed zone from the toe, gap to the opening [mm], {c}"] = last["toe_failed_gap_mm"]
    return q


def _circular_quantities(summary):
    """name → value of one circular-opening run (scripts/paper/circular_opening.py's summary): the Kirsch errors."""
    return {"max L2 rel. error of σxx, σyy (r ≥ 2a)": summary.get("l2_rel_error_max"),
            "max L2 rel. error near the hole": summary.get("l2_rel_error_near_max"),
            "hoop stress at θ = 0° [MPa] (Kirsch 10)": summary.get("hoop_stress_theta0_MPa"),
            "hoop stress at θ = 90° [MPa] (Kirsch 50)": summary.get("hoop_stress_theta90_MPa")}


def _penny_quantities(summary):
    """name → value of one line-crack run (scripts/paper/penny_crack.py's summary): Sneddon errors and the crack growth."""
    q = {"u_y L2 rel. error (Sneddon)": summary.get("uy_l2_rel_error"), "u_y rel. error at the centre": summary.get("uy_center_rel_error"),
         "σyy ahead of the tip, L2 rel. error": summary.get("syy_ahead_l2_rel_error")}
    from ..validation.line_crack import PAPER_DA
    c = summary.get("paper_comparison") or {}
    for (t, paper), da in zip(PAPER_DA, c.get("da_paper_cells") or ()):
        q[f"Δa at t = {t:g} s [cells] (paper {paper})"] = da
    if c:
        q["first growth, t on the paper's axis [s]"] = c.get("initiation_t_paper_s")
    return q


QUANTITIES = {"uniaxial": lambda f, s: _uniaxial_quantities(s), "tunnel": _tunnel_quantities,
              "circular_opening": lambda f, s: _circular_quantities(s), "penny_crack": lambda f, s: _penny_quantities(s)}


def ensemble_section(R):
    R.w("## Spread over where the grid cuts the specimen", "",
        "The default-grid runs repeated with the grid moved against the specimen by sub-cell shifts (`yade_mpm.make_solver`'s "
        "`shift`; a slip plane stays on a node or half-node line, so an axis bounded by slip planes takes the shifts 0 and ½ only). "
        "The runs differ in nothing else, but for the tunnel's runs named `_l74` and `_l76`: the 150 mm specimen, bounded by slip "
        "walls on three sides, admits four shifts only, so these two cut it with 74 and 76 cells across (l = 2.027 and 1.974 mm; "
        "1.3 % from the default grid in resolution too). Mean, range and coefficient of variation (population standard deviation / |mean|) of "
        "each quantity; a quantity that is not reached in some runs (\"never\") counts only the runs that reach it, with n.", "")
    for scene in ENSEMBLES:
        ms = members(R, scene)
        R.w(f"**{scene}** — " + (f"{len(ms)} runs ({', '.join(m for m, _ in ms)}), `{command(scene)}`" if ms else
                                 f"*not run here* — `{command(scene)}` writes `{shown(os.path.join(R.root, ENSEMBLES[scene][0]))}/`"), "")
        if not ms:
            continue
        per = []
        for _, f in ms:
            s = json.load(open(os.path.join(f, "summary.json")))
            per.append(QUANTITIES[scene](f, s))
        names = [k for k in per[0]] + [k for p in per[1:] for k in p if k not in per[0]]
        R.w("| quantity | unshifted | mean | min–max | CV | n |", "|---|---|---|---|---|---|")
        for k in dict.fromkeys(names):
            sp = uncertainty.spread([p.get(k) for p in per])
            v0 = per[0].get(k)
            if sp is None:
                R.w(f"| {k} | never | — | — | — | 0 |")
                continue
            R.w(f"| {k} | {'never' if v0 is None else f'{v0:.4g}'} | {sp['mean']:.4g} | {sp['min']:.4g}–{sp['max']:.4g} | "
                f"{100 * sp['cv']:.1f} % | {sp['n']} of {len(per)} |")
        R.w("")
        include_notes(R, os.path.join(R.root, ENSEMBLES[scene][0], "notes.md"))   # what the runs showed (written with them)
