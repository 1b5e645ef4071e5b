"""The figures of penny_crack.py beside it (the pressurised line crack, paper Sec. 3.2, Figs. 7–9):
the damage field on the particles' initial lattice, the elastic opening and the stress ahead of the tip
against Sneddon, the error against wall time of the convergence runs, the crack extension against Fig. 9."""
import os

import numpy as np

import yade_mpm as ym
import yade_mpm.output as out
from yade_mpm_paper.validation import sneddon
from yade_mpm_paper.validation.line_crack import PAPER_CELL, PAPER_DA


def _save(plt, fig, path):
    """A figure laid out tight, written at 150 dpi and closed."""
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def damage_png(s, geo, path, title, half_width=2.0, half_height=0.6):
    """Damage on the particles' initial lattice (one pixel per particle; the hole is white)."""
    plt = out.pyplot()
    x0, dmg, dp = geo["x0"], ym.get(s, "damage"), geo["dp"]
    ix, iy = np.floor(x0[:, 0] / dp).astype(int), np.floor(x0[:, 1] / dp).astype(int)
    img = np.full((iy.max() + 1, ix.max() + 1), np.nan)
    img[iy, ix] = dmg
    fig, ax = plt.subplots(figsize=(9, 3.2))
    im = ax.imshow(img, origin="lower", extent=(0, dp * img.shape[1], 0, dp * img.shape[0]), cmap="jet",
                   vmin=0, vmax=1, interpolation="nearest")
    fig.colorbar(im, ax=ax, label="damage D")
    ax.set_xlim(geo["xc"] - half_width, geo["xc"] + half_width)
    ax.set_ylim(geo["yc"] - half_height, geo["yc"] + half_height)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    _save(plt, fig, path)


def plot_elastic(e, outdir, P, half_crack, rock):
    """elastic_profiles.png: the opening u_y along the crack against Sneddon (Eq. 43) and σ ahead of the tip
    against Eq. 44 (e: the elastic run's profiles; P [Pa], crack half-length c [m], rock: its young, poisson)."""
    plt = out.pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    xf = np.linspace(-half_crack, half_crack, 201)
    ax[0].plot(xf, 1e3 * sneddon.opening_displacement(xf, P, rock["young"], rock["poisson"], half_crack), "k-",
               label="Sneddon (Eq. 43)")
    ax[0].plot(e["x"], 1e3 * e["uy"], "s", mfc="none", ms=4, label=f"MPM, l = {e['h']} m")
    ax[0].set_xlabel("x − x_c [m]")
    ax[0].set_ylabel("u_y [mm]")
    ax[0].legend()
    xs = np.linspace(half_crack * 1.0005, half_crack + 1.0, 400)
    ax[1].plot(xs, sneddon.stress_ahead(xs, P, half_crack) / 1e6, "k-", label="Eq. 44")
    ax[1].plot(e["xs"], e["syy"] / 1e6, "s", mfc="none", ms=4, label="MPM σ_yy")
    ax[1].plot(e["xs"], e["sxx"] / 1e6, "o", mfc="none", ms=3, label="MPM σ_xx")
    ax[1].set_xlim(half_crack, half_crack + 1.0)
    ax[1].set_ylim(-5, 45)
    ax[1].set_xlabel("|x − x_c| [m]")
    ax[1].set_ylabel("σ [MPa]")
    ax[1].legend()
    _save(plt, fig, os.path.join(outdir, "elastic_profiles.png"))


def plot_convergence(conv, outdir):
    """error_vs_walltime.png: the opening's errors of the convergence runs against their wall time."""
    plt = out.pyplot()
    fig, ax = plt.subplots(figsize=(5.5, 4))
    w = [c["wall"] for c in conv]
    ax.loglog(w, [abs(c["uy_centre_err"]) for c in conv], "o-", label="|u_y centre error|")
    ax.loglog(w, [c["uy_l2"] for c in conv], "s-", label="u_y rel. L2 error")
    for c in conv:
        ax.annotate(f"l={c['h']}", (c["wall"], c["uy_l2"]), fontsize=8)
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("relative error")
    ax.legend()
    _save(plt, fig, os.path.join(outdir, "error_vs_walltime.png"))


def plot_da(results, outdir):
    """crack_extension.png: mean Δa of the two tips [cells of 0.02 m] of each growth law against the paper's Fig. 9."""
    plt = out.pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    for r in results:
        t = [row[0] for row in r["rows"]]
        cells = PAPER_CELL / r["h"]
        ax.plot(t, [0.5 * (row[2] + row[3]) / cells for row in r["rows"]], "-",
                label=f"MPM, growth law {r['law']} ({'ε̄^(m/3)' if r['law'] == 'benz-asphaug' else 'ε̄^(1/3), as printed'})")
    ax.plot([p[0] for p in PAPER_DA], [p[1] for p in PAPER_DA], "ks", label="paper Fig. 9")
    ax.set_xlabel("t (paper time scale) [s]")
    ax.set_ylabel("Δa [cells of 0.02 m]")
    ax.legend()
    _save(plt, fig, os.path.join(outdir, "crack_extension.png"))

