"""The arch-shaped tunnel of paper Sec. 4 (Fig. 16), Pan et al. (2020b): the specimen, its opening and
flaw, the full scene with the YADE platen and filler, and the names of the places around the opening
that the crack analytics (``yade_mpm.analysis``) report."""
import math

import numpy as np

from yade_mpm import rocks
from yade_mpm.geometry import Box, Circle, _number, rotated_rectangle
from yade_mpm.scene import add_region, make_solver
from .loading import PLATEN_FRICTION, PLATEN_SPEED, yade_engines, yade_filler, yade_platen

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
                         holes=(), grid_shift=None):
    """The tunnel specimen [0, width]² with the arch opening (and further `holes`), free-slip walls on
    `walls` (the paper's four sides minus the loaded top, where the caller puts a platen or a traction).
    material: default ``rocks.pan2020_sandstone()``. The opening must lie inside the specimen with at
    least one cell of rock around it: width ≥ 40 mm + 2·spacing, floor ≥ spacing and
    floor + 45 mm (rectangle and roof) ≤ width − spacing. grid_shift: (fx, fy) fractions of a cell by which the
    grid is moved against the specimen (``make_solver``'s shift), each 0 or 0.5 so that the slip walls stay on node
    or half-node lines (None: none). Returns the solver."""
    spacing = _number(spacing, "spacing", "m", positive=True)
    width, floor = _number(width, "width", "m", positive=True), _number(floor, "floor", "m")
    if width < TUNNEL_RECT[0] + 2 * spacing:
        raise ValueError(f"width = {width:g} m: the specimen must be at least the opening's width {TUNNEL_RECT[0]:g} m plus a cell "
                         f"of rock on each side, width ≥ {TUNNEL_RECT[0] + 2 * spacing:g} m")
    top = TUNNEL_RECT[1] + TUNNEL_RADIUS                  # the opening's height above its floor
    if not spacing <= floor <= width - spacing - top:
        raise ValueError(f"floor = {floor:g} m puts the opening (height {top:g} m) outside or through the {width:g} m specimen: "
                         f"allowed floor in [{spacing:g}, {width - spacing - top:g}] m (one cell of rock below and above)")
    planes = {"left": (0, -1, 0.0), "right": (0, 1, width), "bottom": (1, -1, 0.0), "top": (1, 1, width)}
    bad = [w for w in walls if w not in planes]
    if bad:
        raise ValueError(f"walls: unknown {bad}; allowed {sorted(planes)}")
    mat = material or rocks.pan2020_sandstone()
    s = make_solver((0, 0), (width, width), spacing, margin=2, shift=grid_shift)
    add_region(s, mat, (0, 0), (width, width), ppc=ppc, holes=list(arch_tunnel_holes(width, floor)) + list(holes))
    for w in walls:
        axis, side, pos = planes[w]
        s.addBoundaryPlane(axis, side, pos, "slip")
    return s


# The flaw of Figs. 16b, c. The paper gives its size (60 mm × 2 mm, "adjacent to the tunnel", on its
# left) but not its position or angle; they are chosen from the description of Fig. 19 (the flaw
# hinders the load path from the top to the left waist; stress concentrates at the flaw toe, next to
# the left spandrel; a crack links the toe to the tunnel corner) — see doc/validation/tunnel.md. One place only:
FLAW_LENGTH = 0.06                 # [m]
FLAW_WIDTH = 0.002                 # [m]
FLAW_ANGLE_DEG = 60.0              # inclination to the horizontal [°]; rises to the left, away from the tunnel
FLAW_ANGLE = math.radians(FLAW_ANGLE_DEG)   # the same [rad]
FLAW_TOE_GAP = 0.010               # horizontal rock bridge from the toe (lower end) to the left wall [m]
FLAW_TOE_HEIGHT = TUNNEL_RECT[1]   # toe height above the opening's floor [m]: spandrel height (top of the walls)
FLAW_TOE = (TUNNEL_WIDTH / 2 - TUNNEL_RECT[0] / 2 - FLAW_TOE_GAP, TUNNEL_FLOOR + FLAW_TOE_HEIGHT)  # [m]

# Loading and contact of Sec. 4 (platen speed and friction, filler χ: cases.loading)
TUNNEL_END_TIME = 0.02             # loading time [s] (2 mm of platen displacement)
FILLER_FRICTION = 0.6              # filler–rock μ_con [-] (the paper's rigid-filled case of Sec. 3.3, Figs. 14–15)
TUNNEL_CASES = ("intact", "open_flaw", "filled_flaw", "grout_flaw")
TUNNEL_MAX_SPACING = 1.25 * FLAW_WIDTH   # coarsest grid [m]: the flaw still cuts a full row of particles (ppc = 2)
TUNNEL_INTACT_MAX_SPACING = 0.005        # coarsest grid of the intact case [m]: 8 cells across the 40 mm opening



def tunnel_flaw(toe=FLAW_TOE, length=FLAW_LENGTH, width=FLAW_WIDTH, angle=FLAW_ANGLE):
    """The flaw as a dict: toe (lower end, centre of the short side) and tip (upper end) [m], centre,
    unit direction from toe to tip, normal, length, width [m], angle [rad] and the Polygon."""
    u = np.array([-math.cos(angle), math.sin(angle)])        # from the toe up and to the left
    toe = np.asarray(toe, float)
    center = toe + 0.5 * length * u
    return dict(toe=toe, tip=toe + length * u, center=center, direction=u, normal=np.array([-u[1], u[0]]),
                length=length, width=width, angle=angle,
                polygon=rotated_rectangle(center, length, width, math.atan2(u[1], u[0])))


def _flaw_clear(angle, spacing):
    """Does the flaw at `angle` [rad] (default toe and size) keep one cell `spacing` of rock to every face and the opening?"""
    f = tunnel_flaw(angle=angle)
    u, n = f["direction"], f["normal"] * 0.5 * f["width"]
    p = f["toe"] + np.linspace(0, f["length"], 41)[:, None] * u
    p = np.vstack([p + n, p - n])
    return bool(np.all((p >= spacing) & (p <= TUNNEL_WIDTH - spacing)) and np.all(tunnel_opening_distance(p) >= spacing))


def tunnel_flaw_at(floor=TUNNEL_FLOOR, angle=FLAW_ANGLE, toe_gap=FLAW_TOE_GAP, toe_height=FLAW_TOE_HEIGHT):
    """``tunnel_flaw()`` for an opening with its floor at `floor` [m]: the toe `toe_gap` [m] left of the
    left wall, `toe_height` [m] above the floor, in [0, 25 mm] (the wall's height; default 25 mm, spandrel
    height), inclined `angle` [rad] (default FLAW_ANGLE)."""
    angle = _number(angle, "flaw_angle", "rad")
    toe_gap = _number(toe_gap, "flaw_toe_gap", "m", positive=True)
    toe_height = _number(toe_height, "flaw_toe_height", "m")
    if not 0 <= toe_height <= TUNNEL_RECT[1]:
        raise ValueError(f"flaw_toe_height = {toe_height!r} m must be in [0, {TUNNEL_RECT[1]}] m (beside the left wall)")
    return tunnel_flaw(toe=(TUNNEL_WIDTH / 2 - TUNNEL_RECT[0] / 2 - toe_gap, floor + toe_height), angle=angle)


def arch_tunnel(case, spacing, material=None, grout=None, ppc=2, platen_speed=PLATEN_SPEED,
                platen_friction=PLATEN_FRICTION, filler_friction=FILLER_FRICTION, flaw_angle=FLAW_ANGLE, label="mpm",
                floor=TUNNEL_FLOOR, flaw_toe_gap=FLAW_TOE_GAP, flaw_toe_height=FLAW_TOE_HEIGHT, contact_law=None,
                grid_shift=None):
    """The scene of paper Sec. 4 in a fresh YADE scene (O.reset()): the 150 × 150 mm specimen with the
    arch tunnel, free-slip left, right and bottom walls, a rigid top platen (a YADE Box with blocked
    DOFs moving down at `platen_speed` [m/s], PTS contact with μ = platen_friction) and
      case "intact"       no flaw,
           "open_flaw"    the flaw (``tunnel_flaw()``) cut out,
           "filled_flaw"  the flaw cut out and filled by a free rigid YADE Box (PTS contact, μ = filler_friction),
           "grout_flaw"   the flaw filled with particles of the elastic `grout` (default ``rocks.cement_grout()``),
                          bonded to the rock through the shared grid.
    spacing: grid spacing l [m] (paper 1 mm); material: the rock (default ``rocks.pan2020_sandstone()``);
    flaw_angle: the flaw's inclination [rad] about its toe (FLAW_ANGLE; it must leave a cell of rock to every face).
    floor [m]: height of the opening's floor (default TUNNEL_FLOOR = 55 mm; the paper gives none, a centred
    opening has 52.5 mm); flaw_toe_gap, flaw_toe_height [m]: the toe's distance from the left wall and height above
    the floor (``tunnel_flaw_at``; neither is given in the paper).
    contact_law: the platen and filler contact law, "kinematic" or "penalty" (None: the declared default).
    grid_shift: the grid moved against the specimen by (fx, fy) cells, each 0 or 0.5 (``arch_tunnel_specimen``).
    O.engines = [ForceResetter, the MpmEngine (labelled `label`, with the bodies), NewtonIntegrator].
    Returns (solver, bodies): bodies = dict(platen=YADE id, filler=YADE id or None, rigid=RigidBodies,
    engine=MpmEngine, flaw=tunnel_flaw() or None, width=specimen width [m],
    axial_stress() -> platen reaction / width [Pa, compression positive],
    platen_displacement() -> downward platen displacement since the build [m])."""
    if case not in TUNNEL_CASES:
        raise ValueError(f"case = {case!r} must be one of {TUNNEL_CASES}")
    spacing = _number(spacing, "spacing", "m", positive=True)
    top = TUNNEL_INTACT_MAX_SPACING if case == "intact" else TUNNEL_MAX_SPACING
    if not spacing <= top:
        raise ValueError(f"spacing = {spacing!r} m must be in (0, {top}] m " + ("(8 cells across the 40 mm opening)" if case == "intact" else
                         f"(the {FLAW_WIDTH * 1e3:g} mm flaw must cut at least one full particle row, particle spacing l/2)"))
    platen_speed = _number(platen_speed, "platen_speed", "m/s", positive=True)
    flaw_angle = _number(flaw_angle, "flaw_angle", "rad")
    if case != "intact" and not _flaw_clear(flaw_angle, spacing):
        ok = [d for d in np.arange(0.0, 180.01, 0.5) if _flaw_clear(math.radians(d), spacing)] or [math.nan]
        raise ValueError(f"flaw_angle = {math.degrees(flaw_angle):.6g}° puts the {FLAW_LENGTH * 1e3:g} mm flaw from its toe at "
                         f"{FLAW_TOE[0] * 1e3:g}, {FLAW_TOE[1] * 1e3:g} mm within one cell of a face or of the opening; allowed at "
                         f"l = {spacing * 1e3:g} mm: [{ok[0]:g}, {ok[-1]:g}]°")
    from yade import O
    from yade_mpm.bodies import RigidBodies

    W = TUNNEL_WIDTH
    flaw = tunnel_flaw_at(floor, flaw_angle, flaw_toe_gap, flaw_toe_height) if case != "intact" else None
    rock = material or rocks.pan2020_sandstone()
    holes = [flaw["polygon"]] if flaw is not None else []
    s = arch_tunnel_specimen(spacing, rock, ppc, floor=floor, holes=holes, grid_shift=grid_shift)
    if case == "grout_flaw":
        add_region(s, grout or rocks.cement_grout(), (0, 0), (W, W), ppc=ppc, keep=flaw["polygon"].contains)
    O.reset()
    rb = RigidBodies(s)
    platen = yade_platen(rb, W / 2, W, W, spacing, platen_speed, platen_friction, law=contact_law)
    filler = (yade_filler(rb, flaw, filler_friction, density=rock.density, law=contact_law)  # weighs as the rock
              if case == "filled_flaw" else None)
    eng = yade_engines(s, rb, label)
    y0 = O.bodies[platen].state.pos[1]

    def axial_stress():
        return rb.force(platen)[1] / W             # the rock pushes the platen up: compression positive

    def platen_displacement():
        return y0 - O.bodies[platen].state.pos[1]
    return s, dict(platen=platen, filler=filler, rigid=rb, engine=eng, flaw=flaw, width=W, floor=floor,
                   axial_stress=axial_stress, platen_displacement=platen_displacement)


def tunnel_location(point, flaw=None, floor=TUNNEL_FLOOR):
    """Name of the part of the tunnel (or flaw) nearest a point [m]: "floor", "left/right corner"
    (where the walls meet the floor), "left/right wall" (the waist), "left/right spandrel" (the arch
    shoulders, more than 30° from the vertical), "crown", "flaw toe", "flaw tip", "flaw face", or
    "rock away from the opening" (more than 10 mm from the opening and the flaw)."""
    x, y = float(point[0]), float(point[1])
    cx = TUNNEL_WIDTH / 2
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


def tunnel_where(points, flaw=None, floor=TUNNEL_FLOOR):
    """Where a set of points [m] (N, 2) lies: its most common ``tunnel_location``, or "A and B" when a
    second place holds at least a quarter as many points (damage on both sides); None for no points."""
    if len(points) == 0:
        return None
    names = [tunnel_location(p, flaw, floor) for p in points]
    uniq, cnt = np.unique(names, return_counts=True)
    order = np.argsort(-cnt)
    return " and ".join([str(uniq[k]) for k in order if cnt[k] >= 0.25 * cnt.max()][:2])


# crack analytics of the tunnel (doc/validation/tunnel.md)
BAND_GAP = 5e-3                    # shear bands are looked for beyond this distance from the opening and the flaw [m]
BAND_FRACTION, BAND_MIN = 0.5, 5e-4  # band particles: ε̄p ≥ max(BAND_MIN, BAND_FRACTION × its 99th percentile there)
TOE_RADIUS = 4e-3                  # the failed zone "from the flaw toe" starts within this distance of it [m]


def tunnel_report(fields, lattice, flaw, soft_end, rock=None, floor=TUNNEL_FLOOR):
    """``analysis.crack_report`` of a tunnel state (fields by id: damage, plastic_strain, mass; lattice of
    the initial positions; flaw: ``tunnel_flaw()`` or None; soft_end: ε̄p of a shear crack; rock: the
    particles that are rock, not grout), with the places named (``tunnel_location``). Returns
    (report, spalled mask): a JSON-able dict with symmetry_damage, symmetry_plastic, damaged_fraction,
    softened_fraction, spalled_area_mm2, spalled_mass_kg_per_m, spalled_particles, spalled_fragments,
    spalling_at, band_threshold, bands (each with side and location), cracks, and with a flaw toe_damaged,
    toe_softened, toe_link_to_opening, toe_plastic_link_to_opening (where the zone from the toe
    reaches the opening), toe_failed_gap_mm and toe_failed_nearest (how far from the opening the failed
    zone from the toe ends [mm], 0 = it reaches it, and the place of the opening nearest to it)."""
    from yade_mpm import analysis
    x0 = lattice.x0
    seg = None if flaw is None else (flaw["toe"], flaw["tip"])
    r = analysis.crack_report(fields, lattice, arch_tunnel_holes(floor=floor), soft_end, rock=rock, axis_x=TUNNEL_WIDTH / 2, flaw=seg,
                              point=None if flaw is None else flaw["toe"], band_gap=BAND_GAP, band_fraction=BAND_FRACTION,
                              band_floor=BAND_MIN, point_radius=TOE_RADIUS, opening_dist=tunnel_opening_distance(x0, floor=floor))
    where = lambda pts: tunnel_where(pts, flaw, floor)
    for b in r["bands"] + r["cracks"]:
        b["side"] = "left" if b["centroid"][0] < TUNNEL_WIDTH / 2 else "right"
        b["location"] = tunnel_location(b["centroid"], flaw, floor)
    sp = r["spalled"]
    out = {k: r[k] for k in ("symmetry_damage", "symmetry_plastic", "damaged_fraction", "softened_fraction")}
    out.update(spalled_area_mm2=sp["area"] * 1e6, spalled_mass_kg_per_m=sp["mass"], spalled_particles=int(sp["mask"].sum()),
               spalled_fragments=sp["fragments"], spalling_at=where(x0[r["surface"]]),
               band_threshold=r["band_threshold"], bands=r["bands"][:6], cracks=r["cracks"][:6])
    out.update(tunnel_fidelity(fields, lattice, sp["mask"], flaw, floor, rock))
    if flaw is not None:
        out.update(toe_damaged=r["point_damaged"], toe_softened=r["point_softened"],
                   toe_link_to_opening=where(x0[r["point_failed_reach"]]),
                   toe_failed_gap_mm=None if r["point_failed_gap"] is None else r["point_failed_gap"] * 1e3,
                   toe_failed_nearest=None if r["point_failed_gap_at"] is None else tunnel_location(x0[r["point_failed_gap_at"]], None, floor),
                   toe_plastic_link_to_opening=where(x0[r["point_plastic_reach"]]))
    return out, sp["mask"]


def tunnel_fidelity(fields, lattice, spalled_mask, flaw=None, floor=TUNNEL_FLOOR, rock=None):
    """The measures of the fidelity table (Figs. 18–19) for one tunnel state: spalled area by place
    (``tunnel_location``) [mm²]; the waists' inward displacement (mean and 90th percentile [mm] of the
    rock within 3 mm of each side wall, positive into the opening; needs fields["pos"]); the plastic
    zones beside the opening (ε̄p ≥ PLASTIC_ZONE_FRACTION × its 99th percentile in the rock, the largest
    8-connected cluster on each side: area [mm²], centroid [mm], fill of its bounding box — ½ a
    triangle, 1 a rectangle)."""
    from yade_mpm import analysis
    x0, dp = lattice.x0, lattice.dp
    rock = np.ones(len(x0), bool) if rock is None else np.asarray(rock, bool)
    places = {}
    for p in x0[spalled_mask]:
        k = tunnel_location(p, flaw, floor)
        places[k] = places.get(k, 0.0) + dp * dp * 1e6
    out = dict(spalled_by_place_mm2={k: round(v, 1) for k, v in sorted(places.items())})
    cx, hw = TUNNEL_WIDTH / 2, TUNNEL_RECT[0] / 2
    band = (x0[:, 1] > floor) & (x0[:, 1] < floor + TUNNEL_RECT[1]) & rock
    if "pos" in fields:
        ux = (np.asarray(fields["pos"], float) - x0)[:, 0]
        for side, sign, wall in (("left", 1.0, cx - hw), ("right", -1.0, cx + hw)):
            m = band & (np.abs(x0[:, 0] - wall) < 3e-3) & ((x0[:, 0] - wall) * sign < 0)
            v = sign * ux[m] * 1e3
            out[f"{side}_waist_inward_mm"] = dict(mean=float(v.mean()), p90=float(np.percentile(v, 90))) if m.any() else None
    e = np.asarray(fields["plastic_strain"], float)
    ref = float(np.percentile(e[rock], 99)) if rock.any() else 0.0
    zones = {}
    if ref > 0:
        for b in analysis.bands(rock & (e >= PLASTIC_ZONE_FRACTION * ref), lattice, min_sites=12):
            side = "left" if b["centroid"][0] < cx else "right"
            if side not in zones:
                zones[side] = dict(area_mm2=b["sites"] * dp * dp * 1e6, centroid_mm=[c * 1e3 for c in b["centroid"]],
                                   fill=b["fill"], bbox_mm=[c * 1e3 for c in b["bbox"]], angle_deg=b["angle_deg"])
    out["plastic_zones"] = zones
    return out


PLASTIC_ZONE_FRACTION = 0.2        # a plastic zone: ε̄p ≥ this share of the rock's 99th percentile (the coloured area of Fig. 18a)
