"""The scenes of the MPM benchmark (scripts/tools/bench.py) and their timed runs in a child process
(`bench.py --child --mode MODE --case CASE --steps N --warmup W` prints one line "BENCH {json}"): the block
cases (CASES, build_scene), the paper-scale scenes (PAPER), the YADE hook, the spheres case (SPHERES) and the
contact case (CONTACT_CASE). Nothing is printed or written while the timed steps run."""
import json
import os
import time


# name: (dim, material, cells per axis of the particle block, timed steps, warm-up steps)
CASES = {
    "elastic2d_80k": (2, "elastic", (200, 100), 300, 20),
    "elastic2d_1m": (2, "elastic", (500, 500), 40, 5),
    "dpgk2d_80k": (2, "dpgk", (200, 100), 300, 20),
    "elastic3d_500k": (3, "elastic", (50, 50, 25), 30, 3),
}
SETTINGS_ENV = "YADE_MPM_BENCH_SETTINGS"  # JSON dict of solver settings for the timed scene (benchmarks only)
QUICK_STEPS = {"elastic2d_80k": 100, "elastic2d_1m": 15, "dpgk2d_80k": 100, "elastic3d_500k": 10}

SPACING = 0.01  # grid spacing l [m]; 2 particles per cell per axis


def build_scene(dim, material, cells, distribute=False):
    """The benchmark block: rock on a fixed floor with slip side walls, deformed by an initial
    pure-shear velocity field v = ε̇ (x − x_c) along x and −ε̇ (y − y_c) along y, so the stress grows
    to the DP–GK yield and damage thresholds within the warm-up. Returns the solver. distribute: under
    MPI each rank builds only its slab (make_solver(…, distribute=True))."""
    import yade_mpm as ym
    from yade_mpm import rocks
    size = [c * SPACING for c in cells]
    lo, hi = (0.0,) * dim, tuple(size)
    s = ym.make_solver(lo, hi, SPACING, margin=3, distribute=distribute)   # under MPI: no rank allocates the whole grid
    # the paper's granite (Sec. 3.1), elastic or with the DP–GK parameters of Sec. 3.2: at this strain
    # rate most particles yield and damage during the timed steps
    mat = rocks.granite() if material == "elastic" else rocks.granite_dpgk()
    ym.add_region(s, mat, lo, hi, ppc=2)
    s.addBoundaryPlane(1, -1, 0.0, "fixed")
    s.addBoundaryPlane(0, -1, 0.0, "slip")
    s.addBoundaryPlane(0, +1, size[0], "slip")
    s.gravity = (0.0, -9.81) if dim == 2 else (0.0, -9.81, 0.0)
    rate = 40.0  # ε̇ [1/s]
    x0, x1 = s.view("x0"), s.view("x1")
    s.view("v0")[:] = rate * (x0 - 0.5 * size[0])
    s.view("v1")[:] = -rate * x1
    return s


# Paper-scale scenes (timed for a few hundred steps; the wall time of the full run is extrapolated).
PAPER = {
    # Sec. 3.2: 5 m × 5 m plane-strain block, l = 0.02 m, 0.4 m line crack (two cell layers removed),
    # P = 75 MPa on the faces; DP–GK rock. The paper runs 0.4 s of a 0.5 s ramp.
    "penny_paper_250k": dict(end_time=0.4, steps=150, warmup=30),
    # Sec. 4: 150 mm × 150 mm sandstone with the arch-shaped tunnel (40 × 25 mm rectangle + 20 mm
    # semicircle), l = 1 mm, 20 ms of loading: cases.arch_tunnel("intact") stepped through YADE with its
    # rigid platen in PTS contact, as scripts/paper/tunnel_spalling.py runs it, at the scene's default Courant number.
    "tunnel_paper_83k": dict(end_time=0.02, steps=300, warmup=30),
}


def build_paper(name):
    import yade_mpm as ym
    from yade_mpm import rocks
    from yade_mpm_paper import cases
    if name == "penny_paper_250k":
        # full pressure within the warm-up: damage grows at the tips while timed
        s, _ = cases.line_crack(5.0, 0.02, rocks.granite_dpgk(), 75e6, ramp=2e-4, damping=0.05)
        return s
    s, _ = cases.arch_tunnel("intact", 1e-3)
    return s


def run_paper(name, steps, warmup):
    """Child process: time `steps` steps of a paper-scale scene; extrapolate to its simulated end time."""
    advance = None
    if name.startswith("tunnel"):
        from yade import O
        advance = lambda n: [O.step() for _ in range(n)]   # the platen moves with YADE's NewtonIntegrator
    out, s = timed(lambda: build_paper(name), steps, warmup, advance)
    out.update(dt=s.lastDt, courant=s.courant)
    return out


def timed(build, steps, warmup, advance=None):
    """Build a scene (`build()` → solver), run `warmup` steps, then time `steps` more with nothing else
    happening: wall and CPU seconds, phase times, particles, storage and peak-RSS growth per particle,
    threads and the plastic/damaged shares. advance(n) steps the scene (default: Solver.run, the C++
    loop). Returns (result dict, solver)."""
    import yade_mpm as ym
    rss0 = peak_rss_bytes()
    s = build()
    s.setSettings(json.loads(os.environ.get(SETTINGS_ENV, "{}")))   # an A/B of one build's settings (bench_kernel NAME=PATH@k=v)
    advance = advance or s.run   # (a YADE scene passes its own: O.step)
    advance(warmup)
    s._resetPhaseTimes()
    c0, t0 = time.process_time(), time.perf_counter()
    advance(steps)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    out = dict(steps=steps, wall=wall, cpu=cpu, phases=s._phaseTimes(), particles=s.numParticles,
               bytes_per_particle=s._bytesPerParticle, rss_per_particle=(peak_rss_bytes() - rss0) / s.numParticles,
               threads=ym.getThreads())
    out.update(material_stats(s))
    return out, s


def peak_rss_bytes():
    import resource
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def run_direct(name, steps, warmup):
    """Child process: build, warm up, time `steps` solver steps."""
    dim, material, cells, _, _ = CASES[name]
    return timed(lambda: build_scene(dim, material, cells), steps, warmup)[0]


def material_stats(s):
    """Share of particles that are plastic / damaged at the end (DP–GK), to show the scene is loaded."""
    import numpy as np
    try:
        eps, dmg = s.view("epsP"), s.view("damage")
    except ValueError:
        return {}
    return dict(plastic_fraction=float(np.mean(eps > 0)), damaged_fraction=float(np.mean(dmg > 0)))


def run_yade(name, steps, warmup):
    """Child process: the same scene through YADE's loop (O.run with the MpmEngine PyRunner)."""
    import yade_mpm as ym
    from yade import O
    from yade.wrapper import ForceResetter, NewtonIntegrator
    dim, material, cells, _, _ = CASES[name]

    def build():
        s = build_scene(dim, material, cells)
        O.engines = [ForceResetter(), ym.MpmEngine(s, label="mpmbench").runner(), NewtonIntegrator()]
        O.dt = 1.0
        return s
    return timed(build, steps, warmup, advance=lambda n: O.run(n, True))[0]


def run_hook_probe(name, steps, warmup):
    """Child process: the fixed per-step cost of the YADE hook (PyRunner call, Δt negotiation, YADE's own
    engines) on a tiny scene, where it is not hidden in the stepping cost: O.run vs Solver.run per step."""
    import yade_mpm as ym
    from yade import O
    from yade.wrapper import ForceResetter, NewtonIntegrator

    def tiny():
        s = ym.make_solver((0, 0), (0.1, 0.1), 0.01)
        ym.add_region(s, ym.rocks.granite(), (0, 0), (0.1, 0.1))
        return s
    a, b = tiny(), tiny()
    e = ym.MpmEngine(a, label="mpmprobe")
    O.engines = [ForceResetter(), e.runner(), NewtonIntegrator()]
    O.dt = 1.0
    O.run(warmup, True)
    b.run(warmup)
    ty, td = [], []
    for _ in range(5):  # interleaved blocks, minimum of each: robust against other processes
        t0 = time.perf_counter()
        O.run(steps, True)
        ty.append((time.perf_counter() - t0) / steps)
        t0 = time.perf_counter()
        b.run(steps)
        td.append((time.perf_counter() - t0) / steps)
    return dict(particles=a.numParticles, yade_step_s=min(ty), direct_step_s=min(td), hook_cost_s=min(ty) - min(td))


# The spheres case (issue 12): the dpgk2d_80k scene through O.run, without and with 10⁴ DEM spheres
# away from the MPM block, registered with yade_mpm.DemSpheres (two-way PTS contact, broad phase).
# Layouts: "free" — the spheres sit still on a lattice 1 m beside the block, touching nothing (no gravity on
# them): YADE's own cost is its collider and NewtonIntegrator, so the ratio shows the coupling's cost;
# "resting" — one row lying on a floor wall under gravity: YADE also runs 10⁴ sphere–wall contacts.
SPHERES = dict(base="dpgk2d_80k", n=10_000, radius=0.01, steps=200, quick_steps=60, warmup=10, blocks=3,
               layouts=("free", "resting"))


def run_spheres(name, steps, warmup):
    """Child process: two YADE scenes in this one process (O.switchScene), the same MPM block in each;
    scene B also holds SPHERES['n'] spheres 1 m beside the block, laid out as `name` ('free' or
    'resting', see SPHERES), all registered for MPM contact. Interleaved timed blocks; returns the wall
    seconds per block of each scene."""
    import yade_mpm as ym
    from yade import O, utils
    from yade.wrapper import (ForceResetter, FrictMat, InsertionSortCollider, Bo1_Sphere_Aabb, Bo1_Wall_Aabb,
                              InteractionLoop, Ig2_Sphere_Sphere_ScGeom, Ig2_Wall_Sphere_ScGeom,
                              Ip2_FrictMat_FrictMat_FrictPhys, Law2_ScGeom_FrictPhys_CundallStrack, NewtonIntegrator)
    dim, material, cells, _, _ = CASES[SPHERES["base"]]
    r, n = SPHERES["radius"], SPHERES["n"]

    resting = name == "resting"

    def engines(s, label, bodies):
        dem = [InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
               InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                               [Law2_ScGeom_FrictPhys_CundallStrack()])] if bodies else []
        return [ForceResetter()] + dem + [ym.MpmEngine(s, label=label, bodies=bodies).runner(),
                                          NewtonIntegrator(gravity=(0, -9.81 if resting else 0.0, 0), damping=0.3)]
    a = build_scene(dim, material, cells)
    O.engines = engines(a, "mpmNoSpheres", None)
    O.dt = 1.0
    O.run(warmup, True)
    O.switchScene()
    b = build_scene(dim, material, cells)
    x0 = cells[0] * SPACING + 1.0
    mat = O.materials.append(FrictMat(young=1e8, density=2500.0, frictionAngle=0.5))
    if resting:
        O.bodies.append(utils.wall(0.0, axis=1, material=mat))
    for k in range(n):   # resting: one row on the floor, 0.5 r apart; free: a 100 × 100 lattice, 0.5 r gaps
        c = (x0 + 2.5 * r * k, r, 0.0) if resting else (x0 + 2.5 * r * (k % 100), 2 * r + 2.5 * r * (k // 100), 0.0)
        sp = utils.sphere(c, r, material=mat)
        sp.state.blockedDOFs = "zXY"
        O.bodies.append(sp)
    bodies = ym.DemSpheres(b)
    bodies.add("all", mu=0.0)                 # frictionless, as when this benchmark was recorded
    O.engines = engines(b, "mpmWithSpheres", bodies)
    O.dt = 1.0
    O.run(warmup, True)
    assert a.lastDt == b.lastDt, "both scenes must step with the MPM stable Δt"
    O.switchScene()
    ta, tb = [], []
    for _ in range(SPHERES["blocks"]):
        for times in (ta, tb):
            t0 = time.perf_counter()
            O.run(steps, True)
            times.append(time.perf_counter() - t0)
            O.switchScene()
    O.switchScene()
    return dict(layout=name, particles=a.numParticles, spheres=n, steps=steps, wall_without=ta, wall_with=tb,
                active_spheres=int(bodies.active.sum()), broad_phase_checks=bodies.checks, coupling_python_wall=bodies.wall,
                steps_with=b.steps, dt=b.lastDt, threads=ym.getThreads())


# Contact cost: the uniaxial specimen of paper Sec. 3.3 (cases.uniaxial_flaw, l = 1 mm, rigid-filled flaw:
# a platen and a free filler in PTS contact) through YADE's loop, beside the same particles without bodies.
CONTACT_CASE = dict(name="uniaxial_filled_1mm", spacing=1e-3, steps=300, warmup=30)


def run_contact(name, steps, warmup):
    """Child process: O.run of the uniaxial specimen with its platen and filler (mode "contact") or of the
    same particles without any body ("nocontact")."""
    from yade import O
    from yade_mpm_paper import cases
    bodies = name == "contact"
    return timed(lambda: cases.uniaxial_flaw("filled", CONTACT_CASE["spacing"], mu_con=0.4, label="mpmcontact",
                                             with_bodies=bodies)[0], steps, warmup, advance=lambda n: O.run(n, True))[0]


def child(args):
    fn = {"yade": run_yade, "paper": run_paper, "hookprobe": run_hook_probe, "spheres": run_spheres,
          "contact": run_contact}.get(args.mode, run_direct)
    res = fn(args.case, args.steps, args.warmup)
    print("BENCH " + json.dumps(res), flush=True)
