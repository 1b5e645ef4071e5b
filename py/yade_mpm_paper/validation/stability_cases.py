"""The scenes of the stability suite (yade_mpm_paper.validation.stability runs and checks them): small
scenes that push the explicit WLS-MPM step to its limits, each a builder `case_*(fast)` returning
(solver, options) and listed in CASES (name: (builder, one-line description)).

Cases: stiff (E = 200 GPa), nearly incompressible (ν = 0.49), very soft (E = 1 MPa), traction ramped
at a baseline quasi-static rate and 100× faster, a column collapsing under gravity (large plastic
deformation), fully damaged regions under tension, particles reaching the grid edge, and particles of
density 1 and 1e7 kg/m³ side by side; debris thrown off the grid (a fragment at 5–200 m/s, a layer torn off
by tension).

Options of a case: end_time [s]; expect ("finished", the default, or "stopped_with_error": the grid-edge
case, whose intact body itself reaches the edge of the grid); removed (the removed-particle count expected:
None = none, ("count", n), ("some", None), ("any", None)); momentum (True: no gravity and walls, the
momentum of the particles plus that of the removed ones must stay the initial momentum).
"""
import math

import numpy as np

from yade_mpm import rocks
from yade_mpm.materials import DpGkMat, ElasticMat
from yade_mpm.scene import add_region, apply_traction, boundary_particles, make_solver


def cells_per_m(fast):
    """Grid cells across the 1 m blocks: 10 for the test versions, 40 for the full suite."""
    return 10 if fast else 40


def block_on_floor(mat, size, cells, floor="fixed", ppc=2, margin=2, extra_x=0.0, extra_y=0.0):
    """Square block [0, size]² on a floor at y = 0 (grid extends `margin` cells plus extra room)."""
    h = size / cells
    s = make_solver((0.0, 0.0), (size + extra_x, size + extra_y), h, margin=margin)
    idx = add_region(s, mat, (0.0, 0.0), (size, size), ppc=ppc)
    s.addBoundaryPlane(1, -1, 0.0, floor)
    return s, idx, h


def top_traction(s, h, ppc, ty, ramp):
    """Vertical traction ty [Pa] on the top particle layer (face length l/ppc each), ramped over `ramp` s."""
    top = boundary_particles(s, 1, +1)
    apply_traction(s, top, (0.0, ty), h / ppc)
    s.tractionRampTime = ramp
    return top


def transit_time(mat, size):
    """Time for a P wave to cross the block [s]."""
    return size / mat.pWaveSpeed()


def elastic_block(mat, cells, traction, floor="fixed", ramp_transits=20.0, run_factor=1.5, gravity=True):
    """Elastic block on a floor under gravity and a compressive top traction ramped over `ramp_transits`
    P-wave transit times (quasi-static baseline: 20), run for run_factor × the ramp."""
    s, _, h = block_on_floor(mat, 1.0, cells, floor)
    if gravity:
        s.gravity = (0.0, -9.81)
    ramp = ramp_transits * transit_time(mat, 1.0)
    top_traction(s, h, 2, -traction, ramp)
    return s, dict(end_time=run_factor * max(ramp, 20 * transit_time(mat, 1.0)))


def case_stiff(fast):
    mat = ElasticMat(young=200e9, poisson=0.3, density=7850.0)
    return elastic_block(mat, cells_per_m(fast), traction=50e6)


def case_incompressible(fast):
    # Slip floor and free sides: the block must bulge sideways at nearly constant volume.
    mat = ElasticMat(young=1e9, poisson=0.49, density=2000.0)
    return elastic_block(mat, cells_per_m(fast), traction=10e6, floor="slip")


def case_soft(fast):
    # Gravity alone strains the base by ρgH/E ≈ 2.5 %; the traction adds 5 %.
    mat = ElasticMat(young=1e6, poisson=0.3, density=2500.0)
    return elastic_block(mat, cells_per_m(fast), traction=50e3)


def rock_rate(fast, speedup):
    mat = rocks.granite_dpgk()
    # 20 MPa compression, ramped over 20 transit times / speedup; run 30 transit times either way.
    s, _, h = block_on_floor(mat, 1.0, cells_per_m(fast))
    s.gravity = (0.0, -9.81)
    tt = transit_time(mat, 1.0)
    top_traction(s, h, 2, -20e6, 20 * tt / speedup)
    return s, dict(end_time=30 * tt)


def case_rate_baseline(fast):
    return rock_rate(fast, 1.0)


def case_rate_100x(fast):
    return rock_rate(fast, 100.0)


def case_overload(fast):
    """DP–GK rock hit by a 200 MPa top compression applied at once (no ramp), ≈ 2.2× the rock's
    Mohr–Coulomb uniaxial strength 2c·cosφ/(1 − sinφ) ≈ 90 MPa: the block is crushed, a loaded top corner
    particle is squeezed out sideways and leaves the grid (2 margin cells on the left): intact material of
    the body reaching the edge, which must stop the run with the grid-edge message (fully damaged or
    detached debris of the crushed corner that leaves first is removed)."""
    mat = rocks.granite_dpgk()
    s, _, h = block_on_floor(mat, 1.0, cells_per_m(fast), extra_x=0.5, extra_y=0.5)
    s.gravity = (0.0, -9.81)
    top_traction(s, h, 2, -200e6, 0.0)
    # debris of the crushed corner (D = 1, or detached) may be removed before the intact corner leaves
    return s, dict(end_time=20 * transit_time(mat, 1.0), expect="stopped_with_error", removed=("any", None))


def case_column_collapse(fast):
    """Weak frictional column (DP, φ = 30°, c = 100 Pa, no damage) 0.2 m × 0.4 m against a slip wall,
    collapsing under gravity onto a fixed (no-slip) floor; runs until it has spread out."""
    mat = DpGkMat(young=2e6, poisson=0.3, density=2000.0, frictionAngle=math.radians(30), dilatancyAngle=0.0,
                     cohesion=100.0, critPlasticStrain=0.1, damage=False)
    h = 0.04 if fast else 0.01
    s = make_solver((0.0, 0.0), (1.2, 0.5), h, margin=2)
    add_region(s, mat, (0.0, 0.0), (0.2, 0.4), ppc=2)
    s.addBoundaryPlane(1, -1, 0.0, "fixed")
    s.addBoundaryPlane(0, -1, 0.0, "slip")
    s.gravity = (0.0, -9.81)
    return s, dict(end_time=0.4 if fast else 1.0)


def case_damaged(fast):
    """Rock block (DP–GK) on a fixed floor under gravity, a band 0.4 ≤ y ≤ 0.6 pre-set to D = 1, and the
    upper part (y > 0.5) launched upwards at 10 m/s: the band cannot hold it (no tensile stiffness left)
    and the tensile waves from the velocity jump (up to ρ c_p Δv/2 ≈ 40 MPa) drive more particles to D = 1. A velocity pull is used
    rather than a top traction: a traction keeps accelerating the loaded layer once the rock beneath it is
    fully damaged, which then flies off the grid (that variant stops with the grid-edge error)."""
    mat = rocks.granite_dpgk()
    s, _, h = block_on_floor(mat, 1.0, cells_per_m(fast), extra_y=0.2)
    s.gravity = (0.0, -9.81)
    y = s.view("x1")
    s.view("damage")[(y > 0.4) & (y < 0.6)] = 1.0
    s.view("v1")[y > 0.5] = 10.0
    s.requestSort()  # velocities changed: the stable step is re-evaluated
    return s, dict(end_time=20 * transit_time(mat, 1.0))


def case_grid_edge(fast):
    """Elastic rock block thrown at 100 m/s towards +x with 2 margin cells and no walls: it must be
    stopped with a message naming the particle that leaves the grid (WLS fits near the edge use the
    reduced node set on the way)."""
    mat = rocks.granite()
    cells = cells_per_m(fast)
    s = make_solver((0.0, 0.0), (0.5, 0.5), 0.5 / cells, margin=2)
    add_region(s, mat, (0.0, 0.0), (0.5, 0.5), ppc=2)
    s.view("v0")[:] = 100.0
    s.requestSort()
    return s, dict(end_time=1.0, expect="stopped_with_error")


# Debris: a detached, fully damaged 2 × 2-cell fragment thrown at the grid edge beside an intact block
# (Solver.outside at its default 'remove-debris'). The block [0, 0.3]² m carries a converging velocity
# field (a compression wave, ≤ 0.2 m/s); the fragment starts at x = 0.48 m, 0.18 m from the block, and is
# thrown towards +x. No gravity, no walls: the momentum of the particles plus that of the removed ones is
# the initial momentum.
DEBRIS_SPEEDS = (5.0, 20.0, 50.0, 200.0)
DEBRIS_FRAGMENT_LO = (0.48, 0.12)


def debris_scene(speed, fragment=True, fast=True):
    """The block and (fragment=True) the fragment thrown at `speed` [m/s] towards +x; returns
    (solver, block ids, fragment ids). Grid spacing 20 mm (fast) or 10 mm, 2 margin cells."""
    h = 0.02 if fast else 0.01
    s = make_solver((0.0, 0.0), (0.5, 0.4), h, margin=2)
    rock = rocks.granite_dpgk()
    block = add_region(s, rock, (0.0, 0.0), (0.3, 0.3), ppc=2)
    lo = DEBRIS_FRAGMENT_LO
    frag = add_region(s, rock, lo, (lo[0] + 2 * h, lo[1] + 2 * h), ppc=2) if fragment else np.zeros(0, dtype=np.int64)
    x, v0, ids = s.view("x0"), s.view("v0"), s.view("id")
    v0[:] = 0.2 * (0.15 - x) / 0.15
    f = np.isin(ids, frag)
    v0[f] = speed
    s.view("damage")[f] = 1.0                 # fully damaged: debris
    del x, v0, ids
    s.requestSort()
    return s, np.asarray(block), np.asarray(frag)


def debris_end_time(fast=True):
    """Long enough for every fragment particle to leave the grid at 5 m/s (≤ 55 mm to go: 11 ms)."""
    return 0.012


def _debris_case(speed):
    def build(fast):
        s, _, _ = debris_scene(speed, fast=fast)
        return s, dict(end_time=debris_end_time(fast), expect="finished", removed=("count", 16), momentum=True)
    build.__doc__ = f"Fragment (D = 1, 2 × 2 cells) thrown at {speed:g} m/s at the grid edge beside an intact block: removed, the run goes on."
    return build


def case_layer_torn_off(fast):
    """Rock block [0, 0.4]² m whose top 60 mm (y > 0.34 m) are launched upwards at 30 m/s: the
    tensile wave from the velocity jump (≈ ρ c_p Δv/2 ≈ 120 MPa) damages the rows beneath them, the
    layer tears off and flies through the top of the grid (4 margin cells). The layer is debris (detached
    from the body, or D = 1) and is removed; the block stays. No gravity, no walls: momentum conserved."""
    h = 0.04 if fast else 0.01
    s = make_solver((0.0, 0.0), (0.4, 0.4), h, margin=4)
    add_region(s, rocks.granite_dpgk(), (0.0, 0.0), (0.4, 0.4), ppc=2)
    y = s.view("x1")
    s.view("v1")[y > 0.34] = 30.0
    del y
    s.requestSort()
    return s, dict(end_time=0.02, expect="finished", removed=("some", None), momentum=True)


def case_mass_contrast(fast):
    """Two touching elastic blocks on a fixed floor under gravity, densities 1 and 1e7 kg/m³ (masses set
    per particle; one material per solver). Δt follows the light block (the solver uses ρ_min)."""
    mat = ElasticMat(young=1e8, poisson=0.25, density=1.0)
    cells = cells_per_m(fast)
    h = 1.0 / cells
    s = make_solver((0.0, 0.0), (1.0, 0.5), h, margin=2)
    add_region(s, mat, (0.0, 0.0), (1.0, 0.5), ppc=2)
    heavy = s.view("x0") > 0.5
    s.view("mass")[heavy] *= 1e7
    s.requestSort()  # ρ_min and the stable step are re-evaluated from the new masses
    s.addBoundaryPlane(1, -1, 0.0, "fixed")
    s.gravity = (0.0, -9.81)
    s.stableDt()  # evaluates ρ_min, so waveSpeed() is the light block's
    # 40 transit times of the light block (its P wave crosses 0.5 m in ~45 µs)
    return s, dict(end_time=40 * 0.5 / s.waveSpeed())


def case_edge_deforming(fast):
    """Rock block filling the grid to its edges (margin 0, no side walls), gravity and a 20 MPa top
    compression ramped over 2 transits: the outer particles deform in cells whose stencils reach past the
    grid, where the WLS fit uses the reduced node set (Eqs. 10, 15 with M assembled from active nodes)."""
    mat = rocks.granite()
    s, _, h = block_on_floor(mat, 1.0, cells_per_m(fast), margin=0)
    s.gravity = (0.0, -9.81)
    tt = transit_time(mat, 1.0)
    top_traction(s, h, 2, -20e6, 2 * tt)
    return s, dict(end_time=30 * tt)


def case_mass_stacked(fast):
    """Heavy (1e7 kg/m³) half resting on a light (1 kg/m³) half, same E = 100 MPa, fixed floor, gravity:
    the light layer is loaded by a weight 1e7× its own (run for 100 light transits)."""
    mat = ElasticMat(young=1e8, poisson=0.25, density=1.0)
    h = 0.5 / (cells_per_m(fast) // 2)
    s = make_solver((0.0, 0.0), (0.5, 1.0), h, margin=2)
    add_region(s, mat, (0.0, 0.0), (0.5, 1.0), ppc=2)
    s.view("mass")[s.view("x1") > 0.5] *= 1e7
    s.requestSort()
    s.addBoundaryPlane(1, -1, 0.0, "fixed")
    s.gravity = (0.0, -9.81)
    s.stableDt()
    return s, dict(end_time=100 * 0.5 / s.waveSpeed())


CASES = {
    "stiff_E200GPa": (case_stiff, "elastic block E = 200 GPa, gravity + 50 MPa top compression (quasi-static ramp)"),
    "incompressible_nu049": (case_incompressible, "elastic block ν = 0.49 on a slip floor, 10 MPa top compression"),
    "soft_E1MPa": (case_soft, "elastic block E = 1 MPa, gravity + 50 kPa top compression"),
    "rate_baseline": (case_rate_baseline, "DP–GK rock, 20 MPa top compression ramped over 20 P-wave transits"),
    "rate_100x": (case_rate_100x, "same, ramp 100× faster (0.2 transits): a stress wave"),
    "overload_step": (case_overload, "DP–GK rock, 200 MPa top compression applied at once: crushed"),
    "column_collapse": (case_column_collapse, "DP column (c = 100 Pa, φ = 30°) collapsing under gravity"),
    "fully_damaged": (case_damaged, "DP–GK rock, D = 1 band, upper half launched up at 10 m/s"),
    "grid_edge": (case_grid_edge, "intact block at 100 m/s towards the grid edge, no walls: the body leaves, the run stops"),
    **{f"debris_{v:g}ms": (_debris_case(v), f"D = 1 fragment thrown at {v:g} m/s at the grid edge beside a block: removed")
       for v in DEBRIS_SPEEDS},
    "layer_torn_off": (case_layer_torn_off, "top layer torn off by tension (launched at 30 m/s): removed as debris"),
    "edge_deforming": (case_edge_deforming, "rock block filling the grid to its edges, 20 MPa fast compression"),
    "mass_contrast": (case_mass_contrast, "densities 1 and 1e7 kg/m³ side by side under gravity"),
    "mass_stacked": (case_mass_stacked, "1e7 kg/m³ half resting on a 1 kg/m³ half under gravity"),
}
