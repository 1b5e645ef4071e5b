"""The validation report's fidelity sections (scripts/paper/report.py): the fidelity table (every claim of
the paper about its results, measured; yade_mpm_paper.fidelity.table), the one-at-a-time variants of the
modelling choices behind it and the time-step (Courant number) study."""
import glob
import json
import os

from .document import REPO, frozen, include_notes, shown


# ---------------------------------------------------------------------------------- fidelity (issue 18)
def load_tunnel(R, part, folder=None):
    """A tunnel folder's summary cases and each case's case.json, or None (nothing written)."""
    folder = folder or R.folder(part)
    path = os.path.join(folder, "summary.json")
    if not os.path.exists(path):
        return None
    s = json.load(open(path))
    info = {}
    for e in s["cases"]:
        cj = os.path.join(folder, e["case"], "case.json")
        info[e["case"]] = json.load(open(cj)) if os.path.exists(cj) else None
    return dict(cases=s["cases"], info=info)


def fidelity_section(R):
    """The fidelity table: every claim of the paper about its results (yade_mpm_paper.fidelity.table.ROWS), measured."""
    from yade_mpm_paper.fidelity import table as fidelity_table
    parts = {p: R.read(p) for p in ("circular_opening", "penny_crack", "penny_crack_damage", "uniaxial_flaw", "uniaxial_paper",
                                     "circular_opening_paper", "penny_crack_paper")}
    parts["penny_crack_damage"] = parts["penny_crack_damage"] or parts["penny_crack"]   # one run with --parts elastic,damage
    parts.update(tunnel=load_tunnel(R, "tunnel"), tunnel_paper=load_tunnel(R, "tunnel_paper"))
    rows = fidelity_table.rows(parts)
    spread = ensemble_rows(R, rows, parts)
    R.w("## Fidelity table: the paper's claims about its results, measured", "",
        "One row per claim of the paper (figure numbers are the paper's). *Measured* is computed from the fields of the runs "
        "below (`yade_mpm_paper.fidelity`, `yade_mpm_paper.fidelity.table`, `yade_mpm.analysis`), not read off a picture. Default grid: "
        "tunnel and uniaxial 2 mm; paper grid: tunnel 1 mm, uniaxial 0.5 mm. Verdicts: agrees / partly / differs / not run / "
        "no reference (the paper gives no number).", "")
    if spread:
        R.w("**Uncertainty.** " + "; ".join(spread) + " (section *Spread over where the grid cuts the specimen*). In the default-grid "
            "column a number that differs between those runs reads `v [min–max]` (v: the unshifted run). The verdict rule: a verdict "
            "(agrees, partly, differs) stands when every run of the ensemble gives it; when they disagree the row reads *within "
            "uncertainty* with the count of each verdict.", "")
    include_notes(R, os.path.join(R.root, "fidelity_notes.md"))
    R.w("| figure | the paper's claim | measured, default grid | verdict | measured, paper grid | verdict |", "|---|---|---|---|---|---|")
    for r in rows:
        R.w(f"| {r['fig']} | {r['claim']} | {r['default']} | **{r['verdict']}** | {r['paper_grid']} | {r['verdict_paper']} |")
    kind = lambda v: v.split(":")[0].split(" (")[0]          # "within uncertainty (agrees 4, partly 1 of 5)": one kind
    n = {}
    for r in rows:
        n[kind(r["verdict"])] = n.get(kind(r["verdict"]), 0) + 1
    npg = {}
    for r in rows:
        k = kind(r["verdict_paper"])
        if k not in ("—", "not run"):
            npg[k] = npg.get(k, 0) + 1
    R.w("", "Default grid: " + ", ".join(f"{v} {k}" for k, v in sorted(n.items())) + f" of {len(rows)} rows."
        + (" Paper grid: " + ", ".join(f"{v} {k}" for k, v in sorted(npg.items())) + f" of the {sum(npg.values())} rows run there." if npg else ""), "")
    include_notes(R, os.path.join(R.root, "fidelity_grids.md"))


def ensemble_rows(R, rows, parts):
    """Every default-grid row of a scene with a grid-shift ensemble: its text over the ensemble's runs (numbers with
    their range) and the combined verdict (yade_mpm_paper.uncertainty). Returns what was merged, as sentences."""
    from yade_mpm_paper import uncertainty
    from yade_mpm_paper.fidelity import table as fidelity_table
    from .uncertainty_sections import members
    said = []
    for scene, scene_parts in (("uniaxial", ("uniaxial_flaw",)), ("tunnel", ("tunnel",)), ("circular_opening", ("circular_opening",)),
                               ("penny_crack", ("penny_crack", "penny_crack_damage"))):   # one penny run: elastic and damage parts
        ms = members(R, scene)
        if len(ms) < 2:
            continue
        per = []
        for _, f in ms:
            p = dict(parts)
            run = load_tunnel(R, scene_parts[0], f) if scene == "tunnel" else json.load(open(os.path.join(f, "summary.json")))
            p.update(dict.fromkeys(scene_parts, run))
            per.append(fidelity_table.rows(p))
        for i, r in enumerate(rows):
            if r["part"] in scene_parts:
                r["default"] = uncertainty.merge_texts([pr[i]["default"] for pr in per])
                r["verdict"] = uncertainty.combined_verdict([pr[i]["verdict"] for pr in per])
        said.append(f"{scene} rows over {len(ms)} runs of the default grid, shifted by {', '.join(m for m, _ in ms)}")
    return said


OLD_INCREMENT = "fidelity_variants_b86bf5e.md"    # the variant matrix run with Δε̄p = Δλ/√3 (before issue 18's default), kept verbatim


def variant_matrix(R, folder="fidelity_variants"):
    """Choice × row: the one-at-a-time variants (scripts/paper/fidelity_variants.py), each against its own baseline."""
    files = sorted(glob.glob(os.path.join(R.root, folder, "*.json")))
    R.w("## Causes: one-at-a-time variants of the modelling choices", "")
    if not files:
        R.w(f"*Not run here* — `/usr/bin/python3 scripts/paper/fidelity_variants.py --scene uniaxial|tunnel ...` writes `{shown(os.path.join(R.root, folder))}/`.", "")
        if os.path.exists(os.path.join(REPO, "archive", "fidelity_variants_d734961.md")):
            R.w("The last screening matrix (a build before the contact fix that made it independent of where the grid cuts a body, C = 0.5) is kept verbatim in "
                "[fidelity_variants_d734961.md](../../archive/fidelity_variants_d734961.md); its Δt rows are superseded by the time-step study below.", "")
        return
    runs = [json.load(open(f)) for f in files]
    if os.path.exists(os.path.join(REPO, "archive", "fidelity_variants_d734961.md")):
        done = {(r["scene"], r["variant"]) for r in runs}
        old = [n for v, n in (("as_printed_growth", "uniaxial growth law"), ("v_cube", "V = dp³"), ("no_residual_cohesion", "residual cohesion"),
                              ("soft_strain_0.01", "ε̄p,crit = 0.01")) if ("uniaxial", v) not in done] + ["tunnel intact at 2.5 mm"]
        R.w(f"Variants not in the matrix below ({', '.join(old)}) were screened on an older build (before the contact fix that made it independent of where the grid cuts a body): "
            "[fidelity_variants_d734961.md](../../archive/fidelity_variants_d734961.md), kept verbatim.", "")
    if os.path.exists(os.path.join(REPO, "archive", OLD_INCREMENT)):
        done = {r["variant"] for r in runs if r["scene"] == "tunnel"}
        old = [n for v, n in (("principal_strain", "Eq. 36 as the principal strain"), ("floor_52.5mm", "the opening centred"),
                              ("flaw_gap_5mm", "the flaw toe 5 mm from the wall")) if v not in done]
        if old:
            R.w("Tunnel variants screened with the earlier default ε̄p increment (Δλ/√3, now `plasticStrainIncrement = 'von-mises'`) "
                f"and not re-run on this build — {', '.join(old)} — are kept verbatim in [{OLD_INCREMENT}](../../archive/{OLD_INCREMENT}).", "")
    include_notes(R, os.path.join(R.root, folder, "notes.md"))
    from yade_mpm_paper import fidelity
    for scene, case in sorted({(r["scene"], r["case"]) for r in runs}):
        rs = sorted((r for r in runs if (r["scene"], r["case"]) == (scene, case)), key=lambda r: list(fidelity.VARIANTS).index(r["variant"]))
        r0 = rs[0]
        R.w(f"**{scene}, {case}** — grid {r0['spacing_m'] * 1e3:g} mm, loading to {r0['end_time_s'] * 1e3:g} ms (screening: "
            f"compare with the baseline row only), HEAD when written `{r0.get('build')}`", "")
        if scene == "uniaxial":
            cols = [("first D = 1 at a flaw end [ms] (Fig. 11b)", lambda r: _ms(r["crack_times"]["first_tip_damage_s"])),
                    ("wing > flaw [ms] (Fig. 11b)", lambda r: _ms(r["crack_times"]["wing_longer_than_flaw_s"])),
                    ("first shear crack [ms] (Fig. 12)", lambda r: _ms(r["crack_times"]["first_shear_crack_s"])),
                    ("through to a face [ms] (Fig. 11b)", lambda r: _ms(r["crack_times"]["through_to_a_face_s"])),
                    ("peak [MPa] at [mm] (Fig. 11a)", lambda r: f"{r['curve_shape']['peak']:.1f} at {r['curve_shape']['x_at_peak']:.3f}")]
        else:
            sn = lambda r, k: r["snapshots"].get(k) or {}
            last = lambda r: max(r["snapshots"], key=lambda k: float(k[:-2]))       # "8ms", "12ms", ...
            cols = [("first D = 1 (Fig. 18d)", lambda r: (r["first_crack"] or {}).get("at") and f"{r['first_crack']['at']} at {r['first_crack']['time_s'] * 1e3:.1f} ms"),
                    ("σ at 0.5 / 1.0 mm [MPa] (Fig. 17)", lambda r: " / ".join(f"{r['stress_MPa_at_mm'].get(k, float('nan')):.1f}" for k in ("0.5", "1"))),
                    ("softened % at the end (Fig. 18b, c)", lambda r: f"{100 * sn(r, last(r))['softened_fraction']:.2f}"),
                    ("bands at the end (Fig. 18b)", lambda r: ", ".join(f"{b['side'][0]} {abs(b['angle_deg']):.0f}°" for b in sn(r, last(r)).get('bands', [])[:3])),
                    ("plastic zones at the end: fill L / R, ½ = triangle (Fig. 18a)", lambda r: " / ".join(f"{sn(r, last(r)).get('plastic_zones', {}).get(k, {}).get('fill', float('nan')):.2f}" for k in ("left", "right"))),
                    ("toe link at the end (Fig. 19f)", lambda r: sn(r, last(r)).get("toe_link_to_opening")),
                    ("failed zone from the toe ends [mm] from the opening, nearest (Fig. 19e, f)",
                     lambda r: sn(r, last(r)).get("toe_failed_gap_mm") is not None
                     and ("reaches it" if sn(r, last(r)).get("toe_link_to_opening") not in (None, "nowhere") else
                          f"{sn(r, last(r))['toe_failed_gap_mm']:.1f}, {sn(r, last(r)).get('toe_failed_nearest')}")),
                    ("spalled at the left wall / corner / spandrel [mm²] (Fig. 19e, g)",
                     lambda r: " / ".join(f"{(sn(r, last(r)).get('spalled_by_place_mm2') or {}).get(k, 0):.0f}"
                                          for k in ("left wall", "left corner", "left spandrel"))),
                    ("ε̄p max / p99 at the end (softening ends at) (Fig. 18b)",
                     lambda r: "eps_p_max" in sn(r, last(r)) and f"{sn(r, last(r))['eps_p_max']:.3g} / {sn(r, last(r))['eps_p_p99']:.2g} "
                     f"({sn(r, last(r))['eps_p_soft_end']:.2g})"),
                    ("left waist in [mm] p90 (Fig. 19g)", lambda r: f"{(sn(r, last(r)).get('left_waist_inward_mm') or {}).get('p90', float('nan')):.3f}")]
        R.w("| variant | " + " | ".join(c for c, _ in cols) + " | wall [s] |", "|---|" + "---|" * (len(cols) + 1))
        for r in rs:
            vals = []
            for _, f in (cols if not r.get("error") else []):
                try:
                    vals.append(str(f(r) if f(r) is not None else "—"))
                except (KeyError, TypeError, ValueError):
                    vals.append("—")
            stop = f" — **stopped by the solver at t = {r['time_reached_s'] * 1e3:.3f} ms**: {r['error'][:160]}" if r.get("error") else ""
            vals = vals or ["—"] * len(cols)
            R.w(f"| {r['variant']}: {r['label']}{stop} | " + " | ".join(vals) + f" | {r['wall_time_s']:.0f} |")
        R.w("")
    done = {r["variant"] for r in runs}
    R.w("Not run: " + (", ".join(f"{k} ({v['label']})" for k, v in fidelity.VARIANTS.items() if k not in done) or "none") + ".", "")


def courant_section(R, folder="courant"):
    """The time-step study (issue 19 item 1): the same scenes at several C (yade_mpm_paper.fidelity.courant)."""
    from yade_mpm_paper.fidelity import courant as fidelity_courant
    d = os.path.join(R.root, folder)
    runs = {float(os.path.basename(f)[1:]): f for f in sorted(glob.glob(os.path.join(d, "c*"))) if os.path.isdir(f)}
    R.w("## Time step: the Courant number chosen by accuracy", "")
    if not runs:
        R.w(f"*Not run here* — the scripts of `scripts/regress.py` with `--courant C` into `{shown(d)}/cC/` (see the notes of a run).", "")
        frozen(R)
        return
    include_notes(R, os.path.join(d, "notes.md"))
    R.w(fidelity_courant.markdown(fidelity_courant.collect(runs)), "")


def _ms(t):
    return "never" if t is None else f"{t * 1e3:.2f}"
