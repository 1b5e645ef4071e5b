"""Scene builders of the reference cases, written once: scripts, tests and benchmarks build their
scenes here and keep only their command line and analysis.

    circular_opening(spacing, ...)   paper Sec. 3.1: holed block under biaxial in-situ stress
    line_crack(size, spacing, ...)   paper Sec. 3.2: pressurised line ("penny-shaped") crack
    arch_tunnel_holes(...)           paper Sec. 4: the arch-shaped tunnel opening (geometry only)
    tunnel_flaw(...)                 paper Sec. 4: the 60 × 2 mm flaw left of the tunnel (geometry only)
    arch_tunnel_specimen(spacing, ...)  the tunnel specimen with its opening and slip walls (no top load)
    arch_tunnel(case, spacing, ...)  paper Sec. 4 + grout: the full scene with the YADE platen (and filler)
    uniaxial_flaw(variant, spacing, ...)  paper Sec. 3.3: 50 × 150 mm specimen, platen, open/rigid-filled flaw
    yade_platen / yade_filler / yade_engines   the rigid YADE bodies and engines of those loading scenes

Rock parameters come from ``yade_mpm.rocks``; the small scenes of the stability suite live with their
checks in ``yade_mpm.stability``. Quantities are SI; stresses are tension positive inside the solver.
"""
import math

import numpy as np

from . import rocks
from .materials import ElasticMat
from .geometry import Box, Circle, rotated_rectangle
from .scene import add_region, apply_face_traction, apply_traction, get, make_solver, set_initial_stress

# ------------------------------------------------------------------------------------------------
# Circular opening, paper Sec. 3.1 (Figs. 3-5)
OPENING_CENTER = 2.5        # hole centre x = y [m]
OPENING_RADIUS = 0.1        # a [m] (diameter 0.2 m)
OPENING_SXX = 20e6          # far-field compression σxx [Pa], compression positive
OPENING_SYY = 10e6          # far-field compression σyy [Pa]


def apply_far_field(solver, lo, hi, ppc, sxx, syy, boundary_load="consistent", sides=(-1, 1)):
    """Far-field traction t = σ0·n (σ0 = diag(sxx, syy), tension positive [Pa]) on the four faces of
    the 2D block [lo, hi] [m]: spread over the outer particle rows with ``consistent_row_weights``
    (boundary_load="consistent", exact discrete equilibrium of the intact block) or on the outermost
    row only ("outer-row"). sides: the faces loaded along each axis (a quarter model loads only +1)."""
    if boundary_load not in ("consistent", "outer-row"):
        raise ValueError(f"boundary_load = {boundary_load!r} must be 'consistent' or 'outer-row'")
    for axis, far in ((0, sxx), (1, syy)):
        for side, face in ((sd, lo[axis] if sd < 0 else hi[axis]) for sd in sides):
            t = np.zeros(2)
            t[axis] = side * far                  # σ0·n with n = side·e_axis: compression pushes inwards
            apply_face_traction(solver, axis, side, face, t, ppc, consistent=(boundary_load == "consistent"))


def circular_opening(spacing, domain=4.8, ppc=2, damping=0.5, boundary_load="consistent", material=None, quarter=False):
    """Square block of side `domain` [m] centred on (2.5, 2.5) m with a hole of radius 0.1 m, every
    particle at the in-situ stress (σxx, σyy) = (−20, −10) MPa, σzz = ν(σxx + σyy) (plane strain), and
    the far-field traction on its faces, so only the hole wall is out of balance ("excavation").
    material: default ``rocks.granite()``. quarter=True models the quadrant x, y ≥ 2.5 m only, with
    slip (symmetry) planes on x = 2.5 m and y = 2.5 m (doc/boundaries.md). Returns (solver, lo, hi)."""
    mat = material or rocks.granite()
    lo, hi = np.full(2, OPENING_CENTER - domain / 2), np.full(2, OPENING_CENTER + domain / 2)
    if quarter:
        lo = np.full(2, OPENING_CENTER)
    s = make_solver(lo, hi, spacing, margin=2)
    add_region(s, mat, lo, hi, ppc=ppc, holes=[Circle((OPENING_CENTER, OPENING_CENTER), OPENING_RADIUS)])
    sxx, syy = -OPENING_SXX, -OPENING_SYY     # tension positive inside the solver
    set_initial_stress(s, (sxx, syy, mat.poisson * (sxx + syy), 0.0))
    apply_far_field(s, lo, hi, ppc, sxx, syy, boundary_load, sides=(1,) if quarter else (-1, 1))
    if quarter:
        s.addBoundaryPlane(0, -1, OPENING_CENTER, "slip")
        s.addBoundaryPlane(1, -1, OPENING_CENTER, "slip")
    s.damping = damping
    return s, lo, hi


# ------------------------------------------------------------------------------------------------
# Pressurised line crack, paper Sec. 3.2 (Figs. 6-9)
CRACK_HALF_LENGTH = 0.2     # c [m] (crack length 0.4 m)


def line_crack(size, spacing, material, pressure, ramp, damping, crack_nodes="excluded", half_length=CRACK_HALF_LENGTH):
    """Square block [0, size]² [m] with a line crack of half-length c at its centre, made by removing
    the particles of two cell layers (ppc = 2); the crack faces carry the pressure P [Pa] as a particle
    traction, ramped linearly over `ramp` [s]. crack_nodes = "excluded" (default) takes the grid nodes
    between the faces out of the WLS fits (``add_region(gap_nodes="excluded")``, ``scene.thin_gap_nodes``):
    the faces are 2 cells apart and the cubic B-spline reaches 2 cells, so with "shared" (the paper's
    construction) both faces map to the mid-line node row and stay tied — the opening then moves away
    from Sneddon as the grid is refined (doc/boundaries.md).

    Returns (solver, geo): geo = dict(xc, yc, h, dp, x0 (initial positions by id), top, bot (particle
    ids of the loaded face rows), half_length)."""
    if crack_nodes not in ("shared", "excluded"):
        raise ValueError(f"crack_nodes = {crack_nodes!r} must be 'shared' or 'excluded'")
    if not (np.isfinite(half_length) and 0 < half_length < size / 2 - 2 * spacing):
        raise ValueError(f"half_length = {half_length} m must lie in (0, size/2 − 2·spacing) = (0, {size / 2 - 2 * spacing:g}) m")
    h = spacing
    s = make_solver((0, 0), (size, size), h, margin=2)
    xc = yc = round(size / 2 / h) * h   # crack centre on a grid line so the hole is exactly two cell layers
    crack = Box((xc - half_length, yc - h), (xc + half_length, yc + h))
    add_region(s, material, (0, 0), (size, size), ppc=2, holes=[crack], gap_nodes=crack_nodes)
    x0 = get(s, "pos")                  # by particle id (== storage slot before the first step)
    dp = h / 2                          # particle spacing
    along = np.abs(x0[:, 0] - xc) < half_length
    top = np.nonzero(along & (np.abs(x0[:, 1] - (yc + h + dp / 2)) < dp / 4))[0]
    bot = np.nonzero(along & (np.abs(x0[:, 1] - (yc - h - dp / 2)) < dp / 4))[0]
    # pressure P on the faces: traction −P n, n the outward normal of the solid (−y on the upper face)
    apply_traction(s, top, (0.0, pressure), dp)
    apply_traction(s, bot, (0.0, -pressure), dp)
    s.damping = damping
    s.tractionRampTime = ramp
    return s, dict(xc=xc, yc=yc, h=h, dp=dp, x0=x0, top=top, bot=bot, half_length=half_length)


# ------------------------------------------------------------------------------------------------
# Arch-shaped tunnel, paper Sec. 4 (Fig. 16), Pan et al. 2020b
TUNNEL_WIDTH = 0.15         # square specimen side [m]
TUNNEL_RECT = (0.04, 0.025)  # width × height of the rectangular part [m]
TUNNEL_RADIUS = 0.02        # semicircular roof radius [m]
TUNNEL_FLOOR = 0.055        # height of the tunnel floor above the specimen base [m]


def arch_tunnel_holes(width=TUNNEL_WIDTH, floor=TUNNEL_FLOOR, rect=TUNNEL_RECT, radius=TUNNEL_RADIUS):
    """The arch-shaped opening as holes for ``add_region``: a rect[0] × rect[1] rectangle with its floor
    at y = floor, centred at x = width/2, under a semicircular roof of `radius` centred on the top edge
    of the rectangle (radius = rect[0]/2 in the paper)."""
    cx = width / 2
    w, hgt = rect
    return [Box((cx - w / 2, floor), (cx + w / 2, floor + hgt)), Circle((cx, floor + hgt), radius)]


def arch_tunnel_specimen(spacing, material=None, ppc=2, width=TUNNEL_WIDTH, floor=TUNNEL_FLOOR, walls=("left", "right", "bottom"),
                         holes=()):
    """The tunnel specimen [0, width]² with the arch opening (and further `holes`), free-slip walls on
    `walls` (the paper's four sides minus the loaded top, where the caller puts a platen or a traction).
    material: default ``rocks.pan2020_sandstone()``. Returns the solver."""
    planes = {"left": (0, -1, 0.0), "right": (0, 1, width), "bottom": (1, -1, 0.0), "top": (1, 1, width)}
    bad = [w for w in walls if w not in planes]
    if bad:
        raise ValueError(f"walls: unknown {bad}; allowed {sorted(planes)}")
    mat = material or rocks.pan2020_sandstone()
    s = make_solver((0, 0), (width, width), spacing, margin=2)
    add_region(s, mat, (0, 0), (width, width), ppc=ppc, holes=list(arch_tunnel_holes(width, floor)) + list(holes))
    for w in walls:
        axis, side, pos = planes[w]
        s.addBoundaryPlane(axis, side, pos, "slip")
    return s


# The flaw of Figs. 16b, c. The paper gives its size (60 mm × 2 mm, "adjacent to the tunnel", on its
# left) but not its position or angle; they are chosen from the description of Fig. 19 (the flaw
# hinders the load path from the top to the left waist; stress concentrates at the flaw toe, next to
# the left spandrel; a crack links the toe to the tunnel corner) — see doc/tunnel.md. One place only:
FLAW_LENGTH = 0.06                 # [m]
FLAW_WIDTH = 0.002                 # [m]
FLAW_ANGLE = math.radians(60.0)    # inclination to the horizontal [rad]; rises to the left, away from the tunnel
FLAW_TOE_GAP = 0.010               # horizontal rock bridge from the toe (lower end) to the left wall [m]
FLAW_TOE = (TUNNEL_WIDTH / 2 - TUNNEL_RECT[0] / 2 - FLAW_TOE_GAP, TUNNEL_FLOOR + TUNNEL_RECT[1])  # at spandrel height [m]

# Loading and contact of Sec. 4
PLATEN_SPEED = 0.1                 # downward velocity of the rigid top platen [m/s]
TUNNEL_END_TIME = 0.02             # loading time [s] (2 mm of platen displacement)
PLATEN_FRICTION = 0.0              # platen–rock μ_con [-]: the paper's free-slip top
FILLER_FRICTION = 0.6              # filler–rock μ_con [-] (the paper's rigid-filled case of Sec. 3.3, Figs. 14–15)
FILLER_CHI = 0.5                   # filler–rock residual penetration factor χ [-] (doc/tunnel.md, doc/contact.md)
TUNNEL_CASES = ("intact", "open_flaw", "filled_flaw", "grout_flaw")
TUNNEL_MAX_SPACING = 1.25 * FLAW_WIDTH   # coarsest grid [m]: the flaw still cuts a full row of particles (ppc = 2)


def tunnel_flaw(toe=FLAW_TOE, length=FLAW_LENGTH, width=FLAW_WIDTH, angle=FLAW_ANGLE):
    """The flaw as a dict: toe (lower end, centre of the short side) and tip (upper end) [m], centre,
    unit direction from toe to tip, normal, length, width [m], angle [rad] and the Polygon."""
    u = np.array([-math.cos(angle), math.sin(angle)])        # from the toe up and to the left
    toe = np.asarray(toe, float)
    center = toe + 0.5 * length * u
    return dict(toe=toe, tip=toe + length * u, center=center, direction=u, normal=np.array([-u[1], u[0]]),
                length=length, width=width, angle=angle,
                polygon=rotated_rectangle(center, length, width, math.atan2(u[1], u[0])))


def arch_tunnel(case, spacing, material=None, grout=None, ppc=2, platen_speed=PLATEN_SPEED,
                platen_friction=PLATEN_FRICTION, filler_friction=FILLER_FRICTION, label="mpm"):
    """The scene of paper Sec. 4 in a fresh YADE scene (O.reset()): the 150 × 150 mm specimen with the
    arch tunnel, free-slip left, right and bottom walls, a rigid top platen (a YADE Box with blocked
    DOFs moving down at `platen_speed` [m/s], PTS contact with μ = platen_friction) and
      case "intact"       no flaw,
           "open_flaw"    the flaw (``tunnel_flaw()``) cut out,
           "filled_flaw"  the flaw cut out and filled by a free rigid YADE Box (PTS contact, μ = filler_friction),
           "grout_flaw"   the flaw filled with particles of the elastic `grout` (default ``rocks.cement_grout()``),
                          bonded to the rock through the shared grid.
    spacing: grid spacing l [m] (paper 1 mm); material: the rock (default ``rocks.pan2020_sandstone()``).
    O.engines = [ForceResetter, the MpmEngine (labelled `label`, with the bodies), NewtonIntegrator].
    Returns (solver, bodies): bodies = dict(platen=YADE id, filler=YADE id or None, rigid=RigidBodies,
    engine=MpmEngine, flaw=tunnel_flaw() or None, width=specimen width [m],
    axial_stress() -> platen reaction / width [Pa, compression positive],
    platen_displacement() -> downward platen displacement since the build [m])."""
    if case not in TUNNEL_CASES:
        raise ValueError(f"case = {case!r} must be one of {TUNNEL_CASES}")
    if not (isinstance(spacing, (int, float)) and 0 < spacing <= TUNNEL_MAX_SPACING):
        raise ValueError(f"spacing = {spacing!r} m must be in (0, {TUNNEL_MAX_SPACING}] m (the {FLAW_WIDTH * 1e3:g} mm flaw must "
                         "cut at least one full particle row, particle spacing l/2)")
    if not (isinstance(platen_speed, (int, float)) and math.isfinite(platen_speed) and platen_speed > 0):
        raise ValueError(f"platen_speed = {platen_speed!r} m/s must be a finite number > 0")
    from yade import O
    from .bodies import RigidBodies

    W = TUNNEL_WIDTH
    flaw = tunnel_flaw() if case != "intact" else None
    rock = material or rocks.pan2020_sandstone()
    holes = [flaw["polygon"]] if flaw is not None else []
    s = arch_tunnel_specimen(spacing, rock, ppc, holes=holes)
    if case == "grout_flaw":
        add_region(s, grout or rocks.cement_grout(), (0, 0), (W, W), ppc=ppc, keep=flaw["polygon"].contains)
    O.reset()
    rb = RigidBodies(s)
    platen = yade_platen(rb, W / 2, W, W, spacing, platen_speed, platen_friction)
    filler = yade_filler(rb, flaw, filler_friction, density=rock.density) if case == "filled_flaw" else None  # weighs as the rock
    eng = yade_engines(s, rb, label)
    y0 = O.bodies[platen].state.pos[1]

    def axial_stress():
        return rb.force(platen)[1] / W             # the rock pushes the platen up: compression positive

    def platen_displacement():
        return y0 - O.bodies[platen].state.pos[1]
    return s, dict(platen=platen, filler=filler, rigid=rb, engine=eng, flaw=flaw, width=W,
                   axial_stress=axial_stress, platen_displacement=platen_displacement)


# ------------------------------------------------------------------------------------------------
# Rigid YADE bodies of the loading scenes (2D: 1 m thick boxes, the unit slice of plane strain)
BODY_HALF_THICKNESS = 0.5          # YADE box half-extent along z [m]: thickness 1 m


def yade_platen(rb, x_center, top, width, spacing, speed, friction, cohesion=0.0):
    """A rigid YADE Box platen resting on the specimen top y = `top` [m] (its lower face there: the top
    particle row is then at the default detection distance, half a particle edge), 1.2 × `width` wide
    and 10 cells high, blockedDOFs 'xyzXYZ', moving down at `speed` [m/s]; registered in the
    RigidBodies `rb` with μ = friction [-], c = cohesion [Pa]. Returns its YADE id."""
    from yade import O, utils
    hp = 5 * spacing                               # platen half-height
    pid = O.bodies.append(utils.box((x_center, top + hp, 0), (0.6 * width, hp, BODY_HALF_THICKNESS), fixed=False))
    O.bodies[pid].state.blockedDOFs = "xyzXYZ"
    O.bodies[pid].state.vel = (0, -speed, 0)
    rb.add(pid, mu=friction, cohesion=cohesion)
    return pid


def yade_filler(rb, flaw, friction, cohesion=0.0, density=None, blocked="zXY", chi=None):
    """A free rigid YADE Box that is the flaw (dict of ``tunnel_flaw``): the domain of the filling, its
    length × width, registered in `rb` with d0 = "initial" (doc/contact.md) so the particles next to it —
    the flaw is cut from the particle lattice, its faces are jagged — touch it at zero force from t = 0;
    free in the plane (blockedDOFs `blocked`, default 'zXY'; 'zXYZ' also blocks its rotation); μ = friction
    [-], c = cohesion [Pa], χ = chi [-] (None: FILLER_CHI); density [kg/m³] (None: YADE's default 1000):
    its true mass, lighter than the grid nodes along its faces — the stick step moves it with its contact
    nodes (doc/contact.md). The grid nodes it covers get the contact exclusion bit, as an open flaw's nodes
    get the user bit. Returns its YADE id."""
    from yade import O, utils
    from yade.minieigenHP import Quaternion, Vector3
    from yade.wrapper import FrictMat
    ang = math.atan2(flaw["direction"][1], flaw["direction"][0])
    kw = {} if density is None else dict(material=FrictMat(density=density))
    fid = O.bodies.append(utils.box((flaw["center"][0], flaw["center"][1], 0), (0.5 * flaw["length"], 0.5 * flaw["width"], BODY_HALF_THICKNESS),
                                    orientation=Quaternion(Vector3(0, 0, 1), ang), fixed=False, **kw))
    st = O.bodies[fid].state
    st.blockedDOFs = blocked                       # default in the plane: x, y, rotation about z
    rb.add(fid, mu=friction, cohesion=cohesion, chi=FILLER_CHI if chi is None else chi, d0="initial")
    return fid


def yade_engines(solver, rb, label):
    """O.engines = [ForceResetter, the MpmEngine (with the RigidBodies `rb`, or None), NewtonIntegrator
    (no damping, no gravity)]; O.dt is lowered to the MPM stable step by the engine. Returns the MpmEngine."""
    from yade import O
    from yade.wrapper import ForceResetter, NewtonIntegrator
    from .engine import MpmEngine
    eng = MpmEngine(solver, label=label, bodies=rb)
    O.engines = [ForceResetter(), eng.runner(), NewtonIntegrator(damping=0.0, gravity=(0, 0, 0))]
    O.dt = 1.0
    return eng


def tunnel_location(point, flaw=None):
    """Name of the part of the tunnel (or flaw) nearest a point [m]: "floor", "left/right corner"
    (where the walls meet the floor), "left/right wall" (the waist), "left/right spandrel" (the arch
    shoulders, more than 30° from the vertical), "crown", "flaw toe", "flaw tip", "flaw face", or
    "rock away from the opening" (more than 10 mm from the opening and the flaw)."""
    x, y = float(point[0]), float(point[1])
    cx, floor = TUNNEL_WIDTH / 2, TUNNEL_FLOOR
    hw, hr = TUNNEL_RECT[0] / 2, TUNNEL_RECT[1]
    if flaw is not None:
        r = np.array([x, y]) - flaw["toe"]
        s = float(np.clip(r @ flaw["direction"], 0, flaw["length"]))
        d_flaw = np.linalg.norm(r - s * flaw["direction"])
        if d_flaw < 0.005:
            return "flaw toe" if s < 0.2 * flaw["length"] else ("flaw tip" if s > 0.8 * flaw["length"] else "flaw face")
    # distance to the opening (rectangle ∪ half disc), 0 inside
    dx = max(abs(x - cx) - hw, 0.0)
    dy = max(floor - y, y - (floor + hr), 0.0)
    d_rect = math.hypot(dx, dy)
    d_arch = max(math.hypot(x - cx, y - (floor + hr)) - TUNNEL_RADIUS, 0.0) if y >= floor + hr else d_rect
    if min(d_rect, d_arch) > 0.010:
        return "rock away from the opening"
    side = "left" if x < cx else "right"
    if y >= floor + hr - 0.003:
        theta = math.degrees(math.atan2(abs(x - cx), max(y - (floor + hr), 1e-12)))
        return "crown" if theta < 30 else f"{side} spandrel"
    if y < floor + 0.005:
        return f"{side} corner" if abs(x - cx) > hw - 0.003 else "floor"
    return f"{side} wall"


def tunnel_opening_distance(points, width=TUNNEL_WIDTH, floor=TUNNEL_FLOOR, rect=TUNNEL_RECT, radius=TUNNEL_RADIUS):
    """Distance [m] of points (N, 2) from the arch opening of ``arch_tunnel_holes`` (0 inside)."""
    p = np.asarray(points, float)
    cx, hw, top = width / 2, rect[0] / 2, floor + rect[1]
    dx = np.maximum(np.abs(p[:, 0] - cx) - hw, 0.0)
    dy = np.maximum(np.maximum(floor - p[:, 1], p[:, 1] - top), 0.0)
    d_rect = np.hypot(dx, dy)
    d_arch = np.maximum(np.hypot(p[:, 0] - cx, p[:, 1] - top) - radius, 0.0)
    return np.minimum(d_rect, d_arch)


# ------------------------------------------------------------------------------------------------
# Uniaxial compression with a flaw, paper Sec. 3.3 (Figs. 10-15), Miao et al. (2018) sandstone
UNIAXIAL_WIDTH = 0.05              # specimen width [m]
UNIAXIAL_HEIGHT = 0.15             # specimen height [m]
UNIAXIAL_FLAW = (0.025, 0.002, math.radians(30.0))   # flaw length, width [m], inclination [rad], at the centre
UNIAXIAL_PAPER_SPACING = 0.5e-3    # the paper's grid [m]
UNIAXIAL_VARIANTS = ("intact", "open", "filled")
UNIAXIAL_SIDE_ROOM = 0.05          # grid beyond each free side face [m]: spalled fragments (measured up to 14 m/s) stay on the grid


def uniaxial_flaw_geometry(width=UNIAXIAL_WIDTH, height=UNIAXIAL_HEIGHT, flaw=UNIAXIAL_FLAW):
    """The centred flaw as a dict like ``tunnel_flaw`` (toe, tip, centre, direction, normal, polygon…)."""
    length, fw, angle = flaw
    u = np.array([-math.cos(angle), math.sin(angle)])
    center = np.array([width / 2, height / 2])
    return tunnel_flaw(toe=center - 0.5 * length * u, length=length, width=fw, angle=angle)


def exclude_nodes_inside(solver, polygon):
    """Take the physical grid nodes inside `polygon` out of the WLS fits (user exclusion bit): the
    faces of an open flaw thinner than the stencil then do not share those nodes — the same nodes a
    rigid filler of the flaw covers (contact bit). Returns the number of nodes excluded."""
    xn = solver.nodePositions()
    lo, hi = np.asarray(solver.origin), np.asarray(solver.origin) + solver.spacing * np.asarray(solver.cells)
    inside = polygon.contains(xn) & np.all((xn > lo + 1e-12) & (xn < hi - 1e-12), axis=1)
    for i in np.nonzero(inside)[0]:
        solver.setNodeExcluded(int(i), True)
    return int(inside.sum())


def uniaxial_flaw(variant, spacing, mu_con=0.0, c_con=0.0, ppc=2, material=None, platen_speed=PLATEN_SPEED,
                  platen_friction=PLATEN_FRICTION, label="mpm", with_bodies=True, filler_blocked="zXY",
                  ramp_time=0.0, end_cap_cells=0, side_room=UNIAXIAL_SIDE_ROOM):
    """The scene of paper Sec. 3.3 in a fresh YADE scene (O.reset()): a 50 × 150 mm specimen of
    ``rocks.miao2018_sandstone()`` (or `material`) on a free-slip base (y = 0), loaded by a rigid top
    platen (a YADE Box, blockedDOFs 'xyzXYZ', moving down at `platen_speed` [m/s], frictionless: the
    free-slip top), and
      variant "intact"  no flaw,
              "open"    the 25 × 2 mm flaw inclined 30° at the centre cut out (nodes inside excluded),
              "filled"  the flaw cut out and filled by a free rigid YADE Box (rock density) in PTS
                        contact with μ_con = mu_con [-] and c_con = c_con [Pa].
    filler_blocked: the filler's blockedDOFs ('zXYZ' keeps it from rotating; see doc/contact.md).
    ramp_time [s] ≥ 0: the platen speed rises linearly from 0 over this time when the run is driven by
    scene["advance"](n) (speed updated before each call: a staircase with n-step treads); 0 (default) starts at
    full speed. end_cap_cells ≥ 0: the particles within this many cells of the base and of the platen get a
    Grady–Kipp activation strain ε_D⁰ = 0.99 (Eq. 37) that tension never reaches — "end caps", so the layer
    under the penalty contact does not crack first (doc/mpm_vs_bonded.md); 0 (default) = none.
    side_room [m] > 0: grid beyond each free side face (default UNIAXIAL_SIDE_ROOM).
    spacing: grid spacing l [m] (paper 0.5 mm); ppc particles per cell per axis. with_bodies=False builds
    the same particles with no YADE bodies at all (the benchmark's reference for the contact cost).
    Returns (solver, scene) with scene = dict(platen, filler (YADE ids; filler None unless filled),
    rigid (RigidBodies), engine (MpmEngine), flaw (dict or None), width, height [m],
    axial_stress() -> platen reaction / width [Pa, compression positive],
    axial_strain() -> platen displacement / height [-],
    advance(n) -> sets the (ramped) platen speed for the time O.time, then runs n steps)."""
    if variant not in UNIAXIAL_VARIANTS:
        raise ValueError(f"variant = {variant!r} must be one of {UNIAXIAL_VARIANTS}")
    W, H = UNIAXIAL_WIDTH, UNIAXIAL_HEIGHT
    flaw = uniaxial_flaw_geometry() if variant != "intact" else None
    if flaw is not None and not (isinstance(spacing, (int, float)) and 0 < spacing <= 2 * flaw["width"]):
        raise ValueError(f"spacing = {spacing!r} m must be in (0, {2 * flaw['width']}] m: the {flaw['width'] * 1e3:g} mm "
                         "flaw must cut at least one full particle row")
    if not (isinstance(platen_speed, (int, float)) and math.isfinite(platen_speed) and platen_speed > 0):
        raise ValueError(f"platen_speed = {platen_speed!r} m/s must be a finite number > 0")
    if not (isinstance(ramp_time, (int, float)) and math.isfinite(ramp_time) and ramp_time >= 0):
        raise ValueError(f"ramp_time = {ramp_time!r} s must be a finite number ≥ 0")
    if not (isinstance(end_cap_cells, int) and 0 <= end_cap_cells < H / (2 * spacing)):
        raise ValueError(f"end_cap_cells = {end_cap_cells!r} must be an integer in [0, height/(2·spacing)) = [0, {H / (2 * spacing):g})")
    if not (isinstance(side_room, (int, float)) and math.isfinite(side_room) and side_room > 0):
        raise ValueError(f"side_room = {side_room!r} m must be a finite number > 0")
    from yade import O
    from .bodies import RigidBodies
    rock = material or rocks.miao2018_sandstone()
    side = side_room                               # grid room beside the free faces for spalled fragments
    s = make_solver((-side, 0), (W + side, H), spacing, margin=2)
    add_region(s, rock, (0, 0), (W, H), ppc=ppc, holes=[flaw["polygon"]] if flaw is not None else [])
    s.addBoundaryPlane(1, -1, 0.0, "slip")
    if end_cap_cells > 0:                          # end caps: ε_D⁰ = 0.99 (Eq. 37) near the base and the platen
        y, e0 = s.view("x1"), s.view("eps0")
        e0[(y < end_cap_cells * spacing) | (y > H - end_cap_cells * spacing)] = 0.99
        del y, e0
    if variant == "open":
        exclude_nodes_inside(s, flaw["polygon"])
    O.reset()
    if not with_bodies:
        return s, dict(engine=yade_engines(s, None, label), flaw=flaw, width=W, height=H)
    rb = RigidBodies(s)
    platen = yade_platen(rb, W / 2, H, W, spacing, platen_speed, platen_friction)
    filler = yade_filler(rb, flaw, mu_con, c_con, density=rock.density, blocked=filler_blocked) if variant == "filled" else None
    eng = yade_engines(s, rb, label)
    y0 = O.bodies[platen].state.pos[1]

    def axial_stress():
        return rb.force(platen)[1] / W             # the rock pushes the platen up: compression positive

    def axial_strain():
        return (y0 - O.bodies[platen].state.pos[1]) / H

    def advance(n):
        v = platen_speed * (min(1.0, O.time / ramp_time) if ramp_time > 0 else 1.0)
        O.bodies[platen].state.vel = (0, -v, 0)
        O.run(n, True)
    if ramp_time > 0:
        O.bodies[platen].state.vel = (0, 0, 0)     # at rest until the first advance()
    return s, dict(platen=platen, filler=filler, rigid=rb, engine=eng, flaw=flaw, width=W, height=H,
                   axial_stress=axial_stress, axial_strain=axial_strain, advance=advance)


# ------------------------------------------------------------------------------------------------
# Boundary checks (doc/boundaries.md)
def uniform_stress_block(dim, axis, side, kind="slip", cells=8, spacing=0.1, sigma=-40e6, damping=0.1, material=None):
    """Block [0, cells·l]^dim under a uniform normal stress σ [Pa] along `axis` (every particle starts at it),
    resting on a boundary plane of `kind` at its face `side` (−1 low, +1 high); the opposite face carries the
    consistent traction σ·n, the lateral faces are free: an exact equilibrium. material: default granite."""
    mat = material or rocks.granite()
    W = cells * spacing
    lo, hi = np.zeros(dim), np.full(dim, W)
    s = make_solver(lo, hi, spacing, margin=2)
    add_region(s, mat, lo, hi, ppc=2)
    st = np.zeros(4 if dim == 2 else 6)
    st[axis] = sigma
    if dim == 2:
        st[2] = mat.poisson * sigma                     # plane-strain σzz of the uniaxial state
    set_initial_stress(s, st)
    n = np.zeros(dim)
    n[axis] = -side                                     # outward normal of the loaded (opposite) face
    apply_face_traction(s, axis, -side, W if side < 0 else 0.0, sigma * n, 2)
    s.addBoundaryPlane(axis, side, 0.0 if side < 0 else W, kind)
    s.damping = damping
    return s


def fixed_free_bar(cells_x, length=1.0, cells_y=2, material=None, amplitude=0.01):
    """Bar [0, L] × [0, cells_y·l] fixed at x = 0 ('fixed' plane), free at x = L, between slip planes in y
    (1D strain), moving in its first mode v_x = a sin(πx/2L). Returns (solver, T = 4L/c_p [s], mode shape)."""
    h = length / cells_x
    s = make_solver((0.0, 0.0), (length, cells_y * h), h, margin=2)
    m = material or ElasticMat(young=1e9, poisson=0.25, density=1000.0)
    add_region(s, m, (0.0, 0.0), (length, cells_y * h), ppc=2)
    s.addBoundaryPlane(0, -1, 0.0, "fixed")
    s.addBoundaryPlane(1, -1, 0.0, "slip")
    s.addBoundaryPlane(1, 1, cells_y * h, "slip")
    shape = lambda x: np.sin(np.pi * x / (2 * length))
    s.view("v0")[:] = amplitude * shape(s.view("x0"))
    s.requestSort()
    return s, 4 * length / np.sqrt((m.bulk() + 4 * m.shear() / 3) / m.density), shape


def mode_period(solver, shape, t_end):
    """Mean period [s] of the modal momentum q = Σ m v_x shape(x) between its downward zero crossings
    (linearly interpolated), stepping `solver` to `t_end` [s]."""
    t, q = [], []
    while solver.time < t_end:
        solver.step()
        t.append(solver.time)
        q.append(np.sum(solver.view("mass") * solver.view("v0") * shape(solver.view("x0"))))
    t, q = np.array(t), np.array(q)
    k = np.nonzero((q[:-1] > 0) & (q[1:] <= 0))[0]
    if len(k) < 2:
        raise ValueError(f"t_end = {t_end} s holds fewer than two downward zero crossings of the mode")
    tz = t[k] + (t[k + 1] - t[k]) * q[k] / (q[k] - q[k + 1])
    return float(np.mean(np.diff(tz)))
