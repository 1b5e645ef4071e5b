"""Spalling of an arch-shaped tunnel under plane-strain compression (paper Sec. 4, Figs. 16–19):
150 × 150 mm Pan (2020b) sandstone, a 40 × 25 mm opening under a 20 mm-radius roof, free-slip sides,
a rigid YADE platen pushed down at 0.1 m/s for 20 ms, and four cases:

    intact       no flaw                                  (Fig. 16a, 18)
    open_flaw    60 × 2 mm open flaw left of the tunnel   (Fig. 16b, 19 top)
    filled_flaw  the flaw filled by a free rigid YADE body with PTS contact (Fig. 16c, 19 bottom)
    grout_flaw   the flaw filled with elastic cement grout bonded through the grid (beyond the paper)

    /usr/bin/python3 scripts/paper/tunnel_spalling.py --out out/tunnel                 # all four, default grid
    /usr/bin/python3 scripts/paper/tunnel_spalling.py --out out/tunnel_paper --paper --cases intact
    ... --checkpoint-every 20000 (steps) or 10min; --resume continues every unfinished case

Outputs (OUT/): summary.json, summary.txt, axial_stress.png (Fig. 17, all cases), and per case
OUT/CASE/: axial_stress.csv, fields_08ms.png, fields_12ms.png, fields_20ms.png (Figs. 18–19:
accumulated plastic strain, damage with the spalled region, max tensile principal stress, x/y
displacement), particles_*.vtu + particles.pvd (ParaView), case.json (analysis), checkpoint.ckpt.
Ctrl-C / SIGTERM: writes a last checkpoint and the outputs so far, then stops (--resume continues).
"""
import argparse
import json
import math
import os
import sys

import numpy as np

import yade_mpm as ym
from yade_mpm import analysis, output, rocks, runner
from yade_mpm_paper import batch, cases, uncertainty
from yade_mpm.checkpoint import resumable
from yade_mpm_paper.cases import tunnel_results as results

SNAPSHOTS_MS = (8.0, 12.0, 20.0)          # field pictures (Figs. 18a–c, 19)
CURVE_STEP_MM = 0.1                       # summary.json: axial stress every 0.1 mm
RECORD_STEP_MM = 0.01                     # CSV: mean platen stress over every 0.01 mm of displacement
DEFAULT_SPACING = 2e-3                    # default grid [m] (README main command: four cases < 20 min)
PAPER_SPACING = 1e-3                      # paper Sec. 4


def parse():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/tunnel", help="output folder (default out/tunnel)")
    ap.add_argument("--cases", default=",".join(cases.TUNNEL_CASES),
                    help=f"comma-separated subset of {', '.join(cases.TUNNEL_CASES)} (default all)")
    ap.add_argument("--spacing", type=float, default=None, help=f"grid spacing l [m] (default {DEFAULT_SPACING})")
    ap.add_argument("--paper", action="store_true", help=f"the paper's grid, l = {PAPER_SPACING} m (83 k particles)")
    ap.add_argument("--end-time", type=float, default=cases.TUNNEL_END_TIME, help="loading time [s] (default 0.02)")
    ym.scene.courant_option(ap)                     # default: the solver's C (pkg-mpm/core/SolverSettings.hpp)
    ap.add_argument("--threads", type=int, default=None, help="OpenMP threads (default: all cores)")
    ap.add_argument("--vtu-every", type=float, default=4e-3, help="simulated seconds between VTU files, plus 8, 12, 20 ms (default 0.004)")
    ap.add_argument("--checkpoint-every", default="5min",
                    help="checkpoint period: N (steps) or Nmin (wall minutes); 0 = only at the end/interrupt (default 5min)")
    ap.add_argument("--resume", action="store_true", help="continue unfinished cases from OUT/CASE/checkpoint.ckpt; keep finished ones")
    ap.add_argument("--progress", type=float, default=15.0, help="wall seconds between progress lines (default 15)")
    ap.add_argument("--flaw-angle", type=float, default=cases.FLAW_ANGLE_DEG, help="flaw inclination about its toe [°] (default %(default)s)")
    ap.add_argument("--filler-mu", type=float, default=cases.FILLER_FRICTION, help="filler–rock friction μ_con of filled_flaw (default %(default)s)")
    ap.add_argument("--grout-young", type=float, default=rocks.CEMENT_GROUT["young"], help="grout E of grout_flaw [Pa] (default %(default)s)")
    uncertainty.shift_option(ap)
    ap.add_argument("--no-pictures", dest="pictures", action="store_false", help="skip the PNG pictures (a study's many runs)")
    a = batch.parse_args(ap)                  # the command line, or a yade-batch / scripts/studies/sweep.py table line
    a.cases = [c.strip() for c in a.cases.split(",") if c.strip()]
    bad = [c for c in a.cases if c not in cases.TUNNEL_CASES]
    if bad or not a.cases:
        ap.error(f"--cases: unknown {bad}; allowed {', '.join(cases.TUNNEL_CASES)}")
    if a.paper and a.spacing is not None:
        ap.error("--paper sets the spacing; do not also give --spacing")
    a.spacing = PAPER_SPACING if a.paper else (a.spacing or DEFAULT_SPACING)
    top = cases.TUNNEL_INTACT_MAX_SPACING if a.cases == ["intact"] else cases.TUNNEL_MAX_SPACING
    if not (0 < a.spacing <= top):
        ap.error(f"--spacing = {a.spacing} m must be in (0, {top}] " + ("(8 cells across the opening)" if a.cases == ["intact"] else
                 "(the 2 mm flaw must cut a full particle row; the intact case alone allows up to 5 mm)"))
    if not (0 < a.end_time <= 0.1):
        ap.error(f"--end-time = {a.end_time} s must be in (0, 0.1]")
    try:
        a.courant = ym.scene.check_courant(a.courant)
        a.grid_shift = uncertainty.parse_shift(a.grid_shift)
    except ValueError as e:
        ap.error(str(e))
    if a.threads is not None and a.threads < 1:
        ap.error("--threads must be ≥ 1")
    if not a.vtu_every > 0:
        ap.error("--vtu-every must be > 0 s")
    try:
        a.ck_steps, a.ck_minutes = resumable.parse_every(a.checkpoint_every)
    except ValueError as e:
        ap.error(str(e))
    return a


class CaseRun:
    """A case: the scene, its recorders (curve, first crack, snapshots), the resumable run, the report."""

    def __init__(self, case, args):
        self.case, self.args = case, args
        self.dir = os.path.join(args.out, case)
        self.solver, self.bodies = cases.arch_tunnel(case, args.spacing, filler_friction=args.filler_mu, flaw_angle=math.radians(args.flaw_angle),
                                                     grout=rocks.cement_grout(young=args.grout_young), grid_shift=args.grid_shift)
        s = self.solver
        step_options = ym.scene.apply_step_options(s, args)
        self.flaw = self.bodies["flaw"]
        self.dp = s.spacing / 2                                # ppc = 2
        self.x0 = ym.get(s, "pos")                             # initial positions by id
        self.lattice = analysis.Lattice(self.x0, self.dp, origin=(0, 0))
        self.rock = ym.get(s, "material") == 0                 # rock, not grout (material 0 of the scene)
        self.job = resumable.ResumableRun(s, self.dir, state=dict(first_crack=None, snapshots=[]), every_steps=args.ck_steps,
                                          every_minutes=args.ck_minutes, engine=self.bodies["engine"],
                                          meta={"case": case, "spacing": args.spacing, **step_options, "flaw_angle": args.flaw_angle,
                                                "filler_mu": args.filler_mu, "grout_young": args.grout_young,
                                                "grid_shift": args.grid_shift})
        self.failed, self.interrupted = None, False

    state = property(lambda self: self.job.state)             # the record: checkpointed, state.json at the end

    def watch_damage(self, solver):
        """The first tensile crack (D = 1): when, where, how many particles."""
        if self.state["first_crack"] is None:
            self.state["first_crack"] = results.first_crack(solver, self.x0, self.bodies["platen_displacement"](), self.flaw)

    def snapshot(self, solver):
        """Fields for the pictures and the analysis at 8, 12, 20 ms (id order), kept in an .npz."""
        name = results.save_snapshot(solver, self.dir, self.bodies["platen_displacement"]())
        if name not in self.state["snapshots"]:
            self.state["snapshots"].append(name)

    def run(self):
        a, s, job = self.args, self.solver, self.job
        from yade import O
        if a.resume and job.finished(a.end_time):                # a finished run: outputs again without the checkpoint
            print(f"[{self.case}] finished earlier (t = {self.state['time'] * 1e3:.3f} ms): outputs from its snapshots", flush=True)
            return self
        if a.resume and job.resume():
            print(f"[{self.case}] resumed at t = {s.time * 1e3:.3f} ms (step {s.steps})", flush=True)
        elif a.pictures:
            self.geometry_picture()
        curve = output.CurveRecorder(self.bodies["platen_displacement"], self.bodies["axial_stress"], RECORD_STEP_MM * 1e-3,
                                     state=self.state)         # the curve continues in the checkpointed record
        print(f"[{self.case}] {s.numParticles} particles, l = {s.spacing * 1e3:g} mm, Δt ≈ {s.stableDt() * 1e6:.3f} µs, "
              f"{a.end_time / s.stableDt():.0f} steps to {a.end_time * 1e3:g} ms", flush=True)
        series = output.VtuSeries(self.dir, fields=lambda s: output.particle_fields(s, x0=self.x0), resume=job.resumed)
        times = [t * 1e-3 for t in SNAPSHOTS_MS if t * 1e-3 <= a.end_time + 1e-12]
        vtu_times = sorted(set(np.arange(0.0, a.end_time + 1e-12, a.vtu_every).tolist()) | set(times))
        outs = [runner.Output(curve.record, steps=1), runner.Output(self.watch_damage, steps=10),
                runner.Output(self.snapshot, times=times, at_end=True), runner.Output(series.write, times=vtu_times, at_end=True)]
        status = job.run(a.end_time, outs, progress=a.progress, label=self.case, advance=O.step)
        self.state["final_displacement"] = self.bodies["platen_displacement"]()
        if status == "failed":                                 # half-updated state: no checkpoint, the outputs so far
            self.failed, self.interrupted = job.error, True
            print(f"[{self.case}] stopped by the solver: {job.error}", flush=True)
        elif status == "stopped":
            print(f"[{self.case}] stopped at t = {s.time * 1e3:.3f} ms ({job.stop_reason}); rerun with --resume to continue", flush=True)
        self.interrupted = self.interrupted or job.interrupted
        return self

    def geometry_picture(self):
        """The scene as built (paper Fig. 16): particles by material, the platen, the filler, the flaw."""
        from yade import O
        bodies = ((self.bodies["platen"], "tab:blue", "rigid platen"), (self.bodies["filler"], "tab:red", "rigid filler"))
        fig, ax = output.scene_figure(self.x0 * 1e3, [(self.rock, "tan", "sandstone"), (~self.rock, "tab:green", "grout")],
                                      [(output.box_outline(O.bodies[b]) * 1e3, c, n) for b, c, n in bodies if b is not None],
                                      (4.2 * 72 / 156 * self.dp * 1e3) ** 2, unit="mm")   # a marker slightly wider than a particle
        if self.flaw is not None:
            ax.plot(*(np.array([self.flaw["toe"], self.flaw["tip"]]) * 1e3).T, "k:", lw=0.8)
            ax.annotate("flaw toe", self.flaw["toe"] * 1e3, xytext=(8, -14), textcoords="offset points", fontsize=7)
        ax.set_xlim(-3, 153), ax.set_ylim(-3, 163)
        ax.set_title(f"{self.case}: {self.solver.numParticles} particles, l = {self.solver.spacing * 1e3:g} mm", fontsize=9)
        ax.legend(fontsize=7, loc="lower left", markerscale=3)
        output.save_figure(fig, os.path.join(self.dir, "geometry.png"), dpi=110)

    def analyse(self):
        """yade_mpm.analysis on every snapshot (cases.tunnel_report: the places named)."""
        self.snaps, self.result = results.analyse_snapshots(self.dir, self.state["snapshots"], self.lattice, self.flaw,
                                                            analysis.softening_end(self.solver), rock=self.rock)
        return self.result

    def summary_entry(self):
        return results.summary_entry(self.case, self.solver, self.state, self.result, CURVE_STEP_MM)

    def write_curve(self):
        rows = [(t, d * 1e3, sig / 1e6) for t, d, sig in self.state["curve"]]
        output.write_csv(os.path.join(self.dir, "axial_stress.csv"), ["time_s", "displacement_mm", "axial_stress_MPa"], rows)

    def pictures(self):
        """Figs. 18–19: plastic strain (with the shear bands), damage (with the spalled region), σ̃max, displacements."""
        for key, f in sorted(self.snaps.items()):
            i = self.result["snapshots"][key]
            pos, disp, ms = f["pos"] * 1e3, (f["pos"] - self.x0) * 1e3, max(0.05, 60.0 * (self.dp * 1e3) ** 2 / 4)
            e_top = max(float(np.percentile(f["plastic_strain"][self.rock], 99.5)), 1e-6)
            fig, axs = output.field_figure(pos, [
                ("accumulated plastic strain ε̄p [-] (to its 99.5th pct.)", f["plastic_strain"], "viridis", (0, e_top)),
                ("damage D [-] (cyan: spalled region)", f["damage"], "inferno", (0, 1)),
                ("max tensile principal stress σ̃max [MPa]", np.maximum(f["max_principal_stress"], 0) / 1e6, "magma", None),
                ("x displacement [mm]", disp[:, 0], "coolwarm", "sym"), ("y displacement [mm]", disp[:, 1], "viridis", None)],
                ms, xlim=(-2, 152), ylim=(-2, 154), panel_size=(5.0, 5.2), unit="mm")
            for b in i["bands"]:                               # detected shear bands: principal axes
                c, u = np.array(b["centroid"]) * 1e3, 0.5e3 * b["length"] * np.array([np.cos(np.radians(b["angle_deg"])), np.sin(np.radians(b["angle_deg"]))])
                axs[0].plot(*np.array([c - u, c + u]).T, "r-", lw=1)
                axs[0].annotate(f"{abs(b['angle_deg']):.0f}°", c + u, color="r", fontsize=8)
            if f["spalled"].any():
                axs[1].scatter(*pos[f["spalled"]].T, s=ms * 1.6, facecolors="none", edgecolors="cyan", linewidths=0.3, marker="s")
            lines = [self.case, f"grid {self.solver.spacing * 1e3:g} mm, {self.solver.numParticles} particles", ""] + snapshot_lines(i)
            axs[5].text(0.0, 1.0, "\n".join(lines), va="top", fontsize=9, family="monospace", transform=axs[5].transAxes)
            output.save_figure(fig, os.path.join(self.dir, f"fields_{key}.png"), dpi=90)

    def text(self, entry):
        st, r = self.state, self.result["snapshots"]
        L = [f"== {self.case} ==",
             f"grid {self.solver.spacing * 1e3:g} mm, {entry['particles']} particles, {entry['steps']} steps, wall {st['wall']:.1f} s, "
             f"{(entry['particle_steps_per_s'] or 0) / 1e6:.2f} M particle-steps/s, final displacement {entry['final_displacement_mm']:.3f} mm"
             + ("" if st["done"] else (f"  [STOPPED BY THE SOLVER: {st['error']}]" if st.get("error") else "  [UNFINISHED: rerun with --resume]"))]
        fc = st["first_crack"]
        L.append("first tensile crack (D = 1): " + (f"{fc['location']} at t = {fc['time'] * 1e3:.2f} ms, displacement "
                                                     f"{fc['displacement'] * 1e3:.3f} mm ({fc['particles']} particles)" if fc else "none"))
        for key, i in sorted(r.items()):
            L += [""] + snapshot_lines(i)
        return "\n".join(L)


def snapshot_lines(i):
    """One snapshot's analysis (cases.tunnel_report) as short lines: summary.txt and the field pictures."""
    L = [f"t = {i['time_ms']:.1f} ms, platen displacement {i['displacement_mm']:.2f} mm",
         "spalled / failed zone at the opening: " + (f"{i['spalled_area_mm2']:.0f} mm², at {i['spalling_at']}" if i["spalling_at"] else "none"),
         f"   {i['spalled_mass_kg_per_m']:.3f} kg per m of tunnel, {i['spalled_fragments']} particles in detached fragments",
         f"symmetry: damage {_fmt(i['symmetry_damage'])}, plastic strain {_fmt(i['symmetry_plastic'])}",
         f"D = 1 in {100 * i['damaged_fraction']:.2f} %, softened {100 * i['softened_fraction']:.2f} % of the rock"]
    L += [f"longest tensile crack: {c['length'] * 1e3:.0f} mm at {c['angle_deg']:+.0f}°, {c['location']}" for c in i.get("cracks", [])[:1]]
    L += ["shear bands (ε̄p ≥ %.1e, beyond %g mm of opening and flaw):" % (i["band_threshold"], cases.BAND_GAP * 1e3)]
    L += [f"   {b['side']}: {abs(b['angle_deg']):.0f}° to the horizontal, {b['length'] * 1e3:.0f} mm, {b['location']}"
          for b in i["bands"][:5]] or ["   none"]
    if "toe_damaged" in i:
        L += [f"flaw toe (4 mm): {i['toe_damaged']} with D = 1, {i['toe_softened']} softened",
              f"   failed zone from the toe reaches: {i['toe_link_to_opening'] or 'nowhere'}",
              f"   plastic band from the toe reaches: {i['toe_plastic_link_to_opening'] or 'nowhere'}"]
    return L


def _fmt(v):
    return "n/a" if v is None else f"{v:.2f}"


def plot_curves(runs, out):
    plt = output.pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    style = {"intact": "k-", "open_flaw": "r-", "filled_flaw": "b-", "grout_flaw": "g-"}
    for r in runs:
        c = np.array(r.state["curve"]) if r.state["curve"] else np.zeros((0, 3))
        ax.plot(c[:, 1] * 1e3, c[:, 2] / 1e6, style.get(r.case, "-"), lw=1.3, label=r.case.replace("_", " "))
    ax.set(xlabel="axial (platen) displacement [mm]", ylabel="axial stress [MPa]",
           title=f"Arch tunnel, plane-strain compression (grid {runs[0].solver.spacing * 1e3:g} mm) — cf. paper Fig. 17")
    ax.grid(alpha=0.3), ax.legend()
    output.save_figure(fig, os.path.join(out, "axial_stress.png"), dpi=130)


def main():
    a = parse()
    if a.threads:
        ym.setThreads(a.threads)
    os.makedirs(a.out, exist_ok=True)
    runs = []
    for case in a.cases:
        r = CaseRun(case, a).run()
        r.analyse(), r.write_curve(), r.pictures() if a.pictures else None
        runs.append(r)
        with open(os.path.join(r.dir, "case.json"), "w") as f:
            json.dump(dict(r.result, first_crack=r.state["first_crack"], finished=r.state["done"]), f, indent=1)
        if r.interrupted:                                      # a signal or a solver error: no further case
            break
    failed = [r.case for r in runs if r.failed]
    entries = [r.summary_entry() for r in runs]
    output.write_summary(a.out, {"cases": entries})
    if a.pictures:
        plot_curves(runs, a.out)
    txt = [r.text(e) for r, e in zip(runs, entries)]
    o = results.ordering(entries)
    if o:
        txt.append(f"Fig. 17 ordering open_flaw < intact < filled_flaw holds at {o['holds']} of {o['samples']} displacements (0.1 mm apart)")
    open(os.path.join(a.out, "summary.txt"), "w").write("\n\n".join(txt) + "\n")
    if not failed and all(r.state["done"] for r in runs) and len(runs) == len(a.cases):
        batch.write_summary(a.out, [results.study_row(r.case, r.state, r.result, e, vars(a)) for r, e in zip(runs, entries)])   # a study's rows: one per case
    print("\n\n".join(txt))
    print(f"results in {os.path.abspath(a.out)}")
    if failed:
        print(f"stopped by the solver in: {', '.join(failed)} (outputs written up to the stop)", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    batch.main(main)
