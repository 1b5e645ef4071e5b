"""A case only 3D can do (issue 22, item 4; doc/validation/three_d.md): a 40 × 80 × 40 mm prism of Miao sandstone with
an inclined penny-shaped (disc) open flaw, 20 mm across, 2 mm thick, inclined 30° (the 2D through flaw's
proportions), under uniaxial compression by the YADE platen (``yade_mpm_paper.cases.prism3d.penny_prism``), and
the intact prism. Each run stops after the peak (as scripts/paper/uniaxial_flaw.py) and writes OUT/NAME/:
curve.csv, run.json (peak, modulus, damage onset: where on the rim damage starts and the first D = 1,
the rim profile at the peak and at the end), particles.pvd + .vtu series (ParaView), snapshots.npz, and
slices.png (damage in the flaw plane, the mid-plane z = D/2 and the plane x = W/2 through the disc centre).
OUT/summary.json and OUT/curves.png compare the runs.

    PYTHONPATH=py OMP_NUM_THREADS=1 /usr/bin/python3 scripts/paper/penny_prism_3d.py [--out DIR] [--spacing L]
        [--runs penny:z,intact:xz] [--end-time T]
"""
import argparse
import json
import os
import sys

import numpy as np

import yade_mpm as ym
from yade_mpm import output, runner
from yade_mpm_paper.cases import prism3d, uniaxial_results as results

DEFAULT_SPACING = 2.5e-3     # [m]: 16 cells across the prism, the disc 8 cells across
END_TIME = 0.012             # loading time cap [s]; runs stop once softened
SNAP_EVERY = 5e-4            # field snapshots every this [s]; VTU every 2 snapshots
ONSET = (0.1, 1.0)           # damage levels whose first appearance is reported [-]


def parse(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default="out/penny_prism_3d", help="output folder (default %(default)s)")
    p.add_argument("--spacing", type=float, default=DEFAULT_SPACING, help="grid spacing [m] (default %(default)s)")
    p.add_argument("--runs", default="penny:z,intact:xz", help="VARIANT:SYMMETRY,... (symmetry none, z (half), xz (quarter, intact))")
    p.add_argument("--end-time", type=float, default=END_TIME, help="loading time cap [s] (default %(default)s)")
    p.add_argument("--progress", type=float, default=60.0, help="wall seconds between progress lines")
    p.add_argument("--summary-only", action="store_true", help="only collect OUT/*/run.json")
    a = p.parse_args(argv)
    a.run_list = [tuple(r.split(":")) if ":" in r else (r, "none") for r in a.runs.split(",")]
    return a


def one_run(a, variant, symmetry):
    name = f"{variant}_{symmetry}"
    d = os.path.join(a.out, name)
    os.makedirs(d, exist_ok=True)
    s, sc = prism3d.penny_prism(variant, a.spacing, symmetry=symmetry, label=f"mpm_{name}")
    fl = sc["flaw"]
    snaps, onset = {}, {}

    def watch(solver):                         # the first particles past each damage level, every 10 steps
        D = ym.get(solver, "damage")
        for lev in ONSET:
            if lev not in onset and D.max() >= lev:
                x = ym.get(solver, "pos")
                first = prism3d.damage_onset(x, D, fl, lev) if fl else [dict(pos_m=x[i].tolist()) for i in np.nonzero(D >= lev)[0]]
                onset[lev] = dict(time_s=solver.time, axial_stress_MPa=sc["axial_stress"]() / 1e6, axial_strain=sc["axial_strain"](),
                                  particles=len(first), nearest=first[:6])

    r = results.compression_run(s, sc, d, a.end_time, a.progress, name, results.field_snapshots(snaps, dtype=np.float32),
                                dict(period=SNAP_EVERY, at_end=True), dict(period=2 * SNAP_EVERY, at_end=True),
                                [runner.Output(watch, steps=10)])
    wall, t, eps, sig, k, E = r["wall_s"], r["t"], r["eps"], r["sig"], r["peak"], r["E"]
    np.savez_compressed(os.path.join(d, "snapshots.npz"), **snaps)
    entry = dict(variant=variant, symmetry=symmetry, spacing_m=a.spacing, particles=int(s.numParticles), steps=int(s.steps),
                 wall_time_s=wall, end_reason=r["result"].reason, **results.peak_fields(t, eps, sig, k, E), onset={str(k_): v for k_, v in onset.items()},
                 damaged_fraction_end=float(np.mean(ym.get(s, "damage") > 0.99)))
    if fl:
        fl_json = dict(radius_m=fl["radius"], thickness_m=fl["thickness"], angle_deg=float(np.degrees(fl["angle"])),
                       center_m=fl["center"].tolist(), normal=fl["normal"].tolist())
        at_peak = max((q for q in snaps if float(q) <= t[k]), key=float, default=None)
        entry.update(flaw=fl_json, rim_profile_end=rim(mirrored(snaps[max(snaps, key=float)], sc), fl, a.spacing),
                     rim_profile_peak=rim(mirrored(snaps[at_peak], sc), fl, a.spacing) if at_peak else None,
                     peak_snapshot_s=float(at_peak or 0))
    with open(os.path.join(d, "run.json"), "w") as f:
        json.dump(entry, f, indent=1)
    slices_png(d, snaps, sc, a.spacing, name)
    print(f"[{name}] {entry['particles']} particles, peak {entry['peak_stress_MPa']:.2f} MPa at ε = {entry['strain_at_peak']:.4g}, "
          f"E = {entry['youngs_modulus_GPa']:.3f} GPa, {s.steps} steps, {wall:.0f} s", flush=True)
    return entry


def rim(snap, fl, spacing):
    a = snap.astype(float)
    return prism3d.rim_profile(a[:, :3], a[:, 3], fl, spacing)


def mirrored(a, sc):
    """The full prism from a symmetric model's snapshot (reflections across its slip planes)."""
    a = a.astype(float)
    (lo, _), (W, _, D) = sc["modelled"], sc["size"]
    if lo[2] > 0:
        b = a.copy()
        b[:, 2] = D - b[:, 2]
        a = np.vstack([a, b])
    if lo[0] > 0:
        b = a.copy()
        b[:, 0] = W - b[:, 0]
        a = np.vstack([a, b])
    return a


def slices_png(d, snaps, sc, spacing, name):
    """Damage in three slices at the last 3 snapshots: the flaw plane (particles within one cell of the
    disc's mid-plane, in its in-plane coordinates: up-dip, z), z = D/2 (x–y) and x = W/2 (z–y)."""
    plt = output.pyplot()
    keys = sorted(snaps, key=float)[-3:]
    W, H, D = sc["size"]
    fl = sc["flaw"]
    fig, axs = plt.subplots(len(keys), 3, figsize=(11, 4.2 * len(keys)), squeeze=False)
    for i, key in enumerate(keys):
        a = mirrored(snaps[key].astype(float), sc)
        x, Dm = a[:, :3], a[:, 3]
        panels = []
        if fl:
            rho, phi, h = prism3d.disc_coordinates(x, fl)
            sel = np.abs(h) <= spacing
            r = x[sel] - fl["center"]
            panels.append((r @ fl["dip"], r[:, 2], Dm[sel], "flaw plane (|h| ≤ l): up-dip vs z [mm]"))
        else:
            sel = np.abs(x[:, 1] - H / 2) <= spacing / 2
            panels.append((x[sel, 0] - W / 2, x[sel, 2] - D / 2, Dm[sel], "mid-height y = H/2: x vs z [mm]"))
        sel = np.abs(x[:, 2] - D / 2) <= spacing / 2
        panels.append((x[sel, 0], x[sel, 1], Dm[sel], "mid-plane z = D/2: x vs y [mm]"))
        sel = np.abs(x[:, 0] - W / 2) <= spacing / 2
        panels.append((x[sel, 2], x[sel, 1], Dm[sel], "x = W/2: z vs y [mm]"))
        for ax, (u, v, c, title) in zip(axs[i], panels):
            o = np.argsort(c)
            ax.scatter(u[o] * 1e3, v[o] * 1e3, c=c[o], s=4, cmap="inferno_r", vmin=0, vmax=1)
            ax.set_aspect("equal")
            ax.set_title(f"{title}\nt = {float(key) * 1e3:.2f} ms", fontsize=8)
        if fl:
            th = np.linspace(0, 2 * np.pi, 100)
            axs[i][0].plot(fl["radius"] * np.cos(th) * 1e3, fl["radius"] * np.sin(th) * 1e3, "c-", lw=0.8)
    fig.suptitle(f"{name}: damage D (black = 1)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "slices.png"), dpi=100)
    plt.close(fig)


def summarize(out):
    import glob
    runs = [dict(json.load(open(f)), dir=os.path.dirname(f)) for f in sorted(glob.glob(os.path.join(out, "*", "run.json")))]
    if not runs:
        return None
    plt = output.pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for e in runs:
        c = np.loadtxt(os.path.join(e["dir"], "curve.csv"), delimiter=",", skiprows=1)
        ax.plot(c[:, 1] * 1e3, c[:, 2], lw=1, label=f"{e['variant']} ({e['symmetry']}), peak {e['peak_stress_MPa']:.1f} MPa")
    ax.set_xlabel("axial strain [‰]")
    ax.set_ylabel("axial stress [MPa]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    output.save_figure(fig, os.path.join(out, "curves.png"), dpi=120)
    peaks = {e["variant"]: e["peak_stress_MPa"] for e in runs}
    summary = dict(runs=[{k: v for k, v in e.items() if k != "dir"} for e in runs])
    if "penny" in peaks and "intact" in peaks:
        summary["peak_penny_over_intact"] = peaks["penny"] / peaks["intact"]
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
    return summary


def main(argv=None):
    a = parse(argv)
    os.makedirs(a.out, exist_ok=True)
    if not a.summary_only:
        for variant, symmetry in a.run_list:
            one_run(a, variant, symmetry)
    s = summarize(a.out)
    if s and "peak_penny_over_intact" in s:
        print(f"peak penny / intact = {s['peak_penny_over_intact']:.3f}")


if __name__ == "__main__":
    main(sys.argv[1:])
