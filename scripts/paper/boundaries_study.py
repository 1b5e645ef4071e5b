"""Exact boundaries (doc/reference/boundaries.md, issue 8): the numbers and figures of the boundary study.

  slip     uniform σ on one plane, each side, 2D and 3D: 'slip' (reflected images) vs 'slip-onesided'
  bar      fixed–free bar period vs 4L/c at L/l = 20, 40, 80 ('fixed' = one-sided WLS on a node line)
  kirsch   circular opening (cases.circular_opening): quarter model with two symmetry planes vs the full
           model at the same grid and the same number of steps: L2 errors along θ = 0°, 90° and wall time
  cost     step time of the tunnel-like scene (arch opening, l = 1 mm): no planes, 4 'slip', 4 'slip-onesided'
  crack    plot of the line-crack centre-opening convergence from scripts/paper/penny_crack.py outputs
           (--crack-dirs out/crack_c0.2,out/crack_c0.3 made with --parts convergence --half-length c)

    PYTHONPATH=py /usr/bin/python3 scripts/paper/boundaries_study.py --out doc/figures --parts slip,bar,kirsch
"""
import argparse
import json
import os
import sys
import time

import numpy as np

import yade_mpm as ym
import yade_mpm.output as out
from yade_mpm_paper import cases
from yade_mpm_paper.validation import kirsch


def uniform_block(dim, axis, side, kind, h=0.1, sigma=-40e6, steps=300):
    """Max relative error of σ_nn, max spurious component / |σ| and row means after `steps` damped steps of
    cases.uniform_stress_block."""
    s = cases.uniform_stress_block(dim, axis, side, kind, spacing=h, sigma=sigma)
    t0 = time.time()
    s.run(steps)
    wall = time.time() - t0
    sg, x = ym.get(s, "stress"), ym.get(s, "pos")
    others = [k for k in range(sg.shape[1]) if k != axis and not (dim == 2 and k == 2)]
    rows = np.round(x[:, axis] / (h / 2) - 0.5).astype(int)
    row_mean = np.array([sg[rows == r, axis].mean() / sigma for r in np.unique(rows)])
    return dict(dim=dim, axis=axis, side=side, kind=kind, max_err=float(np.abs(sg[:, axis] / sigma - 1).max()),
                max_spurious=float(np.abs(sg[:, others] / sigma).max()), row_mean=row_mean.tolist(), wall=wall)


def part_slip(a):
    res = []
    for dim in (2, 3):
        for kind in ("slip", "slip-onesided"):
            for axis in range(dim):
                for side in (-1, 1):
                    r = uniform_block(dim, axis, side, kind, steps=300 if dim == 2 else 100)
                    res.append(r)
                    print(f"slip {dim}D {kind:14s} axis {axis} side {side:+d}: max |Δσn/σ| {r['max_err']:.2e}, "
                          f"spurious {r['max_spurious']:.2e}", flush=True)
    out.write_csv(os.path.join(a.out, "boundaries_slip.csv"), ["dim", "kind", "axis", "side", "max_rel_err_sn", "max_spurious_rel"],
                  [(r["dim"], r["kind"], r["axis"], r["side"], r["max_err"], r["max_spurious"]) for r in res])
    plt = out.pyplot()
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for kind, mk in (("slip", "o"), ("slip-onesided", "s")):
        r = next(r for r in res if r["dim"] == 2 and r["kind"] == kind and r["axis"] == 1 and r["side"] == -1)
        ax.plot(100 * (np.array(r["row_mean"]) - 1), np.arange(len(r["row_mean"])) + 0.5, mk + "-", label=kind)
    ax.axvline(0, color="k", lw=0.5)
    ax.set_xlabel("row-mean σyy error [%] (σ = −40 MPa)")
    ax.set_ylabel("particle row above the plane")
    ax.set_title("Block on a bottom slip plane, 2D")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "boundaries_slip_rows.png"), dpi=120)
    plt.close(fig)
    return dict(slip=[{k: r[k] for k in ("dim", "kind", "axis", "side", "max_err", "max_spurious")} for r in res])


def fixed_free_period(cells_x):
    s, T, shape = cases.fixed_free_bar(cells_x)
    return cases.mode_period(s, shape, 2.3 * T) / T - 1


def part_bar(a):
    ratios = [20, 40, 80]
    err = [fixed_free_period(n) for n in ratios]
    for n, e in zip(ratios, err):
        print(f"fixed–free bar L/l = {n}: period error {100 * e:+.3f} %", flush=True)
    before = [0.017, 0.0097, 0.0050]                      # issue 8: nodes at and beyond the plane fixed
    out.write_csv(os.path.join(a.out, "boundaries_bar.csv"), ["L_over_l", "period_rel_err", "before_issue8"], zip(ratios, err, before))
    plt = out.pyplot()
    fig, ax = plt.subplots(figsize=(5, 3.8))
    ax.loglog(ratios, [100 * abs(e) for e in err], "o-", label="one-sided WLS, plane on a node line")
    ax.loglog(ratios, [100 * e for e in before], "s--", label="before (nodes at/beyond fixed)")
    ax.loglog(ratios, [100 * abs(err[0]) * (20 / n) ** 2 for n in ratios], "k:", label="slope 2")
    ax.axhline(0.3, color="r", lw=0.7, label="bar 0.3 %")
    ax.set_xlabel("L / l")
    ax.set_ylabel("|period / (4L/c) − 1| [%]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "boundaries_bar.png"), dpi=120)
    plt.close(fig)
    return dict(bar=dict(L_over_l=ratios, period_rel_err=err))


def kirsch_errors(s, spacing):
    """Relative L2 errors of (σxx, σyy) on the particle rows next to θ = 0° (y = 2.5 m) and θ = 90°
    (x = 2.5 m) in the quadrant x, y > 2.5 m with r ≥ 2a, against Kirsch at each particle."""
    C, R = cases.OPENING_CENTER, cases.OPENING_RADIUS
    p, sg = ym.get(s, "pos"), ym.get(s, "stress")
    kxx, kyy, _ = kirsch.cartesian(p[:, 0], p[:, 1], (C, C), R, cases.OPENING_SXX, cases.OPENING_SYY)
    res = {}
    for name, along, across in (("theta0", 0, 1), ("theta90", 1, 0)):
        m = (np.abs(p[:, across] - C - spacing / 4) < 1e-6) & (p[:, along] - C >= 2 * R)
        sim, ref = -sg[m][:, :2], np.column_stack([kxx[m], kyy[m]])
        res[name] = float(np.sqrt(np.sum((sim - ref) ** 2) / np.sum(ref ** 2)))
    return res


def part_kirsch(a):
    res = {}
    for model in ("full", "quarter"):
        s, lo, hi = cases.circular_opening(a.kirsch_spacing, quarter=(model == "quarter"))
        n = s.numParticles
        t0 = time.time()
        s.run(a.kirsch_steps)
        wall = time.time() - t0
        e = kirsch_errors(s, a.kirsch_spacing)
        res[model] = dict(particles=n, wall_s=wall, **e)
        print(f"kirsch {model}: {n} particles, {a.kirsch_steps} steps, wall {wall:.1f} s, L2 θ=0° {e['theta0']:.4f}, θ=90° {e['theta90']:.4f}", flush=True)
    res["wall_ratio"] = res["quarter"]["wall_s"] / res["full"]["wall_s"]
    out.write_csv(os.path.join(a.out, "boundaries_kirsch.csv"), ["model", "particles", "wall_s", "l2_theta0", "l2_theta90"],
                  [(m, res[m]["particles"], res[m]["wall_s"], res[m]["theta0"], res[m]["theta90"]) for m in ("full", "quarter")])
    return dict(kirsch=dict(spacing=a.kirsch_spacing, steps=a.kirsch_steps, **res))


def part_crack(a):
    rows = []
    for d in a.crack_dirs.split(","):
        with open(os.path.join(d, "summary.json")) as f:
            sm = json.load(f)
        c = sm["config"]["half_length_m"]
        for r in sm["convergence"]:
            rows.append((c, r["spacing_m"], r["uy_center_rel_error"], r["uy_l2_rel_error"], r["wall_time_s"]))
    out.write_csv(os.path.join(a.out, "boundaries_crack.csv"), ["half_length_m", "spacing_m", "uy_center_rel_error", "uy_l2_rel_error", "wall_s"], rows)
    plt = out.pyplot()
    fig, ax = plt.subplots(figsize=(5, 3.8))
    before = {0.2: [(0.04, 0.006), (0.02, -0.146)], 0.3: [(0.04, -0.067), (0.02, -0.246)]}   # issue 8, shared nodes
    for c, mk in ((0.2, "o"), (0.3, "s")):
        rr = sorted((r for r in rows if abs(r[0] - c) < 1e-9), key=lambda r: -r[1])
        ax.plot([r[1] for r in rr], [100 * r[2] for r in rr], mk + "-", label=f"gap nodes excluded, c = {c} m")
        ax.plot([b[0] for b in before[c]], [100 * b[1] for b in before[c]], mk + "--", mfc="none", label=f"shared (paper), c = {c} m")
    ax.axhspan(-5, 5, color="g", alpha=0.1)
    ax.axhline(0, color="k", lw=0.5)
    ax.invert_xaxis()
    ax.set_xlabel("grid spacing l [m]")
    ax.set_ylabel("centre opening error vs Sneddon [%]")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "boundaries_crack.png"), dpi=120)
    plt.close(fig)
    return dict(crack=[dict(half_length_m=r[0], spacing_m=r[1], uy_center_rel_error=r[2], uy_l2_rel_error=r[3]) for r in rows])


def tunnel_like(kind, spacing):
    """The tunnel specimen's geometry (150 mm square, arch opening) at in-situ stress, with 4 planes of
    `kind` on its sides (None: no planes)."""
    W = cases.TUNNEL_WIDTH
    s = ym.make_solver((0, 0), (W, W), spacing, margin=2)
    ym.add_region(s, ym.ElasticMat(**ym.rocks.GRANITE), (0, 0), (W, W), holes=cases.arch_tunnel_holes())
    ym.set_initial_stress(s, (-10e6, -20e6, -0.2313 * 30e6, 0))
    if kind:
        for axis, side, pos in ((0, -1, 0.0), (0, 1, W), (1, -1, 0.0), (1, 1, W)):
            s.addBoundaryPlane(axis, side, pos, kind)
    s.damping = 0.1
    return s


def part_cost(a):
    """Step time of the tunnel-like scene without planes, with 4 'slip' planes (images) and with 4
    'slip-onesided' planes, interleaved repeats in one process (ratios only)."""
    kinds = (None, "slip", "slip-onesided")
    solvers = {k: tunnel_like(k, a.cost_spacing) for k in kinds}
    for s in solvers.values():
        s.run(20)                                          # warm-up (first sort, page faults)
    times = {k: [] for k in kinds}
    for _ in range(a.cost_repeats):
        for k in kinds:
            t0 = time.perf_counter()
            solvers[k].run(a.cost_steps)
            times[k].append((time.perf_counter() - t0) / a.cost_steps)
    best = {str(k): min(v) for k, v in times.items()}
    res = dict(particles=solvers[None].numParticles, spacing=a.cost_spacing, step_s=best,
               ratio_slip=best["slip"] / best["None"], ratio_onesided=best["slip-onesided"] / best["None"])
    print(f"cost (tunnel-like, {res['particles']} particles, l = {a.cost_spacing} m, best of {a.cost_repeats}×{a.cost_steps} steps): "
          f"no planes {1e3 * best['None']:.2f} ms/step, 4 slip {res['ratio_slip']:.3f}×, 4 slip-onesided {res['ratio_onesided']:.3f}×", flush=True)
    return dict(cost=res)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="output directory (CSV, PNG, summary.json)")
    ap.add_argument("--parts", default="slip,bar,kirsch", help="comma list of slip, bar, kirsch, crack")
    ap.add_argument("--kirsch-spacing", type=float, default=0.04, help="grid spacing of the Kirsch comparison [m]")
    ap.add_argument("--kirsch-steps", type=int, default=3000, help="steps of each Kirsch model (the same for both)")
    ap.add_argument("--crack-dirs", default="out/crack_c0.2,out/crack_c0.3", help="penny_crack.py output directories (crack part)")
    ap.add_argument("--cost-spacing", type=float, default=0.001, help="grid spacing of the cost scene [m] (tunnel: 0.001)")
    ap.add_argument("--cost-steps", type=int, default=50, help="steps per timed repeat of the cost part")
    ap.add_argument("--cost-repeats", type=int, default=5, help="interleaved repeats of the cost part")
    ap.add_argument("--threads", type=int, default=1, help="OpenMP threads")
    a = ap.parse_args(argv)
    parts = set(a.parts.split(","))
    if not parts <= {"slip", "bar", "kirsch", "crack", "cost"}:
        ap.error(f"--parts: unknown part in {a.parts}; allowed slip, bar, kirsch, crack, cost")
    if not (a.cost_spacing > 0 and a.cost_steps >= 1 and a.cost_repeats >= 1):
        ap.error("--cost-spacing must be > 0 m, --cost-steps and --cost-repeats ≥ 1")
    if not (0 < a.kirsch_spacing <= cases.OPENING_RADIUS):
        ap.error(f"--kirsch-spacing must lie in (0, {cases.OPENING_RADIUS}] m")
    if a.kirsch_steps < 1:
        ap.error("--kirsch-steps must be ≥ 1")
    ym.setThreads(a.threads)
    os.makedirs(a.out, exist_ok=True)
    path = os.path.join(a.out, "boundaries_summary.json")
    summary = {}
    if os.path.exists(path):                      # parts run separately accumulate in one summary
        with open(path) as f:
            summary = json.load(f)
    for name, fn in (("slip", part_slip), ("bar", part_bar), ("kirsch", part_kirsch), ("crack", part_crack), ("cost", part_cost)):
        if name in parts:
            summary.update(fn(a))
    with open(path, "w") as f:
        json.dump(summary, f, indent=1)
    return summary


if __name__ == "__main__":
    main(sys.argv[1:])
