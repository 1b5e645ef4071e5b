"""Scene builders of the reference cases, written once: scripts, tests and benchmarks build their
scenes here and keep only their command line, plots and narrative.

    circular_opening(spacing, ...)   paper Sec. 3.1: holed block under biaxial in-situ stress
    line_crack(size, spacing, ...)   paper Sec. 3.2: pressurised line ("penny-shaped") crack
    arch_tunnel_holes(...)           paper Sec. 4: the arch-shaped tunnel opening (geometry only)
    tunnel_flaw(...) / tunnel_flaw_at(floor, angle, gap, toe_height)   paper Sec. 4: the 60 × 2 mm flaw left of the tunnel (geometry)
    arch_tunnel_specimen(spacing, ...)  the tunnel specimen with its opening and slip walls (no top load)
    arch_tunnel(case, spacing, ...)  paper Sec. 4 + grout: the full scene with the YADE platen (and filler)
    uniaxial_flaw(variant, spacing, ...)  paper Sec. 3.3: 50 × 150 mm specimen, platen, open/rigid-filled flaw
                      (slab_cells = n: the same as a 3D slab between slip planes; slab_compare: its curve vs 2D)
    yade_platen / yade_filler / yade_engines   the rigid YADE bodies and engines of those loading scenes
    tunnel_location / tunnel_where / tunnel_report   names of places around the tunnel, its crack analytics
    tunnel_results    a tunnel run's records: first crack, snapshots and their analysis, summary entry,
                      study row, Fig. 17 ordering (scripts/paper/tunnel_spalling.py)
    uniaxial_results  a uniaxial flaw run's records: post-peak stop, peak and modulus, end-of-run crack
                      analytics, the runs' summary (scripts/paper/uniaxial_flaw.py)

Rock parameters come from ``yade_mpm.rocks``; the small scenes of the stability suite live beside their
checks in ``yade_mpm_paper.validation.stability_cases``. Modules: elastic (Secs. 3.1, 3.2, boundary checks),
tunnel (Sec. 4), uniaxial (Sec. 3.3), loading (YADE bodies), tunnel_results, uniaxial_results
(imported by name: ``from yade_mpm_paper.cases import tunnel_results``). Quantities are SI; stresses are tension positive inside the solver.
"""
from .elastic import (CRACK_HALF_LENGTH, FAR_FIELDS, OPENING_CENTER, OPENING_RADIUS, OPENING_SXX, OPENING_SYY, apply_far_field,
                      circular_opening, drifting_block, fixed_free_bar, line_crack, mode_period, uniform_stress_block)
from .loading import (BODY_HALF_THICKNESS, FILLER_CHI, PLATEN_FRICTION, PLATEN_SPEED, blocked_dofs, yade_engines, yade_filler,
                      yade_platen)
from .tunnel import (BAND_GAP, FILLER_FRICTION, FLAW_ANGLE, FLAW_ANGLE_DEG, FLAW_LENGTH, FLAW_TOE, FLAW_TOE_GAP, FLAW_TOE_HEIGHT,
                     FLAW_WIDTH, TUNNEL_CASES,
                     TUNNEL_END_TIME, TUNNEL_FLOOR, TUNNEL_INTACT_MAX_SPACING, TUNNEL_MAX_SPACING, TUNNEL_RADIUS, TUNNEL_RECT, TUNNEL_WIDTH,
                     arch_tunnel, arch_tunnel_holes, arch_tunnel_specimen, tunnel_fidelity, tunnel_flaw, tunnel_flaw_at, tunnel_location,
                     tunnel_opening_distance, tunnel_report, tunnel_where)
from .uniaxial import (UNIAXIAL_FLAW, UNIAXIAL_HEIGHT, UNIAXIAL_PAPER_SPACING, UNIAXIAL_SIDE_ROOM, UNIAXIAL_SLAB_CELLS, UNIAXIAL_VARIANTS,
                       UNIAXIAL_MAX_SPACING, UNIAXIAL_WIDTH, exclude_nodes_inside, uniaxial_flaw, uniaxial_flaw_geometry)
