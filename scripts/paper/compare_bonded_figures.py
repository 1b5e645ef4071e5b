"""The figures and curve files of compare_bonded.py beside it (yade-mpm beside YADE's bonded-particle model
JCFpm, doc/validation/mpm_vs_bonded.md): stress–strain curves of both methods, the end-of-run cracks of each
uniaxial specimen and the Kirsch stress error against run time."""
import csv

import numpy as np

from yade_mpm import output as out

MPa, GPa = 1e6, 1e9


def write_curve(path, strain, stress):
    """CSV of one stress–strain curve: axial strain, axial stress [MPa] (compression positive)."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["axial_strain", "axial_stress_MPa"])
        w.writerows(zip(np.round(strain, 8), np.round(np.asarray(stress) / MPa, 5)))


def plot_curves(path, results):
    """Stress–strain curves of both methods, one panel per case ({case: {method: run}})."""
    plt = out.pyplot()
    fig, axes = plt.subplots(1, len(results), figsize=(5.5 * len(results), 4.2), squeeze=False)
    for ax, (case, r) in zip(axes[0], results.items()):
        for meth, style in (("mpm", "k-"), ("jcfpm", "r-")):
            if meth in r:
                q = r[meth]
                ax.plot(100 * np.asarray(q["strain"]), np.asarray(q["stress"]) / MPa, style,
                        label=f"{'MPM (DP–GK)' if meth == 'mpm' else 'JCFpm'}: E = {q['youngs_modulus'] / GPa:.2f} GPa, "
                              f"peak {q['peak_stress'] / MPa:.1f} MPa")
        ax.set_xlabel("axial strain [%]")
        ax.set_ylabel("axial stress [MPa]")
        ax.set_title(case.replace("_", " "))
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def plot_cracks(path, mpm, dem, holes, title):
    """End of a uniaxial run side by side: MPM damage, JCFpm broken bonds over its discs; the flaw outlined."""
    plt = out.pyplot()
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle as CircleP, Polygon as PolyP
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(7, 8.5))
    if mpm is not None:
        sc = a1.scatter(mpm["pos"][:, 0] * 1e3, mpm["pos"][:, 1] * 1e3, c=mpm["damage"], s=1.0, cmap="inferno_r",
                        vmin=0, vmax=1, marker="s", linewidths=0)
        fig.colorbar(sc, ax=a1, shrink=0.6, label="damage D")
    a1.set_title(f"MPM: damage D ({mpm['particles'] if mpm else 0} particles)", fontsize=9)
    P = dem["discs"]
    a2.add_collection(PatchCollection([CircleP((x * 1e3, y * 1e3), r * 1e3) for x, y, r in P], facecolor="0.85",
                                      edgecolor="0.6", linewidths=0.2))
    c = dem["cracks"]
    for typ, col, name in ((0, "tab:red", "tensile"), (1, "tab:blue", "shear")):
        m = c[:, 2] == typ
        a2.plot(c[m, 0] * 1e3, c[m, 1] * 1e3, ".", ms=2.0, color=col, label=f"{name} ({int(m.sum())})")
    a2.legend(fontsize=8, loc="upper right")
    a2.set_title(f"JCFpm: broken bonds ({len(P)} spheres)", fontsize=9)
    for ax in (a1, a2):
        for h in holes:
            ax.add_patch(PolyP(h.v * 1e3, closed=True, fill=False, ec="g", lw=0.8))
        ax.set_aspect("equal")
        ax.set_xlim(-2, 52)
        ax.set_ylim(-2, 152)
        ax.set_xlabel("x [mm]")
    a1.set_ylabel("y [mm]")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_kirsch_error_vs_time(path, rows, domain, hole_radius):
    """Max relative L2 error of σxx, σyy against Kirsch over the CPU seconds of each run, both methods (rows of
    compare_bonded's Kirsch part: method, resolution_m, particles, cpu_time_s, l2_rel_error_max, l2_rel_error_near_max)."""
    plt = out.pyplot()
    fig, ax = plt.subplots(figsize=(6.2, 4.4))
    for meth, col, mk, name in (("mpm", "k", "o", "MPM (grid spacing l)"), ("jcfpm", "r", "s", "JCFpm (mean radius r̄)")):
        q = [r for r in rows if r["method"] == meth]
        t = [r["cpu_time_s"] for r in q]
        ax.loglog(t, [100 * r["l2_rel_error_max"] for r in q], "-", color=col, marker=mk, label=f"{name}: r ≥ 2a")
        ax.loglog(t, [100 * r["l2_rel_error_near_max"] for r in q], "--", color=col, marker=mk, mfc="none",
                  label=f"{name}: 2a ≤ r ≤ 5a")
        for r in q:
            ax.annotate(f"{r['resolution_m'] * 1e3:g} mm, {r['particles']}", (r["cpu_time_s"], 100 * r["l2_rel_error_max"]),
                        fontsize=7, textcoords="offset points", xytext=(4, 3))
    ax.set_xlabel("run time [CPU s, one thread]")
    ax.set_ylabel("max relative L2 error of σxx, σyy vs Kirsch [%]")
    ax.set_title(f"circular opening: {domain} m block, a = {hole_radius} m, far field 20/10 MPa", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)
