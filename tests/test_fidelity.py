"""The measurements behind the fidelity table (yade_mpm_paper.fidelity, fidelity_table, analysis.flaw_end_cracks,
cases.tunnel_fidelity) on constructed fields with known answers."""
import math

import numpy as np
import pytest

from yade_mpm import analysis, rocks
from yade_mpm_paper import cases, fidelity
from yade_mpm_paper.fidelity import table as fidelity_table

from test_analysis import DP
from test_analysis import lattice as _lattice


def lattice(nx=60, ny=80, keep=None):
    return _lattice(nx, ny, keep)


# a 20 mm flaw rising to the left, toe (lower end) at (40, 30) mm, tip (upper end) at (20.0, 41.5) mm
TOE = np.array([0.0405, 0.0305])
TIP = TOE + 0.020 * np.array([-math.cos(math.radians(30)), math.sin(math.radians(30))])


def test_flaw_end_cracks_wing_anti_wing_shear():
    x, lat = lattice()
    D, e = np.zeros(len(x)), np.zeros(len(x))
    col = np.abs(x[:, 0] - TIP[0]) < 0.6 * DP
    wing = col & (x[:, 1] > TIP[1] - 1.5 * DP) & (x[:, 1] < TIP[1] + 12e-3)        # wing: 12 mm straight up from the tip
    colt = np.abs(x[:, 0] - TOE[0]) < 0.6 * DP
    anti = colt & (x[:, 1] > TOE[1] - 1.5 * DP) & (x[:, 1] < TOE[1] + 7e-3)       # anti-wing: 7 mm up from the toe
    shear = colt & (x[:, 1] < TOE[1] + 1.5 * DP) & (x[:, 1] > TOE[1] - 5e-3)      # shear: 5 mm down from the toe
    D[wing | anti] = 1.0
    e[shear] = 0.2
    far = lambda m: analysis.distance_to_segment(x[m], TOE, TIP).max()             # the farthest particle from the flaw
    r = analysis.flaw_end_cracks(D, e, 0.09, lat, TOE, TIP, 2e-3)
    assert r["tip"]["damaged"] and r["toe"]["damaged"]
    assert r["tip"]["wing"] == pytest.approx(far(wing)) and far(wing) > 10.5e-3
    assert r["tip"]["anti_wing"] <= 1.5 * DP
    assert r["toe"]["anti_wing"] == pytest.approx(far(anti)) == pytest.approx(6e-3 * math.cos(math.radians(30)))   # ⊥ to the flaw
    assert r["toe"]["shear"] == pytest.approx(far(shear)) == pytest.approx(np.hypot(*(x[shear] - TOE).T).max())  # below the toe
    assert r["wing"] == r["tip"]["wing"] and not r["tip"]["boundary"]
    D[col & (x[:, 1] > TIP[1])] = 1.0                                              # now up to the top row
    assert analysis.flaw_end_cracks(D, e, 0.09, lat, TOE, TIP, 2e-3)["tip"]["boundary"]


def test_crack_times_record_the_sequence():
    x, lat = lattice()
    col = np.abs(x[:, 0] - TIP[0]) < 0.6 * DP
    ct = fidelity.CrackTimes(lat, TOE, TIP, 0.09, 2e-3)
    assert ct.length == pytest.approx(0.02)
    z = np.zeros(len(x))
    for t, top in ((1e-3, None), (2e-3, 3e-3), (3e-3, 25e-3), (4e-3, 1.0)):
        D = np.zeros(len(x))
        if top is not None:
            D[col & (x[:, 1] > TIP[1] - 1.5 * DP) & (x[:, 1] < TIP[1] + top)] = 1.0
        ct.check(t, D, z)
    r = ct.result()
    assert r["first_tip_damage_s"] == 2e-3
    assert r["wing_longer_than_flaw_s"] == 3e-3          # 25 mm > 20 mm flaw
    assert r["through_to_a_face_s"] == 4e-3
    assert r["first_shear_crack_s"] is None


def test_curve_shape_of_known_curves():
    x = np.linspace(0, 3, 301)
    y = np.where(x < 2, 10 * x, 20 + 2 * (x - 2))        # eases up late, no peak
    c = fidelity.curve_shape(x, y)
    assert c["peak"] == pytest.approx(22) and c["drop"] == pytest.approx(0)
    assert c["slope_first"] == pytest.approx(10) and c["slope_last"] < c["slope_middle"]
    y2 = np.where(x < 1.5, 10 * x, 15 - 10 * (x - 1.5))  # a peak at 1.5, end at 0
    c2 = fidelity.curve_shape(x, y2)
    assert c2["x_at_peak"] == pytest.approx(1.5) and c2["drop"] == pytest.approx(1.0)


def test_near_segment_stress():
    x, _ = lattice()
    s = np.where(analysis.distance_to_segment(x, TOE, TIP) < 1.5e-3, 2e6, -5e6)
    r = fidelity.near_segment_stress(x, s, TOE, TIP, 1.5e-3)
    assert r["mean"] == pytest.approx(2e6) and r["tension_share"] == 1.0 and r["cv"] == pytest.approx(0.0)
    assert fidelity.near_segment_stress(x, s, (1, 1), (1, 1.01), 1e-3) is None


def test_bands_fill_triangle_and_rectangle():
    x, lat = lattice(80, 80)
    tri = (x[:, 0] > 0.01) & (x[:, 1] > 0.01) & ((x[:, 0] - 0.01) + (x[:, 1] - 0.01) < 0.04)
    rect = (x[:, 0] > 0.055) & (x[:, 0] < 0.075) & (x[:, 1] > 0.055) & (x[:, 1] < 0.07)
    b = analysis.bands(tri | rect, lat)
    fills = sorted(c["fill"] for c in b)
    assert fills[0] == pytest.approx(0.5, abs=0.05) and fills[1] == pytest.approx(1.0)


def test_tunnel_flaw_at_defaults_and_variants():
    a, b = cases.tunnel_flaw(), cases.tunnel_flaw_at()
    assert np.allclose(a["toe"], b["toe"]) and np.allclose(a["tip"], b["tip"])
    c = cases.tunnel_flaw_at(floor=0.0525, angle=math.radians(45), toe_gap=0.005)
    assert c["toe"] == pytest.approx([0.075 - 0.02 - 0.005, 0.0525 + 0.025])
    assert math.degrees(c["angle"]) == pytest.approx(45)
    with pytest.raises(ValueError, match="flaw_toe_gap"):
        cases.tunnel_flaw_at(toe_gap=-1)
    w = cases.tunnel_flaw_at(toe_height=0.0125)                  # the flaw_toe_waist variant: toe at mid-wall height
    assert w["toe"] == pytest.approx([0.045, 0.055 + 0.0125]) and np.allclose(w["tip"] - w["toe"], a["tip"] - a["toe"])
    for bad in (-1e-3, 0.026):
        with pytest.raises(ValueError, match=r"flaw_toe_height .* must be in \[0, 0.025\]"):
            cases.tunnel_flaw_at(toe_height=bad)
    with pytest.raises(ValueError, match="variant"):
        fidelity.variant("floor_52.5mm", "uniaxial")


def test_tunnel_fidelity_waist_and_spalled_places():
    holes = cases.arch_tunnel_holes()
    inside = lambda p: np.any([h.contains(p) for h in holes], axis=0)
    x, lat = lattice(150, 150, keep=lambda p: ~inside(p))
    pos = x.copy()
    left = (np.abs(x[:, 0] - 0.055) < 3e-3) & (x[:, 0] < 0.055) & (x[:, 1] > 0.055) & (x[:, 1] < 0.08)
    pos[left, 0] += 0.5e-3                                   # the left waist moves 0.5 mm into the opening
    sp = left & (x[:, 1] < 0.065)
    f = dict(pos=pos, plastic_strain=np.zeros(len(x)), damage=np.zeros(len(x)))
    r = cases.tunnel_fidelity(f, lat, sp)
    assert r["left_waist_inward_mm"]["mean"] == pytest.approx(0.5)
    assert r["right_waist_inward_mm"]["mean"] == pytest.approx(0.0)
    assert sum(r["spalled_by_place_mm2"].values()) == pytest.approx(sp.sum() * 1.0)
    assert set(r["spalled_by_place_mm2"]) <= {"left wall", "left corner"}


def _tunnel(stress):
    cs = [dict(case=k, axial_stress_MPa_at=[dict(displacement_mm=d, stress_MPa=f(d)) for d in np.round(np.arange(0, 2.01, 0.1), 6)],
               first_damage_location="floor", symmetry_damage=0.95) for k, f in stress.items()]
    return dict(cases=cs, info={})


def test_table_rows_from_constructed_summaries():
    t = _tunnel({"open_flaw": lambda d: 9 * d, "intact": lambda d: 10 * d, "filled_flaw": lambda d: 11 * d})
    m, v = fidelity_table.t_ordering(t)
    assert v == "agrees" and "20 of 20" in m
    t2 = _tunnel({"open_flaw": lambda d: 9 * d, "intact": lambda d: 10 * d, "filled_flaw": lambda d: 10 * d - 1 + (d > 1.5)})
    assert fidelity_table.t_ordering(t2)[1] == "partly"
    assert fidelity_table.t_no_peak(t)[1] == "agrees"
    assert fidelity_table.t_easing(t)[1] == "differs"              # straight lines do not ease up
    u = dict(runs=[dict(variant="open", mu_con=0.0, c_con_MPa=0.0, peak_stress_MPa=30.0, crack_times=dict(
        first_tip_damage_s=1.0e-3, wing_longer_than_flaw_s=3.5e-3, any_crack_longer_than_flaw_s=3.5e-3, first_shear_crack_s=None,
        through_to_a_face_s=None, flaw_length_m=0.025, end_radius_m=0.004)),
        dict(variant="filled", mu_con=0.6, c_con_MPa=0.0, peak_stress_MPa=29.0)])
    assert fidelity_table.u_sequence(u)[1] == "partly"             # both bars met, no run-through by 4.5 ms
    assert fidelity_table.u_filled_above_open(u)[1] == "differs"
    rows = fidelity_table.rows(dict(uniaxial_flaw=u, tunnel=t))
    assert len(rows) == len(fidelity_table.ROWS)
    assert all(r["default"] for r in rows) and {r["verdict"] for r in rows if r["part"] == "circular_opening"} == {"not run"}
    # the paper grid's uniaxial column reads its own runs (open + filled μ_con = 0.6), and says which rows it did not run
    up = dict(runs=[dict(u["runs"][0], peak_stress_MPa=28.0), dict(u["runs"][1], peak_stress_MPa=31.0)])
    rows = {(r["fig"], r["claim"]): r for r in fidelity_table.rows(dict(uniaxial_flaw=u, uniaxial_paper=up, tunnel=t))}
    above = rows[("Fig. 13a", "rigid-filled (μ_con = 0.6) peaks above the open flaw")]
    assert above["verdict"] == "differs" and above["verdict_paper"] == "agrees" and "31.0 MPa vs open 28.0" in above["paper_grid"]
    mu = rows[("Fig. 13a", "peak rises with μ_con")]
    assert mu["verdict_paper"] == "not run" and mu["paper_grid"] == fidelity_table.PAPER_UNIAXIAL_SUBSET
    # a benchmark's paper-grid column: its own run at the paper's spacing (Kirsch 0.01 m), not the default grid's
    k = dict(l2_rel_error_max=0.004, grid_spacing_m=0.04)
    r = {x["fig"]: x for x in fidelity_table.rows(dict(circular_opening=k))}["Fig. 4"]
    assert r["verdict"] == "agrees" and r["verdict_paper"] == "not run" and "l = 0.01 m" in r["paper_grid"]
    r = {x["fig"]: x for x in fidelity_table.rows(dict(circular_opening=k, circular_opening_paper=dict(k, grid_spacing_m=0.01,
                                                                                                     l2_rel_error_max=0.07)))}["Fig. 4"]
    assert r["verdict"] == "agrees" and r["verdict_paper"] == "differs" and "l = 0.01 m" in r["paper_grid"]


def test_von_mises_variant_is_the_named_option_and_the_default_is_the_reference_codes():
    v = fidelity.variant("eps_p_von_mises", "tunnel")
    assert v["material"] == dict(plasticStrainIncrement="von-mises")
    assert rocks.pan2020_sandstone(**v["material"]).plasticStrainIncrement == "von-mises"
    assert rocks.pan2020_sandstone().plasticStrainIncrement == "reference-code"
    assert rocks.miao2018_sandstone().plasticStrainIncrement == "reference-code"


def test_every_tunnel_variant_builds_a_valid_flaw_at_the_default_grid():
    # the scene refuses a flaw within one cell of a face or the opening (arch_tunnel's range check): a variant must pass it
    from yade_mpm_paper.cases.tunnel import _flaw_clear
    for name, v in fidelity.VARIANTS.items():
        if v.get("scene") == "tunnel" and "flaw_angle" in v:
            assert _flaw_clear(math.radians(v["flaw_angle"]), 0.002), name
    assert not _flaw_clear(math.radians(45.0), 0.002)

