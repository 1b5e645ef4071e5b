"""Hybrid DEM–MPM rockfall: DEM boulders (YADE spheres and clumps of spheres) dropped on an MPM rock slab
(plane strain, Drucker–Prager + Grady–Kipp damage sandstone of paper Sec. 3.3), two-way through the PTS
contact of yade_mpm.DemSpheres; YADE's collider and interaction loop handle boulder–boulder contacts in
the same O.engines.

Scene: slab L × H (default 1.0 × 0.2 m) on a frictionless floor (a slip boundary plane: it takes vertical
impulse only, so the horizontal impulse balance of the coupling can be checked exactly), free ends,
gravity. Boulders (granite-like, rocks.GRANITE density and modulus as YADE FrictMat): a sphere resting on
the slab, two spheres and two three-sphere clumps thrown at it at --speed [m/s] downwards and 3 m/s
sideways, one of them aimed at the resting sphere (boulder–boulder contact). Time step: O.dt starts at
0.5 × PWaveTimeStep() of the boulders and MpmEngine lowers it to the MPM stable step when that is smaller
(the smaller wins, every step).

Impulse balance: per step, the contact reaction of every boulder (per metre of thickness) × Δt is summed
(J_s); the MPM particles' horizontal momentum change (from their velocities, per metre) must equal
−Σ_s J_s,x. Reported: |ΔP_x + Σ J_s,x| / Σ_s |J_s|.

Outputs in --out: summary.json {spheres, mpm_particles, impulse_balance_rel_error, wall_time_s, ...},
impulse.csv, final.png, VTU series particles.pvd (MPM, ours) and spheres.pvd (YADE's VTKRecorder files)
for ParaView.

    PYTHONPATH=py /usr/bin/python3 examples/hybrid_rockfall.py --out out/hybrid_rockfall
    PYTHONPATH=py yade -n -x examples/hybrid_rockfall.py --out out/hybrid_rockfall --end-time 0.01
"""
import argparse
import glob
import math
import os
import time

import numpy as np

import yade_mpm as ym
from yade_mpm import output as out
from yade_mpm import rocks


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--spacing", type=float, default=0.01, help="MPM grid spacing l [m]")
    p.add_argument("--length", type=float, default=1.0, help="slab length L [m]")
    p.add_argument("--height", type=float, default=0.2, help="slab thickness H [m]")
    p.add_argument("--speed", type=float, default=10.0, help="downward speed of the thrown boulders [m/s]")
    p.add_argument("--end-time", type=float, default=0.03, help="simulated time [s]")
    p.add_argument("--vtu-every", type=float, default=1e-3, help="simulated seconds between VTU frames (0 = none)")
    p.add_argument("--threads", type=int, default=0, help="OpenMP threads (0 = all cores)")
    p.add_argument("--progress", type=float, default=10.0, help="wall seconds between progress lines")
    a = p.parse_args(argv)
    for n in ("spacing", "length", "height", "speed", "end_time", "progress"):
        v = getattr(a, n)
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"--{n.replace('_', '-')} = {v} must be > 0")
    if not (a.length >= 0.6 and a.height >= 4 * a.spacing and a.length >= 10 * a.spacing):
        raise ValueError(f"--length = {a.length} m must be ≥ 0.6 m (room for the boulders) and the slab ≥ 10 × 4 cells "
                         f"(--height = {a.height} m, --spacing = {a.spacing} m)")
    if not (math.isfinite(a.vtu_every) and a.vtu_every >= 0):
        raise ValueError(f"--vtu-every = {a.vtu_every} s must be ≥ 0")
    if a.threads < 0:
        raise ValueError(f"--threads = {a.threads} must be ≥ 0 (0 = all cores)")
    return a


def build(a):
    """MPM slab + boulders in O; returns (solver, DemSpheres, boulder ids)."""
    from yade import O, utils
    from yade.wrapper import FrictMat
    O.reset()
    L, H, l = a.length, a.height, a.spacing
    s = ym.make_solver((-0.3, 0.0), (L + 0.3, H + 0.3), l)   # room around the slab for ejected fragments
    ym.add_region(s, rocks.miao2018_sandstone(), (0.0, 0.0), (L, H), ppc=2)
    s.addBoundaryPlane(1, -1, 0.0, "slip")
    s.gravity = (0.0, -9.81)
    g = rocks.GRANITE
    mat = O.materials.append(FrictMat(young=g["young"], poisson=g["poisson"], density=g["density"],
                                      frictionAngle=math.radians(30.0)))
    ids = []

    def sphere(x, y, r):
        b = utils.sphere((x, y, 0.0), r, material=mat)
        b.state.blockedDOFs = "zXY"
        return b

    def throw(bid, vx, vy):
        O.bodies[bid].state.vel = (vx, vy, 0.0)

    r = 0.04
    ids.append(O.bodies.append(sphere(0.6 * L, H + r, r)))                       # resting on the slab
    ids.append(O.bodies.append(sphere(0.15 * L, H + r + 0.02, r)))               # thrown
    throw(ids[-1], 3.0, -a.speed)
    ids.append(O.bodies.append(sphere(0.6 * L - 0.12, H + 3 * r + 0.09, 0.05)))  # aimed at the resting one
    throw(ids[-1], 3.0, -a.speed)
    for x0, h in ((0.35 * L, 0.06), (0.8 * L, 0.12)):                            # three-sphere clumps
        cid, _ = O.bodies.appendClumped([sphere(x0 - 0.03, H + 0.03 + h, 0.03), sphere(x0 + 0.03, H + 0.03 + h, 0.03),
                                         sphere(x0, H + 0.08 + h, 0.035)])
        O.bodies[cid].state.blockedDOFs = "zXY"
        throw(cid, 3.0, -a.speed)
        ids.append(cid)
    sp = ym.DemSpheres(s)
    sp.add(ids, mu=0.5)
    return s, sp, ids


def engines(s, bodies):
    from yade.wrapper import (ForceResetter, InsertionSortCollider, Bo1_Sphere_Aabb, InteractionLoop, Ig2_Sphere_Sphere_ScGeom,
                              Ip2_FrictMat_FrictMat_FrictPhys, Law2_ScGeom_FrictPhys_CundallStrack, NewtonIntegrator)
    return [ForceResetter(),
            InsertionSortCollider([Bo1_Sphere_Aabb()]),
            InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                            [Law2_ScGeom_FrictPhys_CundallStrack()]),                 # boulder–boulder: YADE's own
            ym.MpmEngine(s, label="mpmRockfall", bodies=bodies).runner(),            # boulder–MPM: PTS, both ways
            NewtonIntegrator(gravity=(0.0, -9.81, 0.0), damping=0.0)]


def plot_final(path, s, ids):
    from yade import O
    plt = out.pyplot()
    from matplotlib.patches import Circle
    pos, dmg = ym.get(s, "pos"), ym.get(s, "damage")
    fig, ax = plt.subplots(figsize=(10, 3.2))
    sc = ax.scatter(pos[:, 0], pos[:, 1], c=dmg, s=2, cmap="inferno_r", vmin=0, vmax=1, marker="s", linewidths=0)
    fig.colorbar(sc, ax=ax, label="damage D", shrink=0.8)
    for bid in ids:
        b = O.bodies[bid]
        members = b.shape.members if type(b.shape).__name__ == "Clump" else [bid]
        for m in members:
            mb = O.bodies[m]
            ax.add_patch(Circle((mb.state.pos[0], mb.state.pos[1]), mb.shape.radius, fc="0.6", ec="k", lw=0.6))
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"t = {O.time * 1e3:.1f} ms: DEM boulders (grey) and the MPM slab's damage", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv=None):
    a = parse_args(argv)
    from yade import O, utils
    from yade.wrapper import VTKRecorder
    if a.threads:
        ym.setThreads(a.threads)
    os.makedirs(a.out, exist_ok=True)
    s, bodies, ids = build(a)
    O.engines = engines(s, bodies)
    O.dt = 0.5 * utils.PWaveTimeStep()                       # DEM step; the MPM engine lowers it when needed
    dt_dem = O.dt
    P0 = ym.get(s, "momentum").sum(axis=0)                  # exact total momentum of the particles
    J = np.zeros((len(ids), 2))                              # contact impulse on each boulder [N s per metre]
    hist = []
    series = out.VtuSeries(a.out, "particles")
    for f in glob.glob(os.path.join(a.out, "spheres-spheres.*.vtu")):
        os.remove(f)
    rec = VTKRecorder(fileName=os.path.join(a.out, "spheres-"), recorders=["spheres", "velocity", "ids", "clumpId"])
    sphere_frames = []

    def frame():
        series.write(s)
        rec()
        sphere_frames.append((O.time, os.path.join(a.out, f"spheres-spheres.{O.iter}.vtu")))
        out.write_pvd(os.path.join(a.out, "spheres.pvd"), sphere_frames)
    prog = ym.progress.Progress(a.end_time, "rockfall", a.progress)
    t_next, dem_contacts = 0.0, 0
    t0 = time.time()
    while O.time < a.end_time:
        if a.vtu_every and O.time >= t_next:
            frame()
            t_next += a.vtu_every
        O.step()
        f = [bodies.force(b) for b in bodies.ids]                                # reaction on each boulder [N/m]
        J += np.asarray(f) * s.lastDt
        if O.iter % 50 == 0:
            dem_contacts = max(dem_contacts, sum(1 for i in O.interactions if i.isReal))
            hist.append((O.time, *J.sum(axis=0), *ym.get(s, "momentum").sum(axis=0) - P0))
        prog.update(O.iter, O.time)
    wall = time.time() - t0
    if a.vtu_every:
        frame()
    dP = ym.get(s, "momentum").sum(axis=0) - P0
    scale = float(np.sum(np.linalg.norm(J, axis=1)))
    err = abs(dP[0] + J[:, 0].sum()) / scale if scale > 0 else float("nan")
    out.write_csv(os.path.join(a.out, "impulse.csv"),
                  ["time_s", "sum_J_x_Ns_per_m", "sum_J_y_Ns_per_m", "mpm_dP_x_Ns_per_m", "mpm_dP_y_Ns_per_m"], hist)
    plot_final(os.path.join(a.out, "final.png"), s, ids)
    dmg = ym.get(s, "damage")
    summary = dict(case="hybrid DEM–MPM rockfall", spheres=int(sum(len(O.bodies[i].shape.members) if type(O.bodies[i].shape).__name__ == "Clump"
                                                                  else 1 for i in ids)),
                   boulders=len(ids), clumps=int(sum(type(O.bodies[i].shape).__name__ == "Clump" for i in ids)),
                   mpm_particles=int(s.numParticles), impulse_balance_rel_error=err, wall_time_s=wall,
                   steps=int(O.iter), dt_s=float(O.dt), dt_dem_s=float(dt_dem), dt_mpm_stable_s=float(s.stableDt()),
                   end_time_s=float(O.time), total_contact_impulse_Ns_per_m=scale,
                   mpm_dP_Ns_per_m=dP.tolist(), sum_J_Ns_per_m=J.sum(axis=0).tolist(),
                   damaged_particles=int(np.sum(dmg > 0)), fully_damaged_particles=int(np.sum(dmg >= 1)),
                   boulder_velocities=[list(O.bodies[i].state.vel)[:2] for i in ids],
                   max_boulder_boulder_contacts=int(dem_contacts),
                   spacing_m=a.spacing, speed_m_s=a.speed, threads=ym.getThreads())
    out.write_summary(a.out, summary)
    print(f"[rockfall] {summary['spheres']} spheres ({summary['boulders']} boulders), {s.numParticles} MPM particles, "
          f"{O.iter} steps, {wall:.1f} s wall; impulse balance error {err:.2e}; damaged particles {summary['damaged_particles']}",
          flush=True)
    return summary


if __name__ == "__main__":
    main()
