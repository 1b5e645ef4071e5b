"""YADE's bonded-particle rock model JCFpm (Scholtès & Donzé 2012: ``JCFpmMat``,
``Ip2_JCFpmMat_JCFpmMat_JCFpmPhys``, ``Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM``) set up as
a plane-strain specimen, for side-by-side runs with the MPM (``scripts/paper/compare_bonded.py``).
Plane strain on the DEM side: one layer of spheres with their centres at z = 0, z translation and the
rotations about x and y blocked (``blockedDOFs = 'zXY'``), i.e. a disc assembly that moves only in
the xy plane (ε_zz = 0 exactly, as in the 2D MPM). Thickness mapping: the layer stands for a slab of
thickness t = 2 r̄ (r̄ the mean radius); stresses are forces / (length · t), and the sphere density is
raised so that the layer's mass equals ρ · area · t (wave speeds and the time step then belong to the
rock density, not to the 55 % solid fraction of a sphere layer). Everything here runs inside YADE
(``yade -n -x`` or ``/usr/bin/python3`` with YADE importable) and resets ``O``.
"""
import math
import os

import numpy as np

PACK_SOLID_FRACTION = 0.82    # target area fraction of the disc packing (2D random close packing ≈ 0.84)


def _yade():
    import yade
    from yade import O, pack, utils, wrapper
    return yade, O, pack, utils, wrapper


def disc_packing(lo, hi, r_mean, rel_fuzz=0.3, seed=1, cache_dir=None, fraction=PACK_SOLID_FRACTION):
    """Dense random disc packing of the rectangle [lo, hi] (2D, metres): radii uniform in
    r_mean·(1 ± rel_fuzz)·s. A random sequential cloud (YADE's makeCloud, area fraction ≈ 0.42) is
    grown in 30 stages inside four frictionless walls to the target area fraction, relaxing between
    stages. Returns an (N, 3) array of x, y, r. Cached as .npy in cache_dir (key: all arguments)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(hi - lo > 0)):
        raise ValueError(f"lo = {lo}, hi = {hi}: need finite corners with hi > lo")
    if not (math.isfinite(r_mean) and 0 < r_mean < 0.1 * min(hi - lo)):
        raise ValueError(f"r_mean = {r_mean} m must be in (0, {0.1 * min(hi - lo)}) m (a tenth of the short side)")
    if not 0 <= rel_fuzz < 1:
        raise ValueError(f"rel_fuzz = {rel_fuzz} must be in [0, 1)")
    if not 0.5 <= fraction <= 0.84:
        raise ValueError(f"fraction = {fraction} must be in [0.5, 0.84] (2D random close packing)")
    key = f"discs_{lo[0]:g}_{lo[1]:g}_{hi[0]:g}_{hi[1]:g}_{r_mean:g}_{rel_fuzz:g}_{seed}_{fraction:g}.npy"
    if cache_dir:
        path = os.path.join(cache_dir, key)
        if os.path.exists(path):
            return np.load(path)
    yade, O, pack, utils, w = _yade()
    try:                                          # makeCloud warns that a flat box means 2D: that is the intent
        from yade import log
        log.setLevel("SpherePack", log.ERROR)
    except Exception:
        pass
    O.reset()
    # the cloud starts with radii shrunk by the growth factor of a ~0.42 cloud → fraction
    grow = math.sqrt(fraction / 0.42)
    sp = pack.SpherePack()
    sp.makeCloud((lo[0], lo[1], 0), (hi[0], hi[1], 0), rMean=r_mean / grow, rRelFuzz=rel_fuzz, seed=seed)
    mat = O.materials.append(w.FrictMat(young=1e9, poisson=0.5, frictionAngle=0.0, density=2500.0))
    for c, r in sp:
        b = utils.sphere(c, r, material=mat)
        b.state.blockedDOFs = "zXY"
        O.bodies.append(b)
    area = float(np.prod(hi - lo))
    frac0 = sum(math.pi * b.shape.radius ** 2 for b in O.bodies) / area
    grow = math.sqrt(fraction / frac0)
    for axis, pos in ((0, lo[0]), (0, hi[0]), (1, lo[1]), (1, hi[1])):
        O.bodies.append(utils.wall(pos, axis=axis, material=mat))
    O.engines = [w.ForceResetter(), w.InsertionSortCollider([w.Bo1_Sphere_Aabb(), w.Bo1_Wall_Aabb()], verletDist=0.1 * r_mean),
                 w.InteractionLoop([w.Ig2_Sphere_Sphere_ScGeom(), w.Ig2_Wall_Sphere_ScGeom()],
                                   [w.Ip2_FrictMat_FrictMat_FrictPhys()], [w.Law2_ScGeom_FrictPhys_CundallStrack()]),
                 w.NewtonIntegrator(damping=0.7)]
    O.dt = 0.5 * utils.PWaveTimeStep()
    stages = 30
    for _ in range(stages):
        utils.growParticles(grow ** (1.0 / stages), updateMass=True, dynamicOnly=True)
        O.run(150, True)
    for _ in range(20):
        O.run(200, True)
        if utils.unbalancedForce() < 0.01:
            break
    out = np.array([[b.state.pos[0], b.state.pos[1], b.shape.radius] for b in O.bodies
                     if isinstance(b.shape, w.Sphere)])
    O.reset()
    if cache_dir:
        os.makedirs(cache_dir, exist_ok=True)
        np.save(os.path.join(cache_dir, key), out)
    return out


def overlapping(shape, xy, r):
    """Boolean mask of the discs (centres xy (N, 2), radii r (N,)) that intersect a hole shape
    (yade_mpm.geometry Circle, Box or Polygon): these are removed, so nothing bridges the hole."""
    xy, r = np.asarray(xy, float), np.asarray(r, float)
    from yade_mpm.geometry import Box, Circle, Polygon
    if isinstance(shape, Circle):
        return np.hypot(*(xy - shape.center[:2]).T) < shape.radius + r
    if isinstance(shape, Box):
        shape = Polygon([shape.lo[:2], (shape.hi[0], shape.lo[1]), shape.hi[:2], (shape.lo[0], shape.hi[1])])
    if not isinstance(shape, Polygon):
        raise ValueError(f"hole {shape!r} must be a yade_mpm.geometry Circle, Box or Polygon")
    hit = shape.contains(xy)
    v = shape.v
    for i in range(len(v)):
        a, b = v[i], v[(i + 1) % len(v)]
        ab = b - a
        s = np.clip(((xy - a) @ ab) / (ab @ ab), 0.0, 1.0)
        hit |= np.hypot(*(xy - (a + s[:, None] * ab)).T) < r
    return hit


class JcfpmMicro:
    """JCFpm micro-parameters (the calibrated quantities), SI units:
    young [Pa]: contact modulus E_c, kn = 2 E_c r1 r2 / (r1 + r2);  ks_kn [-]: ks / kn (JCFpmMat.poisson);
    tensile [Pa], cohesion [Pa]: bond strengths, FnMax = tensile · A, FsMax = cohesion · A with
    A = π min(r1, r2)²;  friction_deg [°]: contact friction angle (Mohr–Coulomb on bonds and after breakage)."""
    NAMES = ("young", "ks_kn", "tensile", "cohesion", "friction_deg")

    def __init__(self, young, ks_kn, tensile, cohesion, friction_deg):
        for n, v, lo_, hi_ in (("young", young, 0, math.inf), ("ks_kn", ks_kn, 0, 1), ("tensile", tensile, 0, math.inf),
                               ("cohesion", cohesion, 0, math.inf), ("friction_deg", friction_deg, 0, 89)):
            if not (math.isfinite(v) and lo_ < v <= hi_) if n != "friction_deg" else not (lo_ <= v <= hi_):
                raise ValueError(f"{n} = {v} must be in {'[' if n == 'friction_deg' else '('}{lo_}, {hi_}]")
        self.young, self.ks_kn, self.tensile, self.cohesion, self.friction_deg = young, ks_kn, tensile, cohesion, friction_deg

    def as_dict(self):
        return {n: getattr(self, n) for n in self.NAMES}


def layer_thickness(packing):
    """Thickness t = 2 r̄ [m] the disc layer stands for (stress = force / (length · t))."""
    return 2.0 * float(np.mean(packing[:, 2]))


def apparent_modulus(strain, stress, lo=0.25, hi=0.5):
    """Apparent (plane-strain) modulus [Pa] of a compression curve: least-squares slope of stress vs
    strain over the points with lo·peak ≤ stress of the first rise up to hi·peak (skips the seating toe
    and the start-up transient of a platen set moving at once, and any dip and re-rise later)."""
    strain, stress = np.asarray(strain, float), np.asarray(stress, float)
    ip = int(np.argmax(stress))
    # the first rise only: up to the first point above hi·peak (a later dip and re-rise is not elastic)
    n = int(np.argmax(stress > hi * stress[ip]))
    s, e = stress[:n], strain[:n]
    m = s >= lo * stress[ip]
    if m.sum() < 3:
        raise ValueError(f"only {int(m.sum())} points between {lo} and {hi} of the peak: record the curve more densely")
    return float(np.polyfit(e[m], s[m], 1)[0])


def uniaxial(packing, micro, platen_speed, density, holes=(), damping=0.4, idf=1.3, max_strain=0.015,
             post_peak_drop=0.7, record_every=200, crack_dir=None, progress=None, label="jcfpm", ramp_time=0.0):
    """Uniaxial compression of a JCFpm disc-layer specimen between two frictionless platens (YADE
    walls; the top one moves down at platen_speed [m/s], reached by a linear ramp over ramp_time [s],
    the bottom one is fixed), run in O.
    Bonds: every pair closer than idf·(r1 + r2) at the first step (JCFpm convention), then idf = 1.
    Stops when the stress has stayed below post_peak_drop·peak for three records, or at max_strain.
    Returns dict(strain, stress [Pa] (compression +), particles, steps, wall_time_s, cpu_time_s, dt, bonds,
    tensile_cracks, shear_cracks, cracks (K, 3): x, y, type (0 tension, 1 shear)).
    crack_dir: where JCFpm writes its cracks_<label>.txt (default: a temporary directory)."""
    import tempfile
    import time
    if not (math.isfinite(platen_speed) and platen_speed > 0):
        raise ValueError(f"platen_speed = {platen_speed} m/s must be > 0")
    if not (math.isfinite(density) and density > 0):
        raise ValueError(f"density = {density} kg/m³ must be > 0")
    if not 0 <= damping < 1:
        raise ValueError(f"damping = {damping} must be in [0, 1)")
    if not 1 <= idf <= 2:
        raise ValueError(f"idf = {idf} must be in [1, 2]")
    if not (math.isfinite(ramp_time) and ramp_time >= 0):
        raise ValueError(f"ramp_time = {ramp_time} s must be ≥ 0")
    if not 0 < post_peak_drop < 1:
        raise ValueError(f"post_peak_drop = {post_peak_drop} must be in (0, 1)")
    yade, O, pack_, utils, w = _yade()
    O.reset()
    t = layer_thickness(packing)
    x0, x1 = float(np.min(packing[:, 0] - packing[:, 2])), float(np.max(packing[:, 0] + packing[:, 2]))
    y0, y1 = float(np.min(packing[:, 1] - packing[:, 2])), float(np.max(packing[:, 1] + packing[:, 2]))
    width, height = x1 - x0, y1 - y0
    # layer mass = ρ · (x1 − x0)(y1 − y0) · t
    rho_s = density * width * height * t / float(np.sum(4.0 / 3.0 * math.pi * packing[:, 2] ** 3))
    keep = np.ones(len(packing), bool)
    for h in holes:
        keep &= ~overlapping(h, packing[:, :2], packing[:, 2])
    P = packing[keep]
    mat = O.materials.append(w.JCFpmMat(young=micro.young, poisson=micro.ks_kn, frictionAngle=math.radians(micro.friction_deg),
                                        tensileStrength=micro.tensile, cohesion=micro.cohesion, density=rho_s))
    wmat = O.materials.append(w.FrictMat(young=micro.young, poisson=micro.ks_kn, frictionAngle=0.0, density=rho_s))
    for x, y, r in P:
        b = utils.sphere((x, y, 0.0), r, material=mat)
        b.state.blockedDOFs = "zXY"
        O.bodies.append(b)
    bot = O.bodies.append(utils.wall(y0, axis=1, material=wmat))
    top = O.bodies.append(utils.wall(y1, axis=1, material=wmat))
    bo1 = w.Bo1_Sphere_Aabb(aabbEnlargeFactor=idf)
    ig2 = w.Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=idf)
    crack_dir = crack_dir or tempfile.mkdtemp(prefix="jcfpm_")
    os.makedirs(crack_dir, exist_ok=True)
    law = w.Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM(recordCracks=True, Key=label)
    O.engines = [
        w.ForceResetter(),
        w.InsertionSortCollider([bo1, w.Bo1_Wall_Aabb()], verletDist=0.05 * float(np.mean(P[:, 2]))),
        w.InteractionLoop([ig2, w.Ig2_Wall_Sphere_ScGeom()],
                          [w.Ip2_JCFpmMat_JCFpmMat_JCFpmPhys(cohesiveTresholdIteration=1), w.Ip2_FrictMat_FrictMat_FrictPhys()],
                          [law, w.Law2_ScGeom_FrictPhys_CundallStrack()]),
        w.NewtonIntegrator(damping=damping),
    ]
    O.dt = 0.5 * utils.PWaveTimeStep()
    cwd = os.getcwd()
    os.chdir(crack_dir)                       # JCFpm writes cracks_<Key>.txt into the working directory
    try:
        t0, c0 = time.time(), time.process_time()
        O.step()
        bo1.aabbEnlargeFactor, ig2.interactionDetectionFactor = 1.0, 1.0
        bonds = sum(1 for i in O.interactions if isinstance(i.phys, w.JCFpmPhys) and i.phys.isCohesive)
        area = width * t
        strain, stress = [0.0], [0.0]
        peak = 0.0
        while True:
            ramp = min(1.0, O.time / ramp_time) if ramp_time > 0 else 1.0
            O.bodies[top].state.vel = (0.0, -platen_speed * ramp, 0.0)
            O.run(record_every, True)
            gap = O.bodies[top].state.pos[1] - O.bodies[bot].state.pos[1]
            strain.append((height - gap) / height)
            stress.append(0.5 * (O.forces.f(top)[1] - O.forces.f(bot)[1]) / area)
            peak = max(peak, stress[-1])
            if progress:
                progress(strain[-1], stress[-1])
            if strain[-1] >= max_strain or (peak > 0 and len(stress) > 3 and max(stress[-3:]) < post_peak_drop * peak):
                break
        wall, cpu = time.time() - t0, time.process_time() - c0
    finally:
        os.chdir(cwd)
    cracks = np.zeros((0, 3))
    path = os.path.join(crack_dir, f"cracks_{label}.txt")
    if os.path.exists(path):
        with open(path) as f:
            head = f.readline().split()
        data = np.loadtxt(path, skiprows=1, ndmin=2)
        if len(data):
            ix, iy = head.index("p0"), head.index("p1")
            it = head.index("type") if "type" in head else head.index("t")
            cracks = data[:, [ix, iy, it]]
            # the type code of a tensile break differs between YADE versions (2023.02: 1); take the code
            # whose count is the law's tensile counter and store 0 = tensile, 1 = shear
            tens = 1.0 if np.sum(cracks[:, 2] == 1) == law.nbTensCracks else 0.0
            cracks[:, 2] = np.where(cracks[:, 2] == tens, 0.0, 1.0)
    return dict(strain=np.array(strain), stress=np.array(stress), particles=int(len(P)), steps=int(O.iter),
                wall_time_s=wall, cpu_time_s=cpu, dt=float(O.dt), bonds=int(bonds), tensile_cracks=int(law.nbTensCracks),
                shear_cracks=int(law.nbShearCracks), cracks=cracks, thickness_m=t, width_m=width, height_m=height,
                sphere_density=rho_s)


def love_weber(O, centers, radius, thickness, ids=None):
    """Love–Weber stress (tension positive [Pa]; xx, yy, xy) in circular measurement windows of the
    disc layer: σ = −1/(π w² t) Σ_c f_c ⊗ l_c over the contacts c whose contact point lies in the
    window, f_c the force body 1 exerts on body 2 and l_c = x2 − x1 the branch vector (full branch,
    "contact point in window" rule); w = radius [m], t = layer thickness [m]. centers: (K, 2)."""
    cp, fl = [], []
    for i in O.interactions:
        if not i.isReal:
            continue
        b1, b2 = O.bodies[i.id1], O.bodies[i.id2]
        if b1 is None or b2 is None or (ids is not None and not (i.id1 in ids and i.id2 in ids)):
            continue
        f = i.phys.normalForce + i.phys.shearForce
        l = b2.state.pos - b1.state.pos
        c = i.geom.contactPoint
        cp.append((c[0], c[1]))
        fl.append((f[0] * l[0], f[1] * l[1], 0.5 * (f[0] * l[1] + f[1] * l[0])))
    cp, fl = np.asarray(cp), np.asarray(fl)
    centers = np.asarray(centers, float)
    out = np.zeros((len(centers), 3))
    if len(cp):
        for k, c in enumerate(centers):
            m = np.sum((cp - c) ** 2, axis=1) < radius ** 2
            out[k] = -fl[m].sum(axis=0) / (math.pi * radius ** 2 * thickness)
    return out


def _disc_average(fun, centers, radius, n=12):
    """Average of fun(x, y) (returning a tuple of arrays) over discs of given radius around centers,
    by a polar midpoint rule with n rings × 2n angles (area-weighted)."""
    rr = (np.arange(n) + 0.5) / n
    th = (np.arange(2 * n) + 0.5) * math.pi / n
    R, T = np.meshgrid(rr * radius, th, indexing="ij")
    wgt = (R / R.sum()).ravel()
    dx, dy = (R * np.cos(T)).ravel(), (R * np.sin(T)).ravel()
    res = [fun(c[0] + dx, c[1] + dy) for c in centers]
    return [np.array([np.sum(wgt * comp) for comp in (r[k] for r in res)]) for k in range(len(res[0]))]


def circular_opening(packing, micro, center, hole_radius, sxx_far, syy_far, density, damping=0.5,
                     window_radius=None, tol=2e-3, max_transits=60, progress=None):
    """Kirsch test on a JCFpm disc layer (paper Sec. 3.1 loads, bonds unbreakable here): the packed
    square minus the opening (discs touching it removed) is loaded by far-field forces on its edge
    discs — σ·L·t per face (sxx_far, syy_far compression positive [Pa]), shared among the discs
    touching that face in proportion to their diameters, corrected linearly along the face so that
    the face load has no moment about the face centre — and relaxed with YADE's local damping.
    Stresses: Love–Weber in windows of radius w (default a/2, the same for every packing, so finer
    packings put more discs in a window) centred every w on the lines y = yc and x = xc at r ≥ 2a, averaged over the last 5 checks (one check = the P-wave time over 10 hole
    radii); Kirsch (Eqs. 41–42) averaged over the same windows. Stops when the window stresses change
    less than tol·max(|σ_far|) between checks (after 3 transits) or after max_transits transits.
    Returns dict(particles, steps, wall_time_s, cpu_time_s, l2_rel_error_{sxx,syy}_{xline,yline}[_near],
    l2_rel_error_max (windows at r ≥ 2a), l2_rel_error_near_max (2a ≤ r ≤ 5a), profiles)."""
    import time
    from . import kirsch
    yade, O, pack_, utils, w = _yade()
    O.reset()
    center = np.asarray(center, float)
    t = layer_thickness(packing)
    rbar = float(np.mean(packing[:, 2]))
    lo = np.min(packing[:, :2] - packing[:, 2:3], axis=0)
    hi = np.max(packing[:, :2] + packing[:, 2:3], axis=0)
    rho_s = density * float(np.prod(hi - lo)) * t / float(np.sum(4.0 / 3.0 * math.pi * packing[:, 2] ** 3))
    from yade_mpm.geometry import Circle
    P = packing[~overlapping(Circle(center, hole_radius), packing[:, :2], packing[:, 2])]
    mat = O.materials.append(w.JCFpmMat(young=micro.young, poisson=micro.ks_kn, frictionAngle=math.radians(micro.friction_deg),
                                        tensileStrength=micro.tensile, cohesion=micro.cohesion, density=rho_s))
    ids = []
    for x, y, r in P:
        b = utils.sphere((x, y, 0.0), r, material=mat)
        b.state.blockedDOFs = "zXY"
        ids.append(O.bodies.append(b))
    ids = np.array(ids)
    # far-field forces on the discs touching each face (within 0.25 r of it)
    F = np.zeros((len(P), 2))
    for axis, far in ((0, sxx_far), (1, syy_far)):
        L = float(hi[1 - axis] - lo[1 - axis])
        for side, face in ((-1, lo[axis]), (1, hi[axis])):
            touch = np.abs(P[:, axis] + side * P[:, 2] - face) < 0.25 * P[:, 2]
            share = P[touch, 2] / P[touch, 2].sum()
            # no net moment about the face centre (else the block spins up: local damping does not stop it)
            d = P[touch, 1 - axis] - 0.5 * (lo[1 - axis] + hi[1 - axis])
            share *= 1.0 - np.sum(share * d) / np.sum(share * d * d) * d
            share /= share.sum()
            F[touch, axis] += -side * far * L * t * share    # compression pushes inwards
    for k in np.nonzero(np.any(F != 0, axis=1))[0]:
        O.forces.setPermF(int(ids[k]), yade.Vector3(F[k, 0], F[k, 1], 0.0))
    bo1 = w.Bo1_Sphere_Aabb(aabbEnlargeFactor=1.3)
    ig2 = w.Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=1.3)
    O.engines = [
        w.ForceResetter(),
        w.InsertionSortCollider([bo1], verletDist=0.05 * rbar),
        w.InteractionLoop([ig2], [w.Ip2_JCFpmMat_JCFpmMat_JCFpmPhys(cohesiveTresholdIteration=1)],
                          [w.Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM()]),
        w.NewtonIntegrator(damping=damping),
    ]
    O.dt = 0.5 * utils.PWaveTimeStep()
    wr = 0.5 * hole_radius if window_radius is None else float(window_radius)
    if not 0 < wr < 0.25 * float(min(hi - lo)):
        raise ValueError(f"window_radius = {wr} m must be in (0, {0.25 * float(min(hi - lo))}) m")
    half = 0.5 * float(min(hi - lo))
    lines = {}
    for name, axis in (("xline", 0), ("yline", 1)):
        s = np.arange(2 * hole_radius, half - wr + 1e-12, wr)
        along = np.concatenate([-s[::-1], s])
        c = np.tile(center, (len(along), 1))
        c[:, axis] += along
        kxx, kyy, _ = _disc_average(lambda x, y: kirsch.cartesian(x, y, center, hole_radius, sxx_far, syy_far), c, wr)
        lines[name] = dict(centers=c, along=along, kxx=kxx, kyy=kyy)
    allc = np.concatenate([L["centers"] for L in lines.values()])
    cp = math.sqrt(micro.young / rho_s)                 # bar wave speed of the contact modulus (order of magnitude)
    check_steps = max(20, int(10 * hole_radius / cp / O.dt))
    transit_steps = float(np.max(hi - lo)) / cp / O.dt
    t0, c0 = time.time(), time.process_time()
    O.step()
    bo1.aabbEnlargeFactor, ig2.interactionDetectionFactor = 1.0, 1.0
    hist, prev = [], None
    fmax = max(abs(sxx_far), abs(syy_far))
    while True:
        O.run(check_steps, True)
        cur = -love_weber(O, allc, wr, t)               # compression positive
        hist.append(cur)
        change = np.inf if prev is None else float(np.max(np.abs(cur - prev))) / fmax
        prev = cur
        if progress:
            progress(O.iter, change)
        if (O.iter > 3 * transit_steps and change < tol) or O.iter > max_transits * transit_steps:
            break
    wall, cpu = time.time() - t0, time.process_time() - c0
    avg = np.mean(hist[-5:], axis=0)
    res = dict(particles=int(len(P)), steps=int(O.iter), wall_time_s=wall, cpu_time_s=cpu, window_radius_m=wr, dt=float(O.dt),
               converged=bool(change < tol), last_change_rel=change)
    k = 0
    prof = {}
    for name, L in lines.items():
        n = len(L["along"])
        sxx, syy = avg[k:k + n, 0], avg[k:k + n, 1]
        k += n
        res[f"l2_rel_error_sxx_{name}"] = float(np.linalg.norm(sxx - L["kxx"]) / np.linalg.norm(L["kxx"]))
        res[f"l2_rel_error_syy_{name}"] = float(np.linalg.norm(syy - L["kyy"]) / np.linalg.norm(L["kyy"]))
        near = np.abs(L["along"]) <= 5 * hole_radius        # 2a ≤ r ≤ 5a: little of the finite-block effect
        res[f"l2_rel_error_sxx_{name}_near"] = float(np.linalg.norm((sxx - L["kxx"])[near]) / np.linalg.norm(L["kxx"][near]))
        res[f"l2_rel_error_syy_{name}_near"] = float(np.linalg.norm((syy - L["kyy"])[near]) / np.linalg.norm(L["kyy"][near]))
        prof[name] = dict(along=L["along"], sxx=sxx, syy=syy, kxx=L["kxx"], kyy=L["kyy"])
    res["l2_rel_error_max"] = max(v for kk, v in res.items() if kk.startswith("l2_rel_error_s") and not kk.endswith("_near"))
    res["l2_rel_error_near_max"] = max(v for kk, v in res.items() if kk.startswith("l2_rel_error_s") and kk.endswith("_near"))
    res["profiles"] = prof
    return res
