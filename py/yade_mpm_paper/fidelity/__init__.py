"""Measurements behind the fidelity table of doc/validation/report.md (issue 18): what a run records so that
each claim the paper makes about its results (Figs. 4–19) has a measured counterpart, and the named
modelling choices varied one at a time to find the cause of a row that differs.

    from yade_mpm_paper import fidelity
    times = fidelity.CrackTimes(lattice, toe, tip, soft_end, radius)   # uniaxial flaw: crack sequence
    runner.Output(times.update, steps=25)                               # ... then times.result()
    fidelity.curve_shape(displacement, stress)                          # Fig. 17: peak, easing up late
    fidelity.near_segment_stress(x0, smax, toe, tip, width)             # Figs. 14–15: σ̃max at the flaw
    fidelity.VARIANTS                                                   # the one-at-a-time choices

The rows themselves are assembled by ``yade_mpm_paper.fidelity.table`` from the runs' summaries.
"""
import math

import numpy as np

from yade_mpm import analysis

# ----------------------------------------------------------------------------- crack sequence (Fig. 11b)


class CrackTimes:
    """Times of the crack sequence at the ends of a flaw (``analysis.flaw_end_cracks``), checked each
    time ``update(solver)`` is called (a ``runner.Output``): first D = 1 within `radius` of an end,
    the first time a wing crack (or any tensile crack from an end) is longer than `length` (default the
    flaw length), the first shear crack from an end, the time the cracks from the ends reach a face of
    the specimen. Fields are read in id order (``ym.get``)."""

    def __init__(self, lattice, toe, tip, soft_end, radius, length=None):
        self.lattice, self.toe, self.tip, self.soft_end, self.radius = lattice, toe, tip, soft_end, float(radius)
        self.length = float(np.hypot(*(np.asarray(tip, float) - toe))) if length is None else float(length)
        self.t = dict(first_tip_damage_s=None, wing_longer_than_flaw_s=None, any_crack_longer_than_flaw_s=None,
                      first_shear_crack_s=None, through_to_a_face_s=None)
        self.history = []                      # (t, wing, anti_wing, shear) [s, m, m, m] when they changed

    def check(self, time, damage, plastic_strain):
        """One state: fields per particle in lattice order; returns the flaw_end_cracks dict."""
        r = analysis.flaw_end_cracks(damage, plastic_strain, self.soft_end, self.lattice, self.toe, self.tip, self.radius)
        t = self.t
        if t["first_tip_damage_s"] is None and (r["toe"]["damaged"] or r["tip"]["damaged"]):
            t["first_tip_damage_s"] = time
        if t["wing_longer_than_flaw_s"] is None and r["wing"] > self.length:
            t["wing_longer_than_flaw_s"] = time
        if t["any_crack_longer_than_flaw_s"] is None and max(r["wing"], r["anti_wing"]) > self.length:
            t["any_crack_longer_than_flaw_s"] = time
        if t["first_shear_crack_s"] is None and r["shear"] > 0:
            t["first_shear_crack_s"] = time
        if t["through_to_a_face_s"] is None and (r["toe"]["boundary"] or r["tip"]["boundary"]):
            t["through_to_a_face_s"] = time
        row = (time, r["wing"], r["anti_wing"], r["shear"])
        if not self.history or row[1:] != self.history[-1][1:]:
            self.history.append(row)
        return r

    def update(self, solver):
        from yade_mpm.fields import get
        if all(v is not None for v in self.t.values()):
            return
        self.check(solver.time, get(solver, "damage"), get(solver, "plastic_strain"))

    def result(self):
        """JSON-able: the times [s], the flaw length [m] and the history thinned to at most 60 rows."""
        h = self.history
        step = max(1, len(h) // 60)
        return dict(self.t, flaw_length_m=self.length, end_radius_m=self.radius,
                    history=[[float(v) for v in row] for row in h[::step]])


# ----------------------------------------------------------------------------- curves (Figs. 11a, 13, 17)
def curve_shape(x, y):
    """Shape of a loading curve y(x) (e.g. axial stress against displacement): peak value and where it
    is, the end value, drop = 1 − end/peak (0: no peak, still rising or flat), and the slopes over the
    first, middle and last thirds of the x range (easing up late: last < middle)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 6:
        return None
    k = int(np.argmax(y))
    third = (x[-1] - x[0]) / 3
    slope = lambda lo, hi: float(np.polyfit(x[(x >= lo) & (x <= hi)], y[(x >= lo) & (x <= hi)], 1)[0]) if ((x >= lo) & (x <= hi)).sum() > 2 else None
    return dict(peak=float(y[k]), x_at_peak=float(x[k]), end=float(y[-1]), x_end=float(x[-1]),
                drop=float(1 - y[-1] / y[k]) if y[k] > 0 else None,
                slope_first=slope(x[0], x[0] + third), slope_middle=slope(x[0] + third, x[0] + 2 * third),
                slope_last=slope(x[0] + 2 * third, x[-1]))


def near_segment_stress(x0, smax, a, b, width):
    """σ̃max of the particles within `width` [m] of the segment a–b (e.g. the faces of a flaw, initial
    positions x0): mean, share in tension (σ̃max > 0) and the scatter (coefficient of variation of
    |σ̃max|); None if no particle is that near."""
    near = analysis.distance_to_segment(x0, a, b) < width
    if not near.any():
        return None
    s = np.asarray(smax, float)[near]
    m = float(np.mean(np.abs(s)))
    return dict(mean=float(s.mean()), tension_share=float(np.mean(s > 0)), cv=float(np.std(np.abs(s)) / m) if m > 0 else None,
                particles=int(near.sum()))


# ----------------------------------------------------------------------------- one-at-a-time variants
# Each: what changes (material keyword overrides of the rock, the solver's Courant number, the scene), and
# which rows of the table it is meant to explain. "baseline" is the scene as the defaults build it.
VARIANTS = {
    "baseline": dict(label="defaults (C and the velocity update the solver's, Eq. 36 as printed, Benz–Asphaug growth, V = particle, c_r = 0.1, ε̄p,crit = 0.1, "
                                "Δε̄p = k̄φ Δλ)"),
    "courant_0.5": dict(courant=0.5, label="Δt at half the paper's bound, C = 0.5"),
    "courant_0.25": dict(courant=0.25, label="Δt at a quarter of the paper's bound, C = 0.25 (a converged reference for Δt)"),
    "penalty": dict(contact_law="penalty", label="Eq. 23 as printed: the penalty contact κ = 2m/Δt² (the paper's) instead of the kinematic law"),
    "penalty_courant_0.25": dict(contact_law="penalty", courant=0.25, label="Eq. 23 at C = 0.25 (with C = 0.125: its Δt → 0 limit by Richardson in Δt²)"),
    "penalty_courant_0.125": dict(contact_law="penalty", courant=0.125, label="Eq. 23 at C = 0.125"),
    "no_failed_bulking": dict(material=dict(failedBulking=float("inf")),
                              label="failed particles bulk without limit (the paper) instead of at most 1.5 × V₀"),
    "pic": dict(velocity_update="pic", label="Eq. 6 as printed, v_p = Σ ψ_i v_i (the paper's particle velocity) instead of FLIP"),
    "principal_strain": dict(material=dict(damageStrain="principal"), label="Eq. 36: maximum principal strain instead of σ̃max/(K+4G/3)"),
    "as_printed_growth": dict(material=dict(growthLaw="as-printed"), label="Eq. 38 as printed (dD^⅓/dt ∝ ε̄^⅓)"),
    "v_cube": dict(material=dict(thresholdVolume="cube"), label="V of Eq. 37 = dp³ (the old default, fitted to Fig. 9)"),
    "no_residual_cohesion": dict(material=dict(residualCohesion=0.0), label="residual cohesion 0 instead of 0.1 c₀"),
    "soft_strain_0.01": dict(material=dict(critPlasticStrain=0.01), label="ε̄p,crit = 0.01 instead of 0.1 (softening within reach of the grid's strains)"),
    "eps_p_von_mises": dict(material=dict(plasticStrainIncrement="von-mises"),
                            label="ε̄p grown by the von Mises equivalent of the deviatoric plastic strain, Δε̄p = Δλ/√3 (this code's "
                                  "earlier default) instead of the reference code's k̄φ Δλ (which softens 1.97× faster at φ = 39°)"),
    "floor_52.5mm": dict(floor=0.0525, scene="tunnel", label="opening's floor at 52.5 mm (centred 45 mm-high opening) instead of 55 mm"),
    "flaw_angle_50": dict(flaw_angle=50.0, scene="tunnel", label="flaw inclined 50° instead of 60° (the paper gives no angle; "
                          "45° is refused at 2 mm: its tip comes within a cell of the left face)"),
    "flaw_gap_5mm": dict(flaw_toe_gap=0.005, scene="tunnel", label="flaw toe 5 mm from the left wall instead of 10 mm (position not given)"),
    "flaw_toe_waist": dict(flaw_toe_height=0.0125, scene="tunnel",
                           label="flaw toe at mid-wall height (12.5 mm above the floor) instead of spandrel height (25 mm; not given)"),
}


def variant(name, scene):
    """The variant `name` for `scene` ("tunnel" or "uniaxial"); ValueError naming the allowed ones."""
    allowed = [k for k, v in VARIANTS.items() if v.get("scene", scene) == scene]
    if name not in allowed:
        raise ValueError(f"variant = {name!r} for the {scene} scene must be one of {allowed}")
    return VARIANTS[name]


def json_safe(v):
    """NumPy values and tuples as plain JSON types, NaN/inf as None."""
    if isinstance(v, dict):
        return {str(k): json_safe(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [json_safe(x) for x in v]
    if isinstance(v, (np.bool_, bool)):
        return bool(v)
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return float(v) if math.isfinite(v) else None
    if isinstance(v, np.ndarray):
        return json_safe(v.tolist())
    return v
