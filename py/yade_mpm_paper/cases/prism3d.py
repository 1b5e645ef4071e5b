"""A case only 3D can do (issue 22, item 4; doc/validation/three_d.md): a prism of Miao sandstone under uniaxial
compression by the YADE platen of the uniaxial flaw scene, with an inclined penny-shaped (disc) open flaw
at its centre — the 3D counterpart of paper Sec. 3.3's through flaw, with the 2D scene's proportions,
rock, flaw inclination and thickness, platen and base."""
import numpy as np

from yade_mpm import rocks
from yade_mpm.geometry import Disc, _number
from yade_mpm.scene import add_region, make_solver
from .loading import PLATEN_FRICTION, PLATEN_SPEED, yade_engines, yade_platen
from .uniaxial import UNIAXIAL_FLAW, UNIAXIAL_WIDTH, exclude_nodes_inside

PRISM_SIZE = (0.04, 0.08, 0.04)    # W × H × D [m]: x, y (loading axis), z; the 2D specimen's W/H = 1/3 made 1/2 (cost)
PRISM_SIDE_ROOM = 0.01             # grid beyond each free side face [m] (the runs stop after the peak)
PRISM_SYMMETRY = ("none", "z", "xz")
PRISM_VARIANTS = ("intact", "penny")


def penny_flaw(size=PRISM_SIZE, flaw=UNIAXIAL_FLAW, specimen_width=UNIAXIAL_WIDTH):
    """The disc flaw at the prism centre: diameter = the 2D flaw length scaled by the prism's width
    (25 mm of a 50 mm specimen → 20 mm of 40 mm), thickness = the 2D flaw width, its plane inclined as the
    2D flaw (30° from x, about z: normal (−sin β, cos β, 0)). A dict: disc (geometry.Disc), center, normal,
    radius, thickness [m], angle [rad], rim (the in-plane rim points, upper first: the 2D flaw's tips)."""
    length, fw, angle = flaw
    c = np.array(size) / 2
    n = np.array([-np.sin(angle), np.cos(angle), 0.0])
    u = np.array([np.cos(angle), np.sin(angle), 0.0])          # up-dip direction in the flaw plane
    a = 0.5 * length * size[0] / specimen_width
    return dict(disc=Disc(c, n, a, fw), center=c, normal=n, radius=a, thickness=fw, angle=angle,
                rim=(c + a * u, c - a * u), dip=u)


def penny_prism(variant, spacing, symmetry="none", ppc=2, material=None, platen_speed=PLATEN_SPEED, label="mpm",
                size=PRISM_SIZE, side_room=PRISM_SIDE_ROOM, flaw_nodes="excluded", contact_law=None):
    """The prism [0, W] × [0, H] × [0, D] (size) of ``rocks.miao2018_sandstone()`` (or `material`) on a
    free-slip base y = 0, loaded by the rigid frictionless YADE platen of ``uniaxial_flaw`` (moving down at
    `platen_speed` [m/s]); variant "penny": the disc flaw of ``penny_flaw`` cut out (an open flaw: its nodes
    excluded from the fits), "intact": none. symmetry: "none" (the whole prism), "z" (the half z ≥ D/2 with
    a slip plane on z = D/2: the disc's plane of symmetry), "xz" (intact only: the quarter x ≥ W/2, z ≥ D/2).
    flaw_nodes: "excluded" (default: the grid nodes inside the disc out of the fits, as the 2D open flaw) or "shared"
    (only the particles removed; the paper's construction, ``add_region(gap_nodes="shared")``). contact_law: the
    platen's contact law, "kinematic" or "penalty" (None: the declared default).
    Returns (solver, scene) with scene = dict(platen, rigid, engine, flaw (penny_flaw dict or None), size,
    modelled (the modelled part's lo, hi), axial_stress() [Pa, compression positive: the platen reaction over
    the modelled cross-section], axial_strain() [-])."""
    if variant not in PRISM_VARIANTS:
        raise ValueError(f"variant = {variant!r} must be one of {PRISM_VARIANTS}")
    if symmetry not in PRISM_SYMMETRY or (symmetry == "xz" and variant != "intact"):
        raise ValueError(f"symmetry = {symmetry!r} must be one of {PRISM_SYMMETRY} ('xz' only for 'intact': the inclined disc "
                         "is not symmetric about x = W/2)")
    if flaw_nodes not in ("excluded", "shared"):
        raise ValueError(f"flaw_nodes = {flaw_nodes!r} must be 'excluded' or 'shared'")
    spacing = _number(spacing, "spacing", "m", positive=True)
    W, H, D = size
    flaw = penny_flaw(size) if variant == "penny" else None
    top = min(W, D) / 10 if flaw is None else min(min(W, D) / 10, 2 * flaw["thickness"])
    if not spacing <= top:
        raise ValueError(f"spacing = {spacing!r} m must be in (0, {top:g}] m: 10 cells across the prism"
                         + ("" if flaw is None else f" and the {flaw['thickness'] * 1e3:g} mm disc at least one particle layer thick"))
    cells = np.array(size) / spacing
    if np.any(np.abs(cells - np.round(cells)) > 1e-9) or np.any(np.round(cells) % 2):
        raise ValueError(f"spacing = {spacing!r} m must divide the prism {tuple(size)} m into an even number of cells per axis")
    from yade import O
    from yade_mpm.bodies import RigidBodies
    rock = material or rocks.miao2018_sandstone()
    lo = np.array([W / 2 if symmetry == "xz" else 0.0, 0.0, D / 2 if symmetry != "none" else 0.0])
    hi = np.array([W, H, D])
    room = np.array([1.0, 0.0, 1.0]) * np.ceil(_number(side_room, "side_room", "m", positive=True) / spacing - 1e-9) * spacing
    # whole cells of room: the prism's faces (and the symmetry planes) stay on node lines
    s = make_solver(lo - room * (lo == 0), hi + room, spacing, margin=2)
    add_region(s, rock, lo, hi, ppc=ppc, holes=[flaw["disc"]] if flaw else [], gap_nodes=flaw_nodes)
    s.addBoundaryPlane(1, -1, 0.0, "slip")
    if symmetry != "none":
        s.addBoundaryPlane(2, -1, D / 2, "slip")
    if symmetry == "xz":
        s.addBoundaryPlane(0, -1, W / 2, "slip")
    if flaw and flaw_nodes == "excluded":
        exclude_nodes_inside(s, flaw["disc"])
    O.reset()
    rb = RigidBodies(s)
    platen = yade_platen(rb, W / 2, H, W, spacing, platen_speed, PLATEN_FRICTION, law=contact_law)
    eng = yade_engines(s, rb, label)
    y0 = O.bodies[platen].state.pos[1]
    area = (hi[0] - lo[0]) * (hi[2] - lo[2])

    def axial_stress():
        return rb.force(platen)[1] / area

    def axial_strain():
        return (y0 - O.bodies[platen].state.pos[1]) / H
    return s, dict(platen=platen, rigid=rb, engine=eng, flaw=flaw, size=size, modelled=(lo, hi),
                   axial_stress=axial_stress, axial_strain=axial_strain)


# ------------------------------------------------------------------------------------- reading a run
def disc_coordinates(x, flaw):
    """Positions x (N, 3) [m] in the disc's frame: ρ [m] (distance from the disc axis), φ [deg] (azimuth in the
    disc plane: 0 = the upper in-plane rim point, the 2D flaw's upper tip; ±90 = the rim points on the z axis,
    where the disc edge meets the compression out of plane; ±180 = the lower in-plane rim point), h [m]
    (signed distance from the disc's mid-plane, + on the side of its normal)."""
    r = np.asarray(x, float) - flaw["center"]
    h = r @ flaw["normal"]
    a, b = r @ flaw["dip"], r[:, 2]
    return np.hypot(a, b), np.degrees(np.arctan2(b, a)), h


def damage_onset(x, damage, flaw, threshold):
    """The damaged particles (damage ≥ threshold) as a list of dicts (ρ/a, φ [deg], h [m], position [m]),
    nearest the rim first; [] if none."""
    k = np.nonzero(np.asarray(damage) >= threshold)[0]
    if len(k) == 0:
        return []
    rho, phi, h = disc_coordinates(x[k], flaw)
    order = np.argsort(np.abs(rho / flaw["radius"] - 1))
    return [dict(rho_over_a=float(rho[i] / flaw["radius"]), phi_deg=float(phi[i]), h_m=float(h[i]), pos_m=x[k[i]].tolist())
            for i in order]


def rim_profile(x, damage, flaw, spacing, bins=12, cut=0.99):
    """How damage wraps around the rim: for each of `bins` azimuth sectors (φ from −180° to 180°) the share
    of the particles in the ring a ≤ ρ ≤ a + 2l (|h| ≤ 3l) with D ≥ cut, and the largest distance |h| [m] from
    the disc plane reached by D ≥ cut particles with a − l ≤ ρ ≤ 2a and |h| ≤ 2a in the sector (the wing crack's reach).
    Returns a list of dicts (phi_lo_deg, phi_hi_deg, ring_share, wing_reach_m)."""
    rho, phi, h = disc_coordinates(x, flaw)
    a, d = flaw["radius"], np.asarray(damage) >= cut
    edges = np.linspace(-180, 180, bins + 1)
    out = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        sec = (phi >= lo) & (phi < hi)
        ring = sec & (rho >= a) & (rho <= a + 2 * spacing) & (np.abs(h) <= 3 * spacing)
        wing = sec & d & (rho >= a - spacing) & (rho <= 2 * a) & (np.abs(h) <= 2 * a)
        out.append(dict(phi_lo_deg=float(lo), phi_hi_deg=float(hi), ring_share=float(d[ring].mean()) if ring.any() else float("nan"),
                        wing_reach_m=float(np.abs(h[wing]).max()) if wing.any() else 0.0))
    return out
