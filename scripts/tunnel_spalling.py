"""Spalling of an arch-shaped tunnel under plane-strain compression (paper Sec. 4, Figs. 16–19):
150 × 150 mm Pan (2020b) sandstone, a 40 × 25 mm opening under a 20 mm-radius roof, free-slip sides,
a rigid YADE platen pushed down at 0.1 m/s for 20 ms, and four cases:

    intact       no flaw                                  (Fig. 16a, 18)
    open_flaw    60 × 2 mm open flaw left of the tunnel   (Fig. 16b, 19 top)
    filled_flaw  the flaw filled by a free rigid YADE body with PTS contact (Fig. 16c, 19 bottom)
    grout_flaw   the flaw filled with elastic cement grout bonded through the grid (beyond the paper)

    /usr/bin/python3 scripts/tunnel_spalling.py --out out/tunnel                 # all four, default grid
    /usr/bin/python3 scripts/tunnel_spalling.py --out out/tunnel_paper --paper --cases intact
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
import time

import numpy as np

import yade_mpm as ym
from yade_mpm import analysis, cases, checkpoint, output, rocks, runner

SNAPSHOTS_MS = (8.0, 12.0, 20.0)          # field pictures (Figs. 18a–c, 19)
CURVE_STEP_MM = 0.1                       # summary.json: axial stress every 0.1 mm
RECORD_STEP_MM = 0.01                     # CSV: mean platen stress over every 0.01 mm of displacement
BAND_GAP = 5e-3                          # shear bands are looked for beyond this distance from the opening [m]
BAND_FRACTION, BAND_MIN = 0.5, 5e-4      # band particles: ε̄p ≥ max(BAND_MIN, BAND_FRACTION × its 99th percentile there)
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
    ap.add_argument("--courant", type=float, default=0.5,
                    help="Courant number C of Δt = C·l/(v_c + max|v|) (default 0.5; C = 1, the paper's Δt, inverts the platen corner)")
    ap.add_argument("--threads", type=int, default=None, help="OpenMP threads (default: all cores)")
    ap.add_argument("--vtu-every", type=float, default=4e-3, help="simulated seconds between VTU files, plus 8, 12, 20 ms (default 0.004)")
    ap.add_argument("--checkpoint-every", default="5min",
                    help="checkpoint period: N (steps) or Nmin (wall minutes); 0 = only at the end/interrupt (default 5min)")
    ap.add_argument("--resume", action="store_true", help="continue unfinished cases from OUT/CASE/checkpoint.ckpt; keep finished ones")
    ap.add_argument("--progress", type=float, default=15.0, help="wall seconds between progress lines (default 15)")
    a = ap.parse_args()
    chosen = [c.strip() for c in a.cases.split(",") if c.strip()]
    bad = [c for c in chosen if c not in cases.TUNNEL_CASES]
    if bad or not chosen:
        ap.error(f"--cases: unknown {bad}; allowed {', '.join(cases.TUNNEL_CASES)}")
    a.cases = chosen
    if a.paper and a.spacing is not None:
        ap.error("--paper sets the spacing; do not also give --spacing")
    a.spacing = PAPER_SPACING if a.paper else (a.spacing or DEFAULT_SPACING)
    if not (0 < a.spacing <= cases.TUNNEL_MAX_SPACING):
        ap.error(f"--spacing = {a.spacing} m must be in (0, {cases.TUNNEL_MAX_SPACING}] (the 2 mm flaw must cut a full particle row)")
    if not (0 < a.end_time <= 0.1):
        ap.error(f"--end-time = {a.end_time} s must be in (0, 0.1]")
    if not (0 < a.courant <= 1):
        ap.error(f"--courant = {a.courant} must be in (0, 1]")
    if a.threads is not None and a.threads < 1:
        ap.error("--threads must be ≥ 1")
    if not a.vtu_every > 0:
        ap.error("--vtu-every must be > 0 s")
    ce = a.checkpoint_every.strip()
    try:
        if ce.endswith("min"):
            a.ck_steps, a.ck_minutes = None, float(ce[:-3])
            if not a.ck_minutes > 0:
                raise ValueError
        else:
            a.ck_steps, a.ck_minutes = (int(ce) or None), None
            if a.ck_steps is not None and a.ck_steps < 1:
                raise ValueError
    except ValueError:
        ap.error(f"--checkpoint-every = {ce!r} must be a step count ≥ 0 or minutes like '10min'")
    return a


# ----------------------------------------------------------------------------------- one case
class CaseRun:
    """A case: scene, recorders (curve, first crack, snapshots), checkpointing, analysis, pictures."""

    def __init__(self, case, args):
        self.case, self.args = case, args
        self.dir = os.path.join(args.out, case)
        os.makedirs(self.dir, exist_ok=True)
        self.ckpt = os.path.join(self.dir, "checkpoint.ckpt")
        self.meta = {"case": case, "spacing": args.spacing, "courant": args.courant}
        self.solver, self.bodies = cases.arch_tunnel(case, args.spacing)
        s = self.solver
        s.courant = args.courant
        self.W = self.bodies["width"]
        self.ppc = 2
        self.dp = s.spacing / self.ppc
        self.x0 = ym.get(s, "pos")                             # initial positions by id
        self.lattice = analysis.Lattice(self.x0, self.dp, origin=(0, 0))
        self.rock = self._rock_mask()
        self.dist = cases.tunnel_opening_distance(self.x0)
        fl = self.bodies["flaw"]                              # distance to the flaw (its faces slide: not a band)
        if fl is None:
            self.dist_flaw = np.full(len(self.x0), np.inf)
        else:
            r = self.x0 - fl["toe"]
            along = np.clip(r @ fl["direction"], 0, fl["length"])
            self.dist_flaw = np.linalg.norm(r - along[:, None] * fl["direction"], axis=1)
        # recorder state (saved with each checkpoint)
        self.state = dict(curve=[], acc=[0.0, 0], first_crack=None, wall=0.0, steps_run=0, done=False, snapshots=[])

    def _rock_mask(self):
        """Per particle (id order): rock, not grout (the rock is material 0 of the scene)."""
        s = self.solver
        return s.view("material")[ym.id_order(s)] == 0

    # ---- recorders
    def displacement(self):
        return self.bodies["platen_displacement"]()                          # [m]

    def stress(self):
        return self.bodies["axial_stress"]()                                 # [Pa], compression positive

    def record(self, solver):
        acc = self.state["acc"]
        acc[0] += self.stress()
        acc[1] += 1
        d = self.displacement()
        nxt = (len(self.state["curve"])) * RECORD_STEP_MM * 1e-3
        if d >= nxt - 1e-12:
            self.state["curve"].append([solver.time, d, acc[0] / acc[1]])
            self.state["acc"] = [0.0, 0]

    def watch_damage(self, solver):
        if self.state["first_crack"] is not None:
            return
        dmg = solver.view("damage")
        if dmg.max() < 1.0:
            return
        ids = solver.view("id")[dmg >= 1.0]
        pts = self.x0[ids]
        c = pts.mean(axis=0)
        self.state["first_crack"] = dict(time=solver.time, displacement=self.displacement(), particles=int(len(ids)),
                                         centroid=c.tolist(), location=self._where(pts))

    def _where(self, pts):
        """Location name of a set of points: the most common name; 'A and B' when split both sides."""
        names = [cases.tunnel_location(p, self.bodies["flaw"]) for p in pts]
        uniq, cnt = np.unique(names, return_counts=True)
        order = np.argsort(-cnt)
        top = [str(uniq[k]) for k in order if cnt[k] >= 0.25 * cnt.max()]
        return " and ".join(top[:2])

    def snapshot(self, solver):
        """Fields for the pictures and the analysis at 8, 12, 20 ms (id order), kept in an .npz."""
        o = ym.id_order(solver)
        f = dict(time=solver.time, displacement=self.displacement(), pos=ym.get(solver, "pos", o),
                 damage=ym.get(solver, "damage", o), epsP=ym.get(solver, "plastic_strain", o),
                 smax=ym.get(solver, "max_principal_stress", o), mass=ym.get(solver, "mass", o))
        name = f"snapshot_{int(round(solver.time * 1e3)):02d}ms.npz"      # 08ms, 12ms, 20ms (or where a run stopped)
        np.savez_compressed(os.path.join(self.dir, name), **f)
        if name not in self.state["snapshots"]:
            self.state["snapshots"].append(name)

    def vtu_fields(self, solver):
        pos, fields = output.particle_fields(solver)
        fields["displacement"] = pos - self.x0
        fields["material"] = (~self.rock).astype(np.int64)   # 0 rock, 1 grout
        return pos, fields

    # ---- run
    def run(self):
        a, s = self.args, self.solver
        from yade import O
        resumed = False
        done = os.path.join(self.dir, "state.json")
        if a.resume and os.path.exists(done):                 # a finished run: outputs again without the checkpoint
            st = json.load(open(done))
            if st.get("done") and st.get("time", 0) >= a.end_time * (1 - runner.TIME_TOL):
                self.state = st
                print(f"[{self.case}] finished earlier (t = {st['time'] * 1e3:.3f} ms): outputs from its snapshots", flush=True)
                return self
        if a.resume and os.path.exists(self.ckpt):
            h = checkpoint.load(self.ckpt, meta=self.meta)
            self.state = h["extra"]
            resumed = True
            print(f"[{self.case}] resumed at t = {s.time * 1e3:.3f} ms (step {s.steps})", flush=True)
        if resumed and s.time >= a.end_time * (1 - runner.TIME_TOL):   # finished (a larger --end-time continues it)
            self.state["done"] = True
            return self
        if not resumed:
            self.geometry_picture()
        n = s.numParticles
        print(f"[{self.case}] {n} particles, l = {s.spacing * 1e3:g} mm, Δt ≈ {s.stableDt() * 1e6:.3f} µs, "
              f"{a.end_time / s.stableDt():.0f} steps to {a.end_time * 1e3:g} ms", flush=True)
        series = output.VtuSeries(self.dir, fields=self.vtu_fields)
        if resumed:                                           # keep the files written before the interruption
            series.entries = _pvd_entries(series.pvd)
        ck = checkpoint.Checkpointer(self.ckpt, every_steps=a.ck_steps, every_minutes=a.ck_minutes, meta=self.meta,
                                     extra=lambda: self.state)
        times = [t * 1e-3 for t in SNAPSHOTS_MS if t * 1e-3 <= a.end_time + 1e-12]
        vtu_times = sorted(set(np.arange(0.0, a.end_time + 1e-12, a.vtu_every).tolist()) | set(times))
        outs = [runner.Output(self.record, steps=1), runner.Output(self.watch_damage, steps=10),
                runner.Output(self.snapshot, times=times, at_end=True),
                runner.Output(series.write, times=vtu_times, at_end=True), ck.output(steps=50)]
        wall0 = time.time()
        steps0 = s.steps
        self.failed = None
        with ck.signals():
            try:
                res = runner.run(s, end_time=a.end_time, progress=a.progress, label=self.case, outputs=outs, advance=O.step)
            except RuntimeError as e:                        # YADE wraps the solver's MpmSimulationError
                self.failed = str(self.bodies["engine"].error or e)
        self.state["wall"] += time.time() - wall0
        self.state["steps_run"] += s.steps - steps0
        if self.failed:                                       # half-updated state: no checkpoint, the outputs so far
            self.state["final_displacement"] = self.displacement()
            self.state["error"] = self.failed
            print(f"[{self.case}] stopped by the solver: {self.failed}", flush=True)
            self.interrupted = True
            return self
        self.state["done"] = res.reason == "end_time"
        self.state["final_displacement"] = self.displacement()
        self.state["time"], self.state["steps"] = s.time, int(s.steps)
        ck.save(s.steps)                                      # the last state: resumable, or the finished run
        with open(done, "w") as f:                            # the recorded state, readable without the build
            json.dump(self.state, f)
        if not self.state["done"]:
            print(f"[{self.case}] stopped at t = {s.time * 1e3:.3f} ms ({ck.signal_name or res.reason}); "
                  f"rerun with --resume to continue", flush=True)
        self.interrupted = ck.stop_requested
        return self

    def geometry_picture(self):
        """The scene as built (paper Fig. 16): particles by material, the platen, the filler, the flaw."""
        from yade import O
        plt = output.pyplot()
        from matplotlib.patches import Polygon as Patch
        fig, ax = plt.subplots(figsize=(4.6, 4.8))
        x = self.x0 * 1e3
        ms = (4.2 * 72 / 156 * self.dp * 1e3) ** 2          # a marker slightly wider than the particle cell
        ax.scatter(x[self.rock, 0], x[self.rock, 1], s=ms, c="tan", marker="s", linewidths=0, label="sandstone", rasterized=True)
        if (~self.rock).any():
            ax.scatter(x[~self.rock, 0], x[~self.rock, 1], s=ms, c="tab:green", marker="s", linewidths=0, label="grout", rasterized=True)
        for bid, color, name in ((self.bodies["platen"], "tab:blue", "rigid platen"), (self.bodies["filler"], "tab:red", "rigid filler")):
            if bid is None:
                continue
            b = O.bodies[bid]
            e, q, c = b.shape.extents, b.state.ori, b.state.pos
            R = np.array([[q.toRotationMatrix()[i, j] for j in range(2)] for i in range(2)])
            corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * [e[0], e[1]]
            ax.add_patch(Patch((corners @ R.T + [c[0], c[1]]) * 1e3, closed=True, fc=color, alpha=0.6, label=name))
        fl = self.bodies["flaw"]
        if fl is not None:
            ax.plot(*(np.array([fl["toe"], fl["tip"]]) * 1e3).T, "k:", lw=0.8)
            ax.annotate("flaw toe", fl["toe"] * 1e3, xytext=(8, -14), textcoords="offset points", fontsize=7)
        ax.set_aspect("equal")
        ax.set_xlim(-3, 153), ax.set_ylim(-3, 163)
        ax.set_xlabel("x [mm]"), ax.set_ylabel("y [mm]")
        ax.set_title(f"{self.case}: {self.solver.numParticles} particles, l = {self.solver.spacing * 1e3:g} mm", fontsize=9)
        ax.legend(fontsize=7, loc="lower left", markerscale=3)
        fig.tight_layout()
        fig.savefig(os.path.join(self.dir, "geometry.png"), dpi=110)
        plt.close(fig)

    # ---- analysis and pictures
    def analyse(self):
        s, st = self.solver, self.state
        mat = s.dpgkParameters()
        soft_end = (1 - mat.residualCohesion) * mat.critPlasticStrain          # Eq. 34 reaches its floor
        cx = self.W / 2
        holes = cases.arch_tunnel_holes()
        opening = lambda p: np.any([h.contains(p) for h in holes], axis=0)
        snaps = {}
        for name in st["snapshots"]:
            with np.load(os.path.join(self.dir, name)) as z:
                snaps[name[9:13]] = {k: z[k] for k in z.files}
        res = {"snapshots": {}}
        for key, f in sorted(snaps.items()):
            failed = self.rock & ((f["damage"] >= 1.0) | (f["epsP"] >= soft_end))
            sp = analysis.spalled(failed, self.lattice, opening, f["mass"])
            shear = self.rock & (f["epsP"] >= soft_end)
            # shear bands: localised plastic strain (not the tensile cracks) away from the opening's plastic rim
            zone = self.rock & (f["damage"] < 1) & (self.dist > BAND_GAP) & (self.dist_flaw > BAND_GAP)
            ref = float(np.percentile(f["epsP"][zone], 99)) if zone.any() else 0.0
            thr = max(BAND_MIN, BAND_FRACTION * ref)
            bands = analysis.bands(zone & (f["epsP"] >= thr), self.lattice)
            for b in bands:
                b["side"] = "left" if b["centroid"][0] < cx else "right"
                b["location"] = cases.tunnel_location(b["centroid"], self.bodies["flaw"])
            surf = sp["mask"] & failed
            toe = {}
            fl = self.bodies["flaw"]
            if fl is not None:                                  # the failed zone grown from the flaw toe (Fig. 19)
                near_toe = self.rock & (np.hypot(*(self.x0 - fl["toe"]).T) < 4e-3)
                link = analysis.clusters_touching(failed, self.lattice, near_toe & failed)
                reach = link & analysis.opening_surface(self.lattice, opening)
                # the same for the localised plastic strain (the shear band threshold) grown from the toe
                plastic = self.rock & (f["epsP"] >= thr)
                plink = analysis.clusters_touching(plastic, self.lattice, near_toe & plastic)
                preach = plink & analysis.opening_surface(self.lattice, opening)
                toe = dict(toe_damaged=int(np.count_nonzero(near_toe & (f["damage"] >= 1))),
                           toe_softened=int(np.count_nonzero(near_toe & shear)),
                           toe_link_to_opening=self._where(self.x0[reach]) if reach.any() else None,
                           toe_plastic_link_to_opening=self._where(self.x0[preach]) if preach.any() else None)
            res["snapshots"][key] = dict(
                time_ms=float(f["time"] * 1e3), displacement_mm=float(f["displacement"] * 1e3),
                symmetry_damage=analysis.mirror_symmetry(np.where(self.rock, f["damage"], 0), self.lattice, cx),
                symmetry_plastic=analysis.mirror_symmetry(np.where(self.rock, f["epsP"], 0), self.lattice, cx),
                damaged_fraction=float(np.mean(f["damage"][self.rock] >= 1)), softened_fraction=float(np.mean(shear[self.rock])),
                spalled_area_mm2=sp["area"] * 1e6, spalled_mass_kg_per_m=sp["mass"], spalled_particles=int(sp["mask"].sum()),
                spalled_fragments=sp["fragments"],
                spalling_at=self._where(self.x0[surf]) if surf.any() else None,
                band_threshold=thr, bands=bands[:6], **toe)
            f["spalled"] = sp["mask"]
        self.snaps, self.result = snaps, res
        return res

    def summary_entry(self):
        st, s = self.state, self.solver
        curve = np.array(st["curve"]) if st["curve"] else np.zeros((0, 3))
        d_end = st.get("final_displacement", 0.0)
        at = []
        if len(curve):
            for k in range(int(math.floor(curve[-1, 1] * 1e3 / CURVE_STEP_MM + 1e-9)) + 1):
                dmm = round(k * CURVE_STEP_MM, 10)
                at.append({"displacement_mm": dmm, "stress_MPa": float(np.interp(dmm * 1e-3, curve[:, 1], curve[:, 2]) / 1e6)})
        snap = self.result["snapshots"]
        sym_key = "08ms" if "08ms" in snap else (sorted(snap)[-1] if snap else None)
        fc = st["first_crack"]
        return {"case": self.case, "grid_spacing_m": s.spacing, "particles": int(s.numParticles), "steps": int(st.get("steps", s.steps)),
                "wall_time_s": round(st["wall"], 2),
                "particle_steps_per_s": float(s.numParticles * st["steps_run"] / st["wall"]) if st["wall"] > 0 else None,
                "final_displacement_mm": d_end * 1e3, "axial_stress_MPa_at": at,
                "symmetry_damage": snap[sym_key]["symmetry_damage"] if sym_key else None,
                "first_damage_location": fc["location"] if fc else None}

    def write_curve(self):
        rows = [(t, d * 1e3, sig / 1e6) for t, d, sig in self.state["curve"]]
        output.write_csv(os.path.join(self.dir, "axial_stress.csv"), ["time_s", "displacement_mm", "axial_stress_MPa"], rows)

    def pictures(self):
        plt = output.pyplot()
        from matplotlib.colors import Normalize
        for key, f in sorted(self.snaps.items()):
            info = self.result["snapshots"][key]
            pos, disp = f["pos"] * 1e3, (f["pos"] - self.x0) * 1e3
            e_top = max(float(np.percentile(f["epsP"][self.rock], 99.5)), 1e-6)
            panels = [("accumulated plastic strain ε̄p [-] (to its 99.5th pct.)", f["epsP"], "viridis", (0, e_top)),
                      ("damage D [-] (cyan: spalled region)", f["damage"], "inferno", (0, 1)),
                      ("max tensile principal stress σ̃max [MPa]", np.maximum(f["smax"], 0) / 1e6, "magma", None),
                      ("x displacement [mm]", disp[:, 0], "coolwarm", "sym"),
                      ("y displacement [mm]", disp[:, 1], "viridis", None)]
            fig, axs = plt.subplots(2, 3, figsize=(15, 10.4))
            axs = axs.ravel()
            ms = max(0.05, 60.0 * (self.dp * 1e3) ** 2 / 4)
            for ax, (title, v, cmap, lim) in zip(axs, panels):
                if lim == "sym":
                    m = np.max(np.abs(v)) or 1.0
                    norm = Normalize(-m, m)
                elif lim is None:
                    norm = Normalize(np.min(v), np.max(v) if np.max(v) > np.min(v) else np.min(v) + 1)
                else:
                    norm = Normalize(*lim)
                sc = ax.scatter(pos[:, 0], pos[:, 1], c=v, s=ms, cmap=cmap, norm=norm, marker="s", linewidths=0, rasterized=True)
                ax.set_title(title, fontsize=9)
                ax.set_aspect("equal")
                ax.set_xlim(-2, 152), ax.set_ylim(-2, 154)
                ax.set_xlabel("x [mm]"), ax.set_ylabel("y [mm]")
                fig.colorbar(sc, ax=ax, shrink=0.8)
            for b in info["bands"]:                            # detected shear bands: principal axes
                c, h, a = np.array(b["centroid"]) * 1e3, 0.5 * b["length"] * 1e3, np.radians(b["angle_deg"])
                u = h * np.array([np.cos(a), np.sin(a)])
                axs[0].plot(*np.array([c - u, c + u]).T, "r-", lw=1)
                axs[0].annotate(f"{abs(b['angle_deg']):.0f}°", c + u, color="r", fontsize=8)
            sp = f["spalled"]
            if sp.any():
                axs[1].scatter(pos[sp, 0], pos[sp, 1], s=ms * 1.6, facecolors="none", edgecolors="cyan", linewidths=0.3, marker="s")
            axs[5].axis("off")
            lines = [f"{self.case}", f"t = {info['time_ms']:.1f} ms, platen displacement {info['displacement_mm']:.2f} mm",
                     f"grid {self.solver.spacing * 1e3:g} mm, {self.solver.numParticles} particles", "",
                     f"spalled / failed zone at the opening: {info['spalled_area_mm2']:.0f} mm²",
                     f"   {info['spalled_mass_kg_per_m']:.3f} kg per m of tunnel, at: {info['spalling_at'] or '—'}",
                     f"damage symmetry {_fmt(info['symmetry_damage'])}, plastic strain symmetry {_fmt(info['symmetry_plastic'])}",
                     f"D = 1 in {100 * info['damaged_fraction']:.2f} % of the rock",
                     "shear bands (ε̄p ≥ %.1e, beyond %g mm of opening and flaw):" % (info["band_threshold"], BAND_GAP * 1e3)]
            lines += [f"   {b['side']}: {abs(b['angle_deg']):.0f}° to the horizontal, {b['length'] * 1e3:.0f} mm, {b['location']}"
                      for b in info["bands"][:5]] or ["   none"]
            if "toe_damaged" in info:
                lines += [f"flaw toe (4 mm): {info['toe_damaged']} with D = 1, {info['toe_softened']} softened",
                          f"   failed zone from the toe reaches: {info['toe_link_to_opening'] or 'nowhere'}",
                          f"   plastic band from the toe reaches: {info.get('toe_plastic_link_to_opening') or 'nowhere'}"]
            axs[5].text(0.0, 1.0, "\n".join(lines), va="top", fontsize=9, family="monospace", transform=axs[5].transAxes)
            fig.tight_layout()
            fig.savefig(os.path.join(self.dir, f"fields_{key}.png"), dpi=90)
            plt.close(fig)

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
            bands = "; ".join(f"{b['side']} {b['angle_deg']:+.0f}° ({b['length'] * 1e3:.0f} mm, {b['location']})" for b in i["bands"][:4]) or "none"
            L.append(f"t = {i['time_ms']:.1f} ms (d = {i['displacement_mm']:.2f} mm): symmetry D {_fmt(i['symmetry_damage'])}, "
                     f"ε̄p {_fmt(i['symmetry_plastic'])}; D = 1 in {100 * i['damaged_fraction']:.1f} %, softened {100 * i['softened_fraction']:.1f} % "
                     f"of the rock; shear bands (inclination to the horizontal): {bands}; spalling at the opening surface: "
                     + (f"yes, at {i['spalling_at']}, {i['spalled_area_mm2']:.0f} mm² ({i['spalled_mass_kg_per_m']:.3f} kg per m of tunnel, "
                        f"{i['spalled_fragments']} particles in detached fragments)" if i["spalling_at"] else "no")
                     + (f"; flaw toe: {i['toe_damaged']} particles D = 1, {i['toe_softened']} softened within 4 mm, failed zone from "
                        f"the toe reaches the opening at: {i['toe_link_to_opening'] or 'nowhere'}, plastic band (ε̄p ≥ {i['band_threshold']:.1e}) "
                        f"from the toe reaches it at: {i.get('toe_plastic_link_to_opening') or 'nowhere'}" if "toe_damaged" in i else ""))
        return "\n".join(L)


def _fmt(v):
    return "n/a" if v is None else f"{v:.2f}"


def _pvd_entries(pvd):
    """(time, path) entries of an existing .pvd (to continue a VTU series after --resume)."""
    import re
    if not os.path.exists(pvd):
        return []
    d = os.path.dirname(pvd)
    return [(float(t), os.path.join(d, f)) for t, f in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', open(pvd).read())]


def plot_curves(runs, out):
    plt = output.pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    style = {"intact": "k-", "open_flaw": "r-", "filled_flaw": "b-", "grout_flaw": "g-"}
    for r in runs:
        c = np.array(r.state["curve"]) if r.state["curve"] else np.zeros((0, 3))
        ax.plot(c[:, 1] * 1e3, c[:, 2] / 1e6, style.get(r.case, "-"), lw=1.3, label=r.case.replace("_", " "))
    ax.set_xlabel("axial (platen) displacement [mm]")
    ax.set_ylabel("axial stress [MPa]")
    ax.set_title(f"Arch tunnel, plane-strain compression (grid {runs[0].solver.spacing * 1e3:g} mm) — cf. paper Fig. 17")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "axial_stress.png"), dpi=130)
    plt.close(fig)


def ordering(entries):
    """At equal displacement: open_flaw < intact < filled_flaw (paper Fig. 17)? Share of the 0.1 mm samples."""
    by = {e["case"]: {p["displacement_mm"]: p["stress_MPa"] for p in e["axial_stress_MPa_at"]} for e in entries}
    if not all(k in by for k in ("intact", "open_flaw", "filled_flaw")):
        return None
    ds = sorted(set(by["intact"]) & set(by["open_flaw"]) & set(by["filled_flaw"]) - {0.0})
    ok = [by["open_flaw"][d] < by["intact"][d] < by["filled_flaw"][d] for d in ds]
    return dict(samples=len(ds), holds=int(sum(ok)), fraction=(sum(ok) / len(ds)) if ds else None)


def main():
    a = parse()
    if a.threads:
        ym.setThreads(a.threads)
    os.makedirs(a.out, exist_ok=True)
    runs, interrupted = [], False
    for case in a.cases:
        r = CaseRun(case, a).run()
        r.analyse()
        r.write_curve()
        r.pictures()
        runs.append(r)
        with open(os.path.join(r.dir, "case.json"), "w") as f:
            json.dump(dict(r.result, first_crack=r.state["first_crack"], finished=r.state["done"]), f, indent=1)
        if getattr(r, "interrupted", False):
            interrupted = True
            break
    failed = [r.case for r in runs if getattr(r, "failed", None)]
    entries = [r.summary_entry() for r in runs]
    output.write_summary(a.out, {"cases": entries})
    plot_curves(runs, a.out)
    txt = [r.text(e) for r, e in zip(runs, entries)]
    o = ordering(entries)
    if o:
        txt.append(f"Fig. 17 ordering open_flaw < intact < filled_flaw holds at {o['holds']} of {o['samples']} displacements (0.1 mm apart)")
    open(os.path.join(a.out, "summary.txt"), "w").write("\n\n".join(txt) + "\n")
    print("\n\n".join(txt))
    print(f"results in {os.path.abspath(a.out)}")
    if failed:
        print(f"stopped by the solver in: {', '.join(failed)} (outputs written up to the stop)", file=sys.stderr)
        sys.exit(1)
    if interrupted:
        sys.exit(0)


if __name__ == "__main__":
    main()
