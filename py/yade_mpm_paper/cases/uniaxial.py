"""Uniaxial compression of a sandstone specimen with a flaw, paper Sec. 3.3 (Figs. 10–15), Miao et al.
(2018) sandstone: the specimen, the open or rigid-filled flaw, the YADE platen."""
import math

import numpy as np

from yade_mpm import rocks
from yade_mpm.scene import add_region, is_thin, make_solver
from yade_mpm.geometry import _integer, _number
from .loading import PLATEN_FRICTION, PLATEN_SPEED, blocked_dofs, yade_engines, yade_filler, yade_platen
from .tunnel import tunnel_flaw

UNIAXIAL_WIDTH = 0.05              # specimen width [m]
UNIAXIAL_HEIGHT = 0.15             # specimen height [m]
UNIAXIAL_FLAW = (0.025, 0.002, math.radians(30.0))   # flaw length, width [m], inclination [rad], at the centre
UNIAXIAL_PAPER_SPACING = 0.5e-3    # the paper's grid [m]
UNIAXIAL_VARIANTS = ("intact", "open", "filled")
UNIAXIAL_MAX_SPACING = UNIAXIAL_WIDTH / 10   # coarsest grid [m]: 10 cells across the specimen (a coarser one ran with 3–5 particles)
UNIAXIAL_SIDE_ROOM = 0.05          # grid beyond each free side face and above the top [m]: spalled fragments (measured up to 14 m/s) stay on the grid
UNIAXIAL_SLAB_CELLS = 2            # thickness of the 3D slab (slab_cells > 0) in grid cells [-] (doc/validation/three_d.md)


def uniaxial_flaw_geometry(width=UNIAXIAL_WIDTH, height=UNIAXIAL_HEIGHT, flaw=UNIAXIAL_FLAW):
    """The centred flaw as a dict like ``tunnel_flaw`` (toe, tip, centre, direction, normal, polygon…)."""
    length, fw, angle = flaw
    u = np.array([-math.cos(angle), math.sin(angle)])
    center = np.array([width / 2, height / 2])
    return tunnel_flaw(toe=center - 0.5 * length * u, length=length, width=fw, angle=angle)


def exclude_nodes_inside(solver, polygon):
    """Take the physical grid nodes inside `polygon` out of the WLS fits (user exclusion bit) when the flaw is
    thinner than the stencil (scene.is_thin: < 4 cells): its faces then do not share those nodes — the same
    nodes a rigid filler of the flaw covers (contact bit). A flaw at least 4 cells wide (the paper's 2 mm flaw
    on its 0.5 mm grid) keeps its faces apart by itself and gets no exclusion, the paper's construction: nodes
    excluded there would leave a particle that enters the gap (a fragment at a flaw end, the closing flaw) with
    no active node for its fit — the 0.5 mm open-flaw run stopped so at 5.46 ms. Returns the number of nodes
    excluded."""
    if not is_thin(polygon, solver.spacing):
        return 0
    xn = solver._nodePositions()
    lo, hi = np.asarray(solver.origin), np.asarray(solver.origin) + solver.spacing * np.asarray(solver.cells)
    inside = polygon.contains(xn) & np.all((xn > lo + 1e-12) & (xn < hi - 1e-12), axis=1)
    for i in np.nonzero(inside)[0]:
        solver._setNodeExcluded(int(i), True)
    return int(inside.sum())


def uniaxial_flaw(variant, spacing, mu_con=0.0, c_con=0.0, ppc=2, material=None, platen_speed=PLATEN_SPEED,
                  platen_friction=PLATEN_FRICTION, label="mpm", with_bodies=True, filler_blocked="zXY",
                  ramp_time=0.0, end_cap_cells=0, side_room=UNIAXIAL_SIDE_ROOM, slab_cells=0,
                  platen_d0=None, contact_law=None, grid_shift=None):
    """The scene of paper Sec. 3.3 in a fresh YADE scene (O.reset()): a 50 × 150 mm specimen of
    ``rocks.miao2018_sandstone()`` (or `material`) on a free-slip base (y = 0), loaded by a rigid top
    platen (a YADE Box, blockedDOFs 'xyzXYZ', moving down at `platen_speed` [m/s], frictionless: the
    free-slip top), and
      variant "intact"  no flaw,
              "open"    the 25 × 2 mm flaw inclined 30° at the centre cut out (nodes inside excluded when the flaw is
                        under 4 cells wide: exclude_nodes_inside),
              "filled"  the flaw cut out and filled by a free rigid YADE Box (rock density) in PTS
                        contact with μ_con = mu_con [-] and c_con = c_con [Pa].
    filler_blocked: the filler's blockedDOFs ('zXYZ' keeps it from rotating; see doc/reference/contact.md).
    ramp_time [s] ≥ 0: the platen speed rises linearly from 0 over this time when the run is driven by
    scene["advance"](n) (speed updated before each call: a staircase with n-step treads); 0 (default) starts at
    full speed. end_cap_cells ≥ 0: the particles within this many cells of the base and of the platen get a
    Grady–Kipp activation strain ε_D⁰ = 0.99 (Eq. 37) that tension never reaches — "end caps", so the layer
    under the penalty contact does not crack first (doc/validation/mpm_vs_bonded.md); 0 (default) = none.
    side_room [m] > 0: grid beyond each free side face and above the specimen's top, beside the platen (default
    UNIAXIAL_SIDE_ROOM): a top corner that fails is squeezed out sideways at up to 10 m/s and rises past the
    platen's edge (the 0.5 mm, c_con = 5 MPa run lost such a particle 1 mm above the top at 10.9 ms when the grid
    ended 2 cells above the specimen).
    slab_cells ≥ 0: 0 (default) = 2D plane strain; n > 0 = the same specimen as a 3D slab n cells thick
    (z ∈ [0, n·l]) between two slip (symmetry) planes on its front and back faces, i.e. plane strain
    imposed by the boundary instead of the kinematics (doc/validation/three_d.md); the flaw is a through prism and the
    platen spans the slab (1 m along z); variants "intact" and "open". The 2D parameters above hold unchanged.
    platen_d0: the platen's contact detection distance [m] (None, default: half the particle edge ½V^(1/D) of
    the current volume, which differs between 2D and 3D once the volume changes; a number makes a slab
    and the 2D run identical to roundoff, doc/validation/three_d.md).
    contact_law: the law of the platen and filler contacts, "kinematic" or "penalty" (None: the declared default;
    doc/reference/contact.md).
    grid_shift: (fx, fy) fractions of a cell by which the grid is moved against the specimen (``make_solver``'s
    shift; None: none): fy must be 0 or 0.5 (the slip base stays on a node or half-node line).
    spacing: grid spacing l [m] (paper 0.5 mm); ppc particles per cell per axis. with_bodies=False builds
    the same particles with no YADE bodies at all (the benchmark's reference for the contact cost).
    Returns (solver, scene) with scene = dict(platen, filler (YADE ids; filler None unless filled),
    rigid (RigidBodies), engine (MpmEngine), flaw (dict or None), width, height, thickness [m] (2D: 1 m),
    axial_stress() -> platen reaction / (width × thickness) [Pa, compression positive],
    axial_strain() -> platen displacement / height [-],
    advance(n) -> sets the (ramped) platen speed for the time O.time, then runs n steps)."""
    if variant not in UNIAXIAL_VARIANTS:
        raise ValueError(f"variant = {variant!r} must be one of {UNIAXIAL_VARIANTS}")
    W, H = UNIAXIAL_WIDTH, UNIAXIAL_HEIGHT
    flaw = uniaxial_flaw_geometry() if variant != "intact" else None
    spacing = _number(spacing, "spacing", "m", positive=True)
    top = UNIAXIAL_MAX_SPACING if flaw is None else min(UNIAXIAL_MAX_SPACING, 2 * flaw["width"])
    if not spacing <= top:
        raise ValueError(f"spacing = {spacing!r} m must be in (0, {top:g}] m: " + ("the specimen must be at least 10 cells wide"
                         if flaw is None else f"the {flaw['width'] * 1e3:g} mm flaw must cut at least one full particle row"))
    platen_speed = _number(platen_speed, "platen_speed", "m/s", positive=True)
    ramp_time = _number(ramp_time, "ramp_time", "s")
    if ramp_time < 0:
        raise ValueError(f"ramp_time = {ramp_time!r} s must be a finite number ≥ 0")
    end_cap_cells = _integer(end_cap_cells, "end_cap_cells", 0, math.ceil(H / (2 * spacing)) - 1)
    side_room = _number(side_room, "side_room", "m", positive=True)
    slab_cells = _integer(slab_cells, "slab_cells", 0, 64)
    if slab_cells and variant == "filled":         # the 1 m filler box would carry 1 m of mass for an n·l slab
        raise ValueError(f"slab_cells = {slab_cells}: the 3D slab is built for the variants 'intact' and 'open' only (got 'filled')")
    T = slab_cells * spacing if slab_cells else 1.0   # thickness [m]: the 2D forces are per metre
    z = (0.0,) if slab_cells else ()              # the slab's z range: [0, T]
    blocked_dofs(filler_blocked, "filler_blocked")
    from yade import O
    from yade_mpm.bodies import RigidBodies
    rock = material or rocks.miao2018_sandstone()
    side = side_room                               # grid room beside the free faces for spalled fragments
    zt = (T,) if slab_cells else ()
    s = make_solver((-side, 0) + z, (W + side, H + side) + zt, spacing, margin=2, shift=grid_shift)   # room above too: fragments rise beside the platen
    add_region(s, rock, (0, 0) + z, (W, H) + zt, ppc=ppc, holes=[flaw["polygon"]] if flaw is not None else [])
    s.addBoundaryPlane(1, -1, 0.0, "slip")
    if slab_cells:                                 # front and back faces: slip (symmetry) planes
        s.addBoundaryPlane(2, -1, 0.0, "slip")
        s.addBoundaryPlane(2, 1, T, "slip")
    if end_cap_cells > 0:                          # end caps: ε_D⁰ = 0.99 (Eq. 37) near the base and the platen
        y, e0 = s.view("x1"), s.view("eps0")
        e0[(y < end_cap_cells * spacing) | (y > H - end_cap_cells * spacing)] = 0.99
        del y, e0
    if variant == "open":
        exclude_nodes_inside(s, flaw["polygon"])
    O.reset()
    if not with_bodies:
        return s, dict(engine=yade_engines(s, None, label), flaw=flaw, width=W, height=H, thickness=T)
    rb = RigidBodies(s)
    platen = yade_platen(rb, W / 2, H, W, spacing, platen_speed, platen_friction, d0=platen_d0, law=contact_law)
    filler = (yade_filler(rb, flaw, mu_con, c_con, density=rock.density, blocked=filler_blocked, law=contact_law)
              if variant == "filled" else None)
    eng = yade_engines(s, rb, label)
    y0 = O.bodies[platen].state.pos[1]

    def axial_stress():
        return rb.force(platen)[1] / (W * T)       # the rock pushes the platen up: compression positive

    def axial_strain():
        return (y0 - O.bodies[platen].state.pos[1]) / H

    def advance(n):
        v = platen_speed * (min(1.0, O.time / ramp_time) if ramp_time > 0 else 1.0)
        O.bodies[platen].state.vel = (0, -v, 0)
        O.run(n, True)
    if ramp_time > 0:
        O.bodies[platen].state.vel = (0, 0, 0)     # at rest until the first advance()
    return s, dict(platen=platen, filler=filler, rigid=rb, engine=eng, flaw=flaw, width=W, height=H, thickness=T,
                   axial_stress=axial_stress, axial_strain=axial_strain, advance=advance)
