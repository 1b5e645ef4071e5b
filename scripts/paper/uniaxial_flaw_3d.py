"""The uniaxial flaw specimen (paper Sec. 3.3) as a 3D slab against the 2D plane-strain run (issue 22,
item 4; doc/validation/three_d.md): the scene of ``yade_mpm_paper.cases.uniaxial_flaw`` with slab_cells = n (z ∈ [0, n·l],
slip planes on the front and back faces) and with slab_cells = 0 (2D), the same grid, rock, flaw and
platen, both stopped after the peak as scripts/paper/uniaxial_flaw.py stops. Writes OUT/2d/ and OUT/3d/
(curve.csv: time, axial strain, axial stress; run.json; particles.pvd + .vtu series; snapshots.npz),
OUT/compare.json (``cases.slab_compare.compare``: moduli, peaks, pre-peak deviation, the slab's spread
across z), OUT/curves.png and OUT/damage.png (2D against the slab's mid-plane).

    PYTHONPATH=py OMP_NUM_THREADS=1 /usr/bin/python3 scripts/paper/uniaxial_flaw_3d.py [--out DIR] [--spacing L]
        [--slab-cells N] [--variant open|intact] [--only 2d|3d] [--end-time T]
"""
import argparse
import json
import os
import sys

import numpy as np

import yade_mpm as ym
from yade_mpm import output, rocks
from yade_mpm_paper import cases
from yade_mpm_paper.cases import slab_compare, uniaxial_results as results

DEFAULT_SPACING = 2.0e-3      # the 2D study's default grid [m] (scripts/paper/uniaxial_flaw.py)
END_TIME = 0.014              # loading time cap [s] (scripts/paper/uniaxial_flaw.py); runs stop once softened
SNAP_EVERY = 1e-3             # field snapshots (and VTU) every this [s]


def parse(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default="out/uniaxial_flaw_3d", help="output folder (default %(default)s)")
    p.add_argument("--spacing", type=float, default=DEFAULT_SPACING, help="grid spacing [m] (default %(default)s)")
    p.add_argument("--slab-cells", type=int, default=cases.UNIAXIAL_SLAB_CELLS, help="slab thickness [cells] (default %(default)s)")
    p.add_argument("--variant", default="open", choices=("open", "intact"), help="flaw (default %(default)s)")
    p.add_argument("--threshold-volume", default=None, choices=("particle", "cube", "cell"),
                   help="V of Eq. 37 for both runs (default: the rock's, 'particle': 2D area × 1 m against 3D dp³, doc/validation/three_d.md)")
    p.add_argument("--only", choices=("2d", "3d"), default=None, help="run one of the two (the other is read from OUT)")
    p.add_argument("--end-time", type=float, default=END_TIME, help="loading time cap [s] (default %(default)s)")
    p.add_argument("--progress", type=float, default=60.0, help="wall seconds between progress lines")
    ym.scene.courant_option(p)
    a = p.parse_args(argv)
    if not (a.spacing > 0 and a.end_time > 0 and a.slab_cells >= 1):
        p.error("--spacing and --end-time must be > 0, --slab-cells ≥ 1")
    try:
        a.courant = ym.scene.check_courant(a.courant)
    except ValueError as e:
        p.error(str(e))
    return a


def one_run(a, slab_cells):
    tag = "3d" if slab_cells else "2d"
    d = os.path.join(a.out, tag)
    os.makedirs(d, exist_ok=True)
    rock = rocks.miao2018_sandstone(**({"thresholdVolume": a.threshold_volume} if a.threshold_volume else {}))
    s, sc = cases.uniaxial_flaw(a.variant, a.spacing, slab_cells=slab_cells, label=f"mpm_{tag}", material=rock)
    s.courant = a.courant
    snaps = {}
    r = results.compression_run(s, sc, d, a.end_time, a.progress, tag, results.field_snapshots(snaps, dtype=np.float32),
                                dict(period=SNAP_EVERY, at_end=True), dict(period=SNAP_EVERY, at_end=True))
    wall, t, eps, sig, k, E = r["wall_s"], r["t"], r["eps"], r["sig"], r["peak"], r["E"]
    np.savez_compressed(os.path.join(d, "snapshots.npz"), **snaps)
    entry = dict(dim=3 if slab_cells else 2, slab_cells=slab_cells, variant=a.variant, threshold_volume=str(rock.thresholdVolume),
                 eps0_median=float(np.median(s.view("eps0"))), spacing_m=a.spacing, courant=a.courant,
                 particles=int(s.numParticles), steps=int(s.steps), wall_time_s=wall, end_reason=r["result"].reason,
                 particle_steps_per_s=s.numParticles * s.steps / wall, **results.peak_fields(t, eps, sig, k, E),
                 thickness_m=sc["thickness"], damaged_fraction_end=float(np.mean(ym.get(s, "damage") > 0.99)))
    with open(os.path.join(d, "run.json"), "w") as f:
        json.dump(entry, f, indent=1)
    print(f"[{tag}] {entry['particles']} particles, peak {entry['peak_stress_MPa']:.2f} MPa at ε = {entry['strain_at_peak']:.4g}, "
          f"E = {entry['youngs_modulus_GPa']:.3f} GPa, {s.steps} steps, {wall:.0f} s", flush=True)
    return entry


def load(out, tag):
    d = os.path.join(out, tag)
    c = np.loadtxt(os.path.join(d, "curve.csv"), delimiter=",", skiprows=1)
    return json.load(open(os.path.join(d, "run.json"))), c[:, 1], c[:, 2] * 1e6, np.load(os.path.join(d, "snapshots.npz"))


def z_spread(snap, slab_cells, spacing):
    """Largest difference of D and of ε̄p between the slab's particles of one (x, y) column (the slab stays
    plane when these stay near 0): max over columns of (max − min) across z."""
    key = max(snap.files, key=float)
    a = snap[key].astype(float)
    nz = 2 * slab_cells                                   # ppc = 2
    n = len(a) // nz                                      # particle ids: z fastest (fill_region), ids kept by fields()
    D, ep = a[:n * nz, 3].reshape(n, nz), a[:n * nz, 4].reshape(n, nz)
    return dict(time_s=float(key), damage=float(np.max(D.max(1) - D.min(1))), plastic_strain=float(np.max(ep.max(1) - ep.min(1))))


def figures(out, r2, r3, cmp):
    plt = output.pyplot()
    H = cases.UNIAXIAL_HEIGHT
    fig, ax = plt.subplots(1, 2, figsize=(10, 4.2))
    for (e, c), st, lab in ((r2[1:3], "k-", "2D plane strain"), (r3[1:3], "r--", f"3D slab, {r3[0]['slab_cells']} cells")):
        b, m = slab_compare.smooth(e, c, H)
        ax[0].plot(b * 1e3, m / 1e6, st, lw=1.3, label=lab)
    ax[0].set_xlabel("axial strain [‰]")
    ax[0].set_ylabel("axial stress [MPa]")
    ax[0].legend()
    ax[0].grid(alpha=0.3)
    b2, m2 = slab_compare.smooth(*r2[1:3], H)
    b3, m3 = slab_compare.smooth(*r3[1:3], H)
    sel = (b2 >= b3.min()) & (b2 <= b3.max())
    ax[1].plot(b2[sel] * 1e3, (np.interp(b2[sel], b3, m3) - m2[sel]) / cmp["peak_2d"] * 100, "b-")
    ax[1].axvline(cmp["strain_at_peak_2d"] * 1e3, color="k", lw=0.8, ls=":")
    ax[1].set_xlabel("axial strain [‰]")
    ax[1].set_ylabel("(σ_3D − σ_2D) / σ_peak,2D [%]")
    ax[1].grid(alpha=0.3)
    fig.suptitle(f"uniaxial {r2[0]['variant']} flaw, l = {r2[0]['spacing_m'] * 1e3:g} mm: E 2D {cmp['E_2d'] / 1e9:.3f}, "
                 f"3D {cmp['E_3d'] / 1e9:.3f} GPa; peak 2D {cmp['peak_2d'] / 1e6:.1f}, 3D {cmp['peak_3d'] / 1e6:.1f} MPa", fontsize=9)
    output.save_figure(fig, os.path.join(out, "curves.png"), dpi=120)
    t3 = np.array(sorted(map(float, r3[3].files)))
    k3 = {float(k): k for k in r3[3].files}
    keys = [(k, k3[t3[np.argmin(np.abs(t3 - float(k)))]]) for k in sorted(r2[3].files, key=float) if float(k) <= t3.max() * 1.001][-3:]
    if not keys:
        return
    fig, axs = plt.subplots(1, 2 * len(keys), figsize=(2.4 * 2 * len(keys), 6.5), sharey=True)
    zmid = r3[0]["thickness_m"] / 2
    for j, (key, key3) in enumerate(keys):
        a2, a3 = r2[3][key], r3[3][key3]
        a3 = a3[np.abs(a3[:, 2] - zmid) < r3[0]["spacing_m"] / 2]     # the two particle layers next to the mid-plane
        for ax, a, lab, col in ((axs[2 * j], a2, "2D", 2), (axs[2 * j + 1], a3, "3D mid", 3)):
            ax.scatter(a[:, 0] * 1e3, a[:, 1] * 1e3, c=a[:, col], s=1.2, cmap="inferno_r", vmin=0, vmax=1)
            ax.set_aspect("equal")
            ax.set_title(f"{lab} D, t = {float(key) * 1e3:.1f} ms", fontsize=8)
            ax.set_xlabel("x [mm]")
    axs[0].set_ylabel("y [mm]")
    output.save_figure(fig, os.path.join(out, "damage.png"), dpi=110)


def main(argv=None):
    a = parse(argv)
    os.makedirs(a.out, exist_ok=True)
    if a.only in (None, "2d"):
        one_run(a, 0)
    if a.only in (None, "3d"):
        one_run(a, a.slab_cells)
    if not all(os.path.exists(os.path.join(a.out, t, "run.json")) for t in ("2d", "3d")):
        return None
    r2, r3 = load(a.out, "2d"), load(a.out, "3d")
    cmp = slab_compare.compare(r2[1:3], r3[1:3], cases.UNIAXIAL_HEIGHT)
    cmp["z_spread_end"] = z_spread(r3[3], r3[0]["slab_cells"], r3[0]["spacing_m"])
    cmp["runs"] = {"2d": r2[0], "3d": r3[0]}
    with open(os.path.join(a.out, "compare.json"), "w") as f:
        json.dump(cmp, f, indent=1)
    figures(a.out, r2, r3, cmp)
    print(json.dumps({k: v for k, v in cmp.items() if k != "runs"}, indent=1))
    return cmp


if __name__ == "__main__":
    main(sys.argv[1:])
