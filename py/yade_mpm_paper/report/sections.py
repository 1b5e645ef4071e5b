"""The validation report's sections of the reproduced cases (scripts/paper/report.py): the circular opening (Kirsch), the line crack (Sneddon, Fig. 9), the stability
suite, the uniaxial flaw runs and the arch tunnel with the README's picture."""
import glob
import json
import os

import numpy as np

from .document import fmt, frozen, include_notes, shown, table


# ------------------------------------------------------------------------------------- benchmarks
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
            R.w("Elastic opening against Sneddon (Eq. 43): the convergence of this run's own script below; across grids and time "
                "steps: *Error against run time* above.", "")
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
                                    ("passed", lambda r: r.get("passed")),
                                    ("what a stopped case printed", lambda r: (r.get("message") or "")[:200].replace("|", "/").replace("\n", " ") or None)]))
    rows = s.get("cases", [])
    bad = [r.get("case") for r in rows if not (r.get("passed") and r.get("outcome") == r.get("expected_outcome"))]
    R.w(f"All {len(rows)} cases passed (each with its expected outcome)." if rows and not bad else
        f"**FAILED: {', '.join(map(str, bad)) or 'no cases in the summary'}** (passed = the expected outcome, no NaN, "
        "energy bounded, Δt within the limit).", "")
    R.figures("stability", ["energy_ratio.png"])


RUN_COLUMNS = ("variant", "mu_con", "c_con_MPa", "peak_stress_MPa", "strain_at_peak", "time_at_peak_s", "end_reason",
               "time_reached_s", "reaction_spikes", "wall_time_s", "particles")   # a uniaxial run's row: how and when it ended beside its peak


def run_cell(r, c):
    """A uniaxial run's table cell: its reaction spikes (uniaxial_results.spike_record) in words, else the value."""
    v = r.get(c)
    if c == "reaction_spikes" and isinstance(v, dict):
        return f"{v['count']} from {v['first_time_s'] * 1e3:.3f} ms (largest {v['largest_MPa']:.0f} MPa)"
    return v


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
            R.w(*table(v, [(c, (lambda c: lambda r: run_cell(r, c))(c)) for c in keys]))
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
