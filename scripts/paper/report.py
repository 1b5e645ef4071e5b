"""Builds doc/validation/report.md from the output folders of the reference scripts: every case's figures
(copied to doc/figures/) and numbers, error against run time for the benchmarks, the stability table,
the uniaxial sweeps, the fidelity table (every claim of the paper about its results, measured; yade_mpm_paper.fidelity.table) and the
one-at-a-time variants behind it (scripts/paper/fidelity_variants.py).

    /usr/bin/python3 scripts/paper/report.py                       # reads out/<case>/, writes doc/validation/report.md
    /usr/bin/python3 scripts/paper/report.py --root out --doc doc

Folders read (each optional; a missing one is reported with the command that makes it):
    circular_opening/  scripts/paper/circular_opening.py --convergence
    penny_crack/       scripts/paper/penny_crack.py
    circular_opening_paper/, penny_crack_paper/   the elastic benchmarks at the paper's grid (0.01 m, 0.02 m)
    stability/         scripts/paper/stability.py
    uniaxial_flaw/     scripts/paper/uniaxial_flaw.py
    uniaxial_paper/    scripts/paper/uniaxial_flaw.py --paper   (paper grid: open, filled μ_con 0 and 0.6, c_con 5 and 10 MPa)
    tunnel/            scripts/paper/tunnel_spalling.py            (default grid, all four cases)
    tunnel_paper/      scripts/paper/tunnel_spalling.py --paper    (paper grid)
    fidelity_variants/ scripts/paper/fidelity_variants.py          (variant screening; notes.md: how it was run)
    fidelity_notes.md  how the runs of the fidelity table were made (build, commands, wall times)
    fidelity_grids.md  the default and the paper grid compared: where they differ, which to trust and why
"""
import argparse
import glob
import json
import os
import shutil
import time

import numpy as np

PARTS = {
    "circular_opening": "/usr/bin/python3 scripts/paper/circular_opening.py --out out/circular_opening --convergence",
    "penny_crack": "/usr/bin/python3 scripts/paper/penny_crack.py --out out/penny_crack",
    "penny_crack_damage": "/usr/bin/python3 scripts/paper/penny_crack.py --out out/penny_crack_damage --parts damage",
    "circular_opening_paper": "/usr/bin/python3 scripts/paper/circular_opening.py --out out/circular_opening_paper --spacing 0.01 --no-convergence --no-vtu",
    "penny_crack_paper": "/usr/bin/python3 scripts/paper/penny_crack.py --out out/penny_crack_paper --parts elastic --spacing 0.02",
    "stability": "/usr/bin/python3 scripts/paper/stability.py --out out/stability",
    "uniaxial_flaw": "/usr/bin/python3 scripts/paper/uniaxial_flaw.py --out out/uniaxial_flaw",
    "tunnel": "./run.sh   (= /usr/bin/python3 scripts/paper/tunnel_spalling.py --out out/tunnel)",
    "uniaxial_paper": "/usr/bin/python3 scripts/paper/uniaxial_flaw.py --out out/uniaxial_paper --paper --runs open,filled:0:0,filled:0.6:0,filled:0:5,filled:0:10",
    "tunnel_paper": "/usr/bin/python3 scripts/paper/tunnel_spalling.py --out out/tunnel_paper --paper --threads 2 --cases intact,open_flaw,filled_flaw",
}


MAX_FIGURE_BYTES = 400_000       # larger pictures stay in the output folder
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def shown(path):
    """A folder as the report names it: relative to the repository (no absolute path of this machine);
    a folder outside the repository by its last two components only."""
    p = os.path.abspath(path)
    if os.path.commonpath([p, REPO]) == REPO:
        return os.path.relpath(p, REPO)
    return os.path.join("…", *p.split(os.sep)[-2:]) + " (outside the repository)"


class Report:
    def __init__(self, root, doc, dirs=None):
        self.root, self.doc, self.dirs = root, doc, dict(dirs or {})
        self.fig_dir = os.path.join(doc, "figures")
        self.path = os.path.join(doc, "validation", "report.md")
        os.makedirs(self.fig_dir, exist_ok=True)
        self.lines = []

    def w(self, *lines):
        self.lines.extend(lines)

    def folder(self, part):
        return self.dirs.get(part, os.path.join(self.root, part))

    def read(self, part):
        path = os.path.join(self.folder(part), "summary.json")
        if not os.path.exists(path):
            return None
        with open(path) as f:
            return json.load(f)

    def load(self, part):
        """summary.json of a part, or None after a line saying how to make it."""
        s = self.read(part)
        if s is None:
            self.w(f"*Not run here* — `{PARTS[part]}` writes `{shown(self.folder(part))}/`.", "")
        return s

    def figure(self, src, name, caption, width=None):
        """Copy a PNG to doc/figures/ and link it."""
        if not os.path.exists(src):
            return False
        dst = os.path.join(self.fig_dir, name)
        shutil.copyfile(src, dst)
        rel = os.path.relpath(dst, os.path.dirname(self.path))
        self.w(f"![{caption}]({rel})" if width is None else f'<img src="{rel}" width="{width}" alt="{caption}">', f"*{caption}*", "")
        return True

    def figures(self, part, names):
        """The named PNGs of a part's folder (a selection: doc/ keeps small files only)."""
        for b in names:
            for p in sorted(glob.glob(os.path.join(self.folder(part), b))):
                if os.path.getsize(p) <= MAX_FIGURE_BYTES:
                    self.figure(p, f"{part}_{os.path.basename(p)}", f"{part}: {os.path.basename(p)}")

    def write(self):
        os.makedirs(os.path.dirname(self.path), exist_ok=True)
        with open(self.path, "w") as f:
            f.write("\n".join(self.lines).rstrip() + "\n")
        return self.path


def fmt(v, nd=3):
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return f"{v:,}"
    if isinstance(v, float):
        return f"{v:,.0f}" if abs(v) >= 1000 else f"{v:.{nd}g}"
    return str(v)


def table(rows, cols):
    out = ["| " + " | ".join(c for c, _ in cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        out.append("| " + " | ".join(fmt(get(r)) for _, get in cols) + " |")
    return out + [""]


# ------------------------------------------------------------------------------------- benchmarks
def error_vs_time(R, circ, penny):
    series = []
    if circ and circ.get("convergence"):
        c = circ["convergence"]
        series.append(("circular opening: max L2 rel. error of σ vs Kirsch", [r["wall_time_s"] for r in c],
                       [r["l2_rel_error_max"] for r in c], [r["grid_spacing_m"] for r in c]))
    if penny and penny.get("convergence"):
        c = penny["convergence"]
        series.append(("penny crack: L2 rel. error of the opening u_y vs Sneddon", [r["wall_time_s"] for r in c],
                       [r["uy_l2_rel_error"] for r in c], [r["spacing_m"] for r in c]))
    R.w("## Error against run time (benchmarks)", "")
    if not series:
        R.w("No convergence runs found (`--convergence` of circular_opening.py, the convergence part of penny_crack.py).", "")
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for (label, t, e, l), m in zip(series, ("o-", "s-")):
        ax.loglog(t, e, m, label=label)
        for ti, ei, li in zip(t, e, l):
            ax.annotate(f"l = {li:g} m", (ti, ei), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xlabel("wall time of the run [s]")
    ax.set_ylabel("relative error")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    p = os.path.join(R.fig_dir, "error_vs_walltime.png")
    fig.savefig(p, dpi=120)
    plt.close(fig)
    R.w(f"![error against wall time]({os.path.relpath(p, R.doc)})", "")
    for label, t, e, l in series:
        R.w(f"**{label}**", "")
        R.w(*table([dict(l=a, t=b, e=c) for a, b, c in zip(l, t, e)],
                   [("grid spacing [m]", lambda r: r["l"]), ("wall time [s]", lambda r: r["t"]), ("relative error", lambda r: r["e"])]))


def circular(R):
    R.w("## Circular opening (paper Sec. 3.1, Kirsch)", "")
    s = R.load("circular_opening")
    if s is None:
        return
    R.w(f"Hoop stress at the wall: θ = 0° {fmt(s.get('hoop_stress_theta0_MPa'))} MPa (Kirsch {fmt(s.get('kirsch_hoop_theta0_MPa'))}), "
        f"θ = 90° {fmt(s.get('hoop_stress_theta90_MPa'))} MPa (Kirsch {fmt(s.get('kirsch_hoop_theta90_MPa'))}); "
        f"max L2 relative error of the stress profiles {fmt(s.get('l2_rel_error_max'))}; grid {fmt(s.get('grid_spacing_m'))} m, "
        f"{fmt(s.get('particles'))} particles, wall {fmt(s.get('wall_time_s'))} s.", "")
    R.figures("circular_opening", ["convergence.png", "stress_lines_zoom.png"])


def penny(R):
    R.w("## Penny-shaped (line) crack (paper Sec. 3.2, Sneddon)", "")
    s = R.load("penny_crack")
    if s is not None:
        if s.get("convergence"):
            R.w("Elastic opening against Sneddon (Eq. 43): see *Error against run time* above.", "")
        R.figures("penny_crack", ["error_vs_walltime.png"])
    dmg = R.read("penny_crack_damage") if "penny_crack_damage" in R.dirs else None
    s = dmg or s
    if s is None:
        return
    if dmg is not None:
        R.w(f"Damage growth (from `{shown(R.folder('penny_crack_damage'))}`):", "")
    ext = s.get("crack_extension_cells") or []
    paper = {round(p["t_s"], 3): p["cells"] for p in s.get("paper_crack_extension_cells", [])}
    if ext:
        R.w("Crack extension (cells) against the paper's Fig. 9:", "")
        R.w(*table(ext, [("t [s]", lambda r: r["t_s"]), ("left", lambda r: r.get("left")), ("right", lambda r: r.get("right")),
                         ("paper", lambda r: paper.get(round(r["t_s"], 3)))]))
    R.w(f"Wall time {fmt(s.get('wall_time_s'))} s, {fmt(s.get('particles'))} particles.", "")
    if dmg is not None:
        R.figures("penny_crack_damage", ["crack_extension.png", "damage_benz-asphaug_t0.40s.png"])


def stability(R):
    R.w("## Stability suite", "")
    s = R.load("stability")
    if s is None:
        return
    R.w(*table(s.get("cases", []), [("case", lambda r: r.get("case")), ("outcome", lambda r: r.get("outcome")),
                                    ("expected", lambda r: r.get("expected_outcome")),
                                    ("max energy ratio", lambda r: r.get("max_energy_ratio")), ("steps", lambda r: r.get("steps")),
                                    ("NaN seen", lambda r: r.get("nan_seen")), ("wall [s]", lambda r: r.get("wall_time_s")),
                                    ("passed", lambda r: r.get("passed"))]))
    rows = s.get("cases", [])
    bad = [r.get("case") for r in rows if not (r.get("passed") and r.get("outcome") == r.get("expected_outcome"))]
    R.w(f"All {len(rows)} cases passed (each with its expected outcome)." if rows and not bad else
        f"**FAILED: {', '.join(map(str, bad)) or 'no cases in the summary'}** (passed = the expected outcome, no NaN, "
        "energy bounded, Δt within the limit).", "")
    R.figures("stability", ["energy_ratio.png"])


RUN_COLUMNS = ("variant", "mu_con", "c_con_MPa", "peak_stress_MPa", "strain_at_peak", "time_at_peak_s", "end_reason",
               "time_reached_s", "wall_time_s", "particles")   # a uniaxial run's row: how and when it ended beside its peak


def include_notes(R, path):
    """A notes file of the output folder (how the runs were made, written by whoever ran them), verbatim, if present."""
    if os.path.exists(path):
        R.w(open(path).read().rstrip(), "")


def uniaxial(R, part="uniaxial_flaw", title="Uniaxial compression with a flaw (paper Sec. 3.3)"):
    R.w(f"## {title}", "")
    s = R.load(part)
    if s is None:
        return
    include_notes(R, os.path.join(R.folder(part), "notes.md"))
    flat = {k: v for k, v in s.items() if isinstance(v, (int, float, str, bool))}
    if flat:
        R.w(*table([{"k": k, "v": v} for k, v in flat.items()], [("quantity", lambda r: r["k"]), ("value", lambda r: r["v"])]))
    for k, v in s.items():
        if isinstance(v, list) and v and isinstance(v[0], dict):
            keys = [c for c in v[0] if isinstance(v[0][c], (int, float, str, bool)) or v[0][c] is None]
            keys = [c for c in RUN_COLUMNS if c in keys] or keys[:8]
            R.w(f"**{k}**", "")
            R.w(*table(v, [(c, (lambda c: lambda r: r.get(c))(c)) for c in keys]))
    R.figures(part, ["curves_mu.png", "curves_c.png", "damage_plastic_open.png", "damage_plastic_filled_mu0.6_c0MPa.png"])


# ------------------------------------------------------------------------------------------ tunnel
def tunnel(R, part, title, keys_intact=("08ms", "12ms", "20ms"), keys_flaw=("20ms",)):
    R.w(f"## {title}", "")
    s = R.load(part)
    if s is None:
        frozen(R)
        return None
    cs = s["cases"]

    def at(e, d):
        for p in e["axial_stress_MPa_at"]:
            if abs(p["displacement_mm"] - d) < 1e-9:
                return p["stress_MPa"]
        return None
    R.w(*table(cs, [("case", lambda e: e["case"]), ("grid [mm]", lambda e: e["grid_spacing_m"] * 1e3),
                    ("particles", lambda e: e["particles"]), ("steps", lambda e: e["steps"]),
                    ("wall [s]", lambda e: e["wall_time_s"]),
                    ("M particle-steps/s", lambda e: (e["particle_steps_per_s"] or 0) / 1e6),
                    ("final displ. [mm]", lambda e: e["final_displacement_mm"]),
                    ("σ at 0.5 mm [MPa]", lambda e: at(e, 0.5)), ("σ at 1.0 mm", lambda e: at(e, 1.0)),
                    ("σ at 2.0 mm", lambda e: at(e, 2.0)), ("symmetry D (8 ms)", lambda e: e["symmetry_damage"]),
                    ("first damage", lambda e: e["first_damage_location"])]))
    d = R.folder(part)
    include_notes(R, os.path.join(d, "notes.md"))
    R.figure(os.path.join(d, "axial_stress.png"), f"{part}_axial_stress.png", "Axial stress against platen displacement (cf. paper Fig. 17)")
    txt = os.path.join(d, "summary.txt")
    if os.path.exists(txt):
        R.w("Text summary written by the run:", "", "```", open(txt).read().rstrip(), "```", "")
    info = {}
    for e in cs:
        cj = os.path.join(d, e["case"], "case.json")
        info[e["case"]] = json.load(open(cj)) if os.path.exists(cj) else None
        R.figure(os.path.join(d, e["case"], "geometry.png"), f"{part}_{e['case']}_geometry.png",
                 f"{e['case']}: the scene as built (paper Fig. 16)", width=320)
        snaps = sorted((info[e["case"]] or {}).get("snapshots", {}))
        keys = [k for k in (keys_intact if e["case"] == "intact" else keys_flaw) if k in snaps] or snaps[-1:]
        for key in keys:
            R.figure(os.path.join(d, e["case"], f"fields_{key}.png"), f"{part}_{e['case']}_fields_{key}.png",
                     f"{e['case']}, t = {int(key[:2])} ms: accumulated plastic strain (red: detected shear bands), damage "
                     "(cyan: spalled region), max tensile principal stress, x and y displacement")
    return cs, info


def readme_figure(R, part="tunnel", case="filled_flaw"):
    """doc/figures/readme_tunnel.png: the Fig. 17 curves of all cases and one case's plastic strain and
    damage at its last snapshot, side by side (the picture at the top of the README)."""
    d = R.folder(part)
    snaps = sorted(glob.glob(os.path.join(d, case, "snapshot_*ms.npz"))) or sorted(glob.glob(os.path.join(d, "intact", "snapshot_*ms.npz")))
    curves = {c: os.path.join(d, c, "axial_stress.csv") for c in ("intact", "open_flaw", "filled_flaw", "grout_flaw")}
    if not snaps or not any(os.path.exists(p) for p in curves.values()):
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 3, figsize=(13, 4.1), gridspec_kw=dict(width_ratios=[1.25, 1, 1]))
    style = {"intact": "k-", "open_flaw": "r-", "filled_flaw": "b-", "grout_flaw": "g-"}
    for c, p in curves.items():
        if os.path.exists(p):
            a = np.loadtxt(p, delimiter=",", skiprows=1, ndmin=2)
            axs[0].plot(a[:, 1], a[:, 2], style[c], lw=1.3, label=c.replace("_", " "))
    axs[0].set_xlabel("platen displacement [mm]"), axs[0].set_ylabel("axial stress [MPa]")
    axs[0].grid(alpha=0.3), axs[0].legend(fontsize=8), axs[0].set_title("axial stress (cf. paper Fig. 17)", fontsize=10)
    with np.load(snaps[-1]) as z:
        pos, dmg, tms = z["pos"] * 1e3, z["damage"], float(z["time"]) * 1e3
        e = z["plastic_strain"] if "plastic_strain" in z.files else z["epsP"]      # snapshots before ym.fields: epsP
    who = os.path.basename(os.path.dirname(snaps[-1]))
    for ax, v, cmap, title, top in ((axs[1], e, "viridis", "accumulated plastic strain", np.percentile(e, 99.5)),
                                    (axs[2], dmg, "inferno", "damage D", 1.0)):
        sc = ax.scatter(pos[:, 0], pos[:, 1], c=v, s=3.5 * 20868 / len(pos), marker="s", linewidths=0, cmap=cmap, vmin=0, vmax=max(top, 1e-9), rasterized=True)
        ax.set_aspect("equal"), ax.set_xticks([]), ax.set_yticks([])
        ax.set_title(f"{who.replace('_', ' ')}, t = {tms:.0f} ms: {title}", fontsize=10)
        fig.colorbar(sc, ax=ax, shrink=0.8)
    fig.tight_layout()
    fig.savefig(os.path.join(R.fig_dir, "readme_tunnel.png"), dpi=100)
    plt.close(fig)


# ---------------------------------------------------------------------------------- fidelity (issue 18)
def load_tunnel(R, part):
    """A tunnel folder's summary cases and each case's case.json, or None (nothing written)."""
    s = R.read(part)
    if s is None:
        return None
    info = {}
    for e in s["cases"]:
        cj = os.path.join(R.folder(part), e["case"], "case.json")
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
    R.w("## Fidelity table: the paper's claims about its results, measured", "",
        "One row per claim of the paper (figure numbers are the paper's). *Measured* is computed from the fields of the runs "
        "below (`yade_mpm_paper.fidelity`, `yade_mpm_paper.fidelity.table`, `yade_mpm.analysis`), not read off a picture. Default grid: "
        "tunnel and uniaxial 2 mm; paper grid: tunnel 1 mm, uniaxial 0.5 mm. Verdicts: agrees / partly / differs / not run / "
        "no reference (the paper gives no number).", "")
    include_notes(R, os.path.join(R.root, "fidelity_notes.md"))
    R.w("| figure | the paper's claim | measured, default grid | verdict | measured, paper grid | verdict |", "|---|---|---|---|---|---|")
    for r in rows:
        R.w(f"| {r['fig']} | {r['claim']} | {r['default']} | **{r['verdict']}** | {r['paper_grid']} | {r['verdict_paper']} |")
    n = {}
    for r in rows:
        n[r["verdict"].split(":")[0]] = n.get(r["verdict"].split(":")[0], 0) + 1
    npg = {}
    for r in rows:
        k = r["verdict_paper"].split(":")[0]
        if k not in ("—", "not run"):
            npg[k] = npg.get(k, 0) + 1
    R.w("", "Default grid: " + ", ".join(f"{v} {k}" for k, v in sorted(n.items())) + f" of {len(rows)} rows."
        + (" Paper grid: " + ", ".join(f"{v} {k}" for k, v in sorted(npg.items())) + f" of the {sum(npg.values())} rows run there." if npg else ""), "")
    include_notes(R, os.path.join(R.root, "fidelity_grids.md"))


OLD_INCREMENT = "fidelity_variants_b86bf5e.md"    # the variant matrix run with Δε̄p = Δλ/√3 (before issue 18's default), kept verbatim


def variant_matrix(R, folder="fidelity_variants"):
    """Choice × row: the one-at-a-time variants (scripts/paper/fidelity_variants.py), each against its own baseline."""
    files = sorted(glob.glob(os.path.join(R.root, folder, "*.json")))
    R.w("## Causes: one-at-a-time variants of the modelling choices", "")
    if not files:
        R.w(f"*Not run here* — `/usr/bin/python3 scripts/paper/fidelity_variants.py --scene uniaxial|tunnel ...` writes `{shown(os.path.join(R.root, folder))}/`.", "")
        if os.path.exists(os.path.join(REPO, "archive", "fidelity_variants_d734961.md")):
            R.w("The last screening matrix (build before issue 17's contact fix, C = 0.5) is kept verbatim in "
                "[fidelity_variants_d734961.md](../../archive/fidelity_variants_d734961.md); its Δt rows are superseded by the time-step study below.", "")
        return
    runs = [json.load(open(f)) for f in files]
    if os.path.exists(os.path.join(REPO, "archive", "fidelity_variants_d734961.md")):
        done = {(r["scene"], r["variant"]) for r in runs}
        old = [n for v, n in (("as_printed_growth", "uniaxial growth law"), ("v_cube", "V = dp³"), ("no_residual_cohesion", "residual cohesion"),
                              ("soft_strain_0.01", "ε̄p,crit = 0.01")) if ("uniaxial", v) not in done] + ["tunnel intact at 2.5 mm"]
        R.w(f"Variants not in the matrix below ({', '.join(old)}) were screened on an older build (before issue 17's contact fix): "
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
    R.w("## Time step: the Courant number chosen by accuracy (issue 19)", "")
    if not runs:
        R.w(f"*Not run here* — the scripts of `scripts/regress.py` with `--courant C` into `{shown(d)}/cC/` (see the notes of a run).", "")
        frozen(R)
        return
    include_notes(R, os.path.join(d, "notes.md"))
    R.w(fidelity_courant.markdown(fidelity_courant.collect(runs)), "")


FROZEN = "paper_grid_and_courant_7ac11e5.md"      # the last paper-grid tunnel runs and C-study, kept verbatim (outputs not kept)


def frozen(R):
    """Link the frozen record of sections whose outputs are not here (archive/FROZEN)."""
    if os.path.exists(os.path.join(REPO, "archive", FROZEN)):
        R.w(f"The last runs of this section (main `7ac11e5`, simulation code of `d734961`) are kept verbatim in [{FROZEN}](../../archive/{FROZEN}).", "")


def _ms(t):
    return "never" if t is None else f"{t * 1e3:.2f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", default="out", help="folder holding the output folders (default out)")
    ap.add_argument("--doc", default="doc", help="doc folder (default doc): writes validation/report.md and figures/")
    ap.add_argument("--dir", action="append", default=[], metavar="PART=DIR",
                    help=f"read PART from DIR instead of ROOT/PART (PART: {', '.join(PARTS)}); repeatable")
    a = ap.parse_args()
    dirs = {}
    for d in a.dir:
        part, _, path = d.partition("=")
        if part not in PARTS or not path:
            ap.error(f"--dir {d!r}: expected PART=DIR with PART in {', '.join(PARTS)}")
        dirs[part] = path
    R = Report(a.root, a.doc, dirs)
    R.w("# Validation report", "",
        f"Generated by `scripts/paper/report.py` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} from the output folders under "
        f"`{shown(a.root)}/`" + (" and " + ", ".join(f"`{shown(v)}` ({k})" for k, v in dirs.items()) if dirs else "") + ". Regenerate: run the commands named in each section, then `/usr/bin/python3 scripts/paper/report.py`.", "")
    fidelity_section(R)
    courant_section(R)
    variant_matrix(R)
    tparts = [tunnel(R, "tunnel", "Arch tunnel spalling (paper Sec. 4), default grid"),
              tunnel(R, "tunnel_paper", "Arch tunnel at the paper's grid (l = 1 mm)", keys_intact=(), keys_flaw=())]
    if tparts[0] or tparts[1]:
        readme_figure(R, "tunnel" if tparts[0] else "tunnel_paper")
    circ, pen = R.read("circular_opening"), R.read("penny_crack")
    error_vs_time(R, circ, pen)
    circular(R)
    penny(R)
    stability(R)
    uniaxial(R)
    uniaxial(R, "uniaxial_paper", "Uniaxial compression with a flaw at the paper's grid (0.5 mm)")
    print(f"wrote {R.write()}")


if __name__ == "__main__":
    main()
