"""Scene builders of the reference cases, written once: scripts, tests and benchmarks build their
scenes here and keep only their command line and analysis.

    circular_opening(spacing, ...)   paper Sec. 3.1: holed block under biaxial in-situ stress
    line_crack(size, spacing, ...)   paper Sec. 3.2: pressurised line ("penny-shaped") crack
    arch_tunnel_holes(...)           paper Sec. 4: the arch-shaped tunnel opening (geometry only)
    arch_tunnel(spacing, ...)        the tunnel specimen with its opening and slip walls (no top load)

Quantities are SI; stresses are tension positive inside the solver.
"""
import numpy as np

from . import rocks
from .geometry import Box, Circle
from .scene import add_region, apply_face_traction, apply_traction, get, make_solver, set_initial_stress

# ------------------------------------------------------------------------------------------------
# Circular opening, paper Sec. 3.1 (Figs. 3-5)
OPENING_CENTER = 2.5        # hole centre x = y [m]
OPENING_RADIUS = 0.1        # a [m] (diameter 0.2 m)
OPENING_SXX = 20e6          # far-field compression σxx [Pa], compression positive
OPENING_SYY = 10e6          # far-field compression σyy [Pa]


def apply_far_field(solver, lo, hi, ppc, sxx, syy, boundary_load="consistent"):
    """Far-field traction t = σ0·n (σ0 = diag(sxx, syy), tension positive [Pa]) on the four faces of
    the 2D block [lo, hi] [m]: spread over the outer particle rows with ``consistent_row_weights``
    (boundary_load="consistent", exact discrete equilibrium of the intact block) or on the outermost
    row only ("outer-row")."""
    if boundary_load not in ("consistent", "outer-row"):
        raise ValueError(f"boundary_load = {boundary_load!r} must be 'consistent' or 'outer-row'")
    for axis, far in ((0, sxx), (1, syy)):
        for side, face in ((-1, lo[axis]), (1, hi[axis])):
            t = np.zeros(2)
            t[axis] = side * far                  # σ0·n with n = side·e_axis: compression pushes inwards
            apply_face_traction(solver, axis, side, face, t, ppc, consistent=(boundary_load == "consistent"))


def circular_opening(spacing, domain=4.8, ppc=2, damping=0.5, boundary_load="consistent", material=None):
    """Square block of side `domain` [m] centred on (2.5, 2.5) m with a hole of radius 0.1 m, every
    particle at the in-situ stress (σxx, σyy) = (−20, −10) MPa, σzz = ν(σxx + σyy) (plane strain), and
    the far-field traction on its faces, so only the hole wall is out of balance ("excavation").
    material: default ``rocks.granite()``. Returns (solver, lo, hi)."""
    mat = material or rocks.granite()
    lo, hi = np.full(2, OPENING_CENTER - domain / 2), np.full(2, OPENING_CENTER + domain / 2)
    s = make_solver(lo, hi, spacing, margin=2)
    add_region(s, mat, lo, hi, ppc=ppc, holes=[Circle((OPENING_CENTER, OPENING_CENTER), OPENING_RADIUS)])
    sxx, syy = -OPENING_SXX, -OPENING_SYY     # tension positive inside the solver
    set_initial_stress(s, (sxx, syy, mat.poisson * (sxx + syy), 0.0))
    apply_far_field(s, lo, hi, ppc, sxx, syy, boundary_load)
    s.damping = damping
    return s, lo, hi


# ------------------------------------------------------------------------------------------------
# Pressurised line crack, paper Sec. 3.2 (Figs. 6-9)
CRACK_HALF_LENGTH = 0.2     # c [m] (crack length 0.4 m)


def line_crack(size, spacing, material, pressure, ramp, damping, crack_nodes="shared", half_length=CRACK_HALF_LENGTH):
    """Square block [0, size]² [m] with a line crack of half-length c at its centre, made by removing
    the particles of two cell layers (ppc = 2); the crack faces carry the pressure P [Pa] as a particle
    traction, ramped linearly over `ramp` [s]. crack_nodes = "excluded" takes the grid nodes on the
    crack's mid-line out of the WLS fits (the cubic B-spline reaches 2 cells, so with "shared" both
    faces, 2 cells apart, map to that node row and stay weakly tied).

    Returns (solver, geo): geo = dict(xc, yc, h, dp, x0 (initial positions by id), top, bot (particle
    ids of the loaded face rows), half_length)."""
    if crack_nodes not in ("shared", "excluded"):
        raise ValueError(f"crack_nodes = {crack_nodes!r} must be 'shared' or 'excluded'")
    h = spacing
    s = make_solver((0, 0), (size, size), h, margin=2)
    xc = yc = round(size / 2 / h) * h   # crack centre on a grid line so the hole is exactly two cell layers
    crack = Box((xc - half_length, yc - h), (xc + half_length, yc + h))
    add_region(s, material, (0, 0), (size, size), ppc=2, holes=[crack])
    x0 = get(s, "pos")                  # by particle id (== storage slot before the first step)
    dp = h / 2                          # particle spacing
    along = np.abs(x0[:, 0] - xc) < half_length
    top = np.nonzero(along & (np.abs(x0[:, 1] - (yc + h + dp / 2)) < dp / 4))[0]
    bot = np.nonzero(along & (np.abs(x0[:, 1] - (yc - h - dp / 2)) < dp / 4))[0]
    # pressure P on the faces: traction −P n, n the outward normal of the solid (−y on the upper face)
    apply_traction(s, top, (0.0, pressure), dp)
    apply_traction(s, bot, (0.0, -pressure), dp)
    if crack_nodes == "excluded":
        xn = s.nodePositions()
        inner = (np.abs(xn[:, 1] - yc) < h / 4) & (np.abs(xn[:, 0] - xc) < half_length - h / 4)
        for i in np.nonzero(inner)[0]:
            s.setNodeExcluded(int(i), True)
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


def arch_tunnel(spacing, material=None, ppc=2, width=TUNNEL_WIDTH, floor=TUNNEL_FLOOR, walls=("left", "right", "bottom")):
    """The tunnel specimen [0, width]² with the arch opening, free-slip walls on `walls` (the paper's
    four sides minus the loaded top, where the caller puts a platen or a traction).
    material: default ``rocks.pan2020_sandstone()``. Returns the solver."""
    planes = {"left": (0, -1, 0.0), "right": (0, 1, width), "bottom": (1, -1, 0.0), "top": (1, 1, width)}
    bad = [w for w in walls if w not in planes]
    if bad:
        raise ValueError(f"walls: unknown {bad}; allowed {sorted(planes)}")
    mat = material or rocks.pan2020_sandstone()
    s = make_solver((0, 0), (width, width), spacing, margin=2)
    add_region(s, mat, (0, 0), (width, width), ppc=ppc, holes=arch_tunnel_holes(width, floor))
    for w in walls:
        axis, side, pos = planes[w]
        s.addBoundaryPlane(axis, side, pos, "slip")
    return s
