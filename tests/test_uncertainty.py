"""The numerical-uncertainty tools: the grid shift of make_solver (the same scene cut differently by the grid),
observed orders and Richardson extrapolation, and how the fidelity table merges an ensemble's texts and verdicts."""
import math

import numpy as np
import pytest

import yade_mpm as ym
from yade_mpm import rocks
from yade_mpm_paper import uncertainty as U


def test_shift_moves_the_grid_and_keeps_the_region_covered():
    lo, hi, l = np.array([0.0, 0.0]), np.array([1.0, 0.5]), 0.1
    s0 = ym.make_solver(lo, hi, l)
    s1 = ym.make_solver(lo, hi, l, shift=(0.3, 0.5))
    assert np.allclose(np.array(s1.origin), np.array(s0.origin) - np.array([0.3, 0.5]) * l, rtol=0, atol=1e-15)
    for s in (s0, s1):
        top = np.array(s.origin) + np.array(s.cells) * l
        assert np.all(top >= hi + 2 * l - 1e-12) and np.all(np.array(s.origin) <= lo - 2 * l + 1e-12)
    with pytest.raises(ValueError, match=r"shift = .*\[0, 1\)"):
        ym.make_solver(lo, hi, l, shift=(1.0, 0.0))
    with pytest.raises(ValueError, match="shift"):
        ym.make_solver(lo, hi, l, shift=(0.1,))


@pytest.mark.parametrize("shift", [None, (0.3, 0.7)])
def test_a_translating_block_stays_rigid_at_any_shift(shift):
    """The WLS shape functions reproduce a constant field wherever the grid cuts the block: a block moving at a
    uniform velocity keeps it and stays stress-free, its particles displaced by v·t (to round-off)."""
    s = ym.make_solver((0.0, 0.0), (0.6, 0.4), 0.05, shift=shift)
    ym.add_region(s, rocks.granite(), (0.0, 0.0), (0.6, 0.4), ppc=2)
    from yade_mpm.fields import views     # the power-user door: set the initial velocity in place
    v = views(s)
    v["v0"][:], v["v1"][:] = 3.0, -1.5
    x0 = ym.get(s, "pos")
    for _ in range(20):
        s.run(1)
    assert np.abs(ym.get(s, "vel") - [3.0, -1.5]).max() < 1e-9
    assert np.abs(ym.get(s, "pos") - x0 - np.array([3.0, -1.5]) * s.time).max() < 1e-12
    assert np.abs(ym.get(s, "stress")).max() < 1e-3                # Pa, against E·(v Δt / l) ~ 1e7 for a wrong field


def test_observed_order_and_richardson():
    h = [0.04, 0.02, 0.01]
    assert U.observed_order(h, [0.4, 0.1, 0.025]) == pytest.approx([2.0, 2.0])
    q = [1.0 + 3.0 * x ** 1.5 for x in h]                        # q(h) = q∞ + c h^p, p = 1.5
    r = U.richardson(h, q)
    assert r["monotone"] and r["order"] == pytest.approx(1.5) and r["limit"] == pytest.approx(1.0, rel=1e-12)
    assert U.richardson(h, [1.0, 1.2, 1.1])["limit"] is None     # not monotone: no extrapolation
    assert U.richardson(h, [53.05, 52.88, 52.54])["limit"] is None   # monotone but the changes grow: not converging
    slow = U.richardson(h, [53.017, 52.775, 52.54])                     # the changes barely shrink: order 0.04
    assert slow["order"] == pytest.approx(0.042, abs=0.01) and slow["limit"] is None
    with pytest.raises(ValueError, match="constant ratio"):
        U.richardson([0.04, 0.02, 0.015], q)


def test_spread_and_merge_and_verdict_rule():
    sp = U.spread([1.0, 2.0, 3.0, None, math.nan])
    assert sp["n"] == 3 and sp["mean"] == 2.0 and sp["min"] == 1.0 and sp["cv"] == pytest.approx(np.std([1, 2, 3]) / 2)
    assert U.spread([None]) is None
    t = U.merge_texts(["peak 28.0 MPa at μ_con = 0.6", "peak 29.5 MPa at μ_con = 0.6", "peak 27.0 MPa at μ_con = 0.6"])
    assert t == "peak 28.0 [27–29.5] MPa at μ_con = 0.6"
    assert "differ in 1 of the 1" in U.merge_texts(["at 1.0 ms", "never"])
    assert U.combined_verdict(["agrees", "agrees"]) == "agrees"
    assert U.combined_verdict(["agrees", "differs", "agrees"]) == "within uncertainty (agrees 2, differs 1 of 3)"
    assert U.parse_shift("0.2,0.5") == (0.2, 0.5) and U.parse_shift("0,0") is None and U.parse_shift(None) is None
    for bad in ("1,0", "0.2", "a,b"):
        with pytest.raises(ValueError, match="--grid-shift"):
            U.parse_shift(bad)


def test_convergence_paths_from_runs():
    """scripts/paper/convergence.py: errors and orders along a refinement path, analytic and Richardson."""
    import importlib.util
    from helpers import script_path
    spec = importlib.util.spec_from_file_location("convergence_script", script_path("convergence.py"))
    conv = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conv)
    rows = [dict(courant=1.0, spacing_m=l, error=0.1 * (l / 0.004) ** 2, peak_MPa=95.0 + 400.0 * l, particles=100, steps=10,
                 particle_steps=1000, cpu_s=1.0 / l, wall_s=1.0 / l) for l in (0.004, 0.002, 0.001)]
    paths = conv.paths("uniaxial_intact", rows)
    modulus = [p for p in paths if p["key"] == "error" and p["courant"] == 1.0][0]
    assert modulus["orders"] == pytest.approx([2.0, 2.0]) and modulus["reference_kind"] == "analytic"
    peak = [p for p in paths if p["key"] == "peak_MPa" and p["courant"] == 1.0][0]
    assert peak["richardson"]["order"] == pytest.approx(1.0) and peak["reference"] == pytest.approx(95.0)
    assert peak["error"][-1] == pytest.approx(0.4 / 95.0)
    assert [p for p in paths if p["courant"] == 0.5][0]["spacing_m"] == []     # no runs at C = 0.5: an empty path
    assert "| uniaxial_intact |" in conv.table(dict(families={"uniaxial_intact": dict(paths=paths, failed=[])}))


def test_tunnel_ensemble_reads_the_tunnel_scripts_files(tmp_path):
    """The spread of a tunnel run reads what scripts/paper/tunnel_spalling.py writes: σ at 2 mm from the summary's
    axial_stress_MPa_at rows, the first crack and the last snapshot's spalled areas from the case's case.json."""
    import json
    from yade_mpm_paper.report.uncertainty_sections import _tunnel_quantities
    (tmp_path / "intact").mkdir()
    snap = dict(spalled_by_place_mm2={"floor": 198.0}, left_waist_inward_mm=dict(p90=0.0157))
    json.dump(dict(snapshots={"08ms": dict(snap, spalled_by_place_mm2={"floor": 1.0}), "20ms": snap},
                   first_crack=dict(time=1.5826e-3, location="floor")), open(tmp_path / "intact" / "case.json", "w"))
    summary = dict(cases=[dict(case="intact", axial_stress_MPa_at=[dict(displacement_mm=d, stress_MPa=100 * d) for d in (0.5, 1.0, 2.0)])])
    q = _tunnel_quantities(str(tmp_path), summary)
    assert q["σ at 2 mm [MPa], intact"] == 200.0
    assert q["first crack [ms], intact"] == pytest.approx(1.5826)
    assert q["spalled at the floor [mm²], intact"] == 198.0 and q["left waist moved in, p90 [mm], intact"] == 0.0157


@pytest.mark.parametrize("scene", sorted(U.SHIFTS))
def test_each_ensemble_table_runs_the_declared_shifts(scene):
    """Every scripts/paper/*_shifts.table runs the shifts of uncertainty.SHIFTS (unshifted first), each line in the
    folder named after its shift, under the ensemble folder the report reads."""
    import os
    from yade_mpm_paper import batch
    from yade_mpm_paper.report.uncertainty_sections import ENSEMBLES
    folder, table, script = ENSEMBLES[scene]
    root = os.path.join(os.path.dirname(__file__), "..")
    assert os.path.isfile(os.path.join(root, script))
    runs = batch.lines(os.path.join(root, table))
    tab = batch.read_table(os.path.join(root, table))
    shifts = [U.parse_shift(batch._literal(tab[ln]["grid_shift"])) or (0.0, 0.0) for ln, _, _ in runs]
    plain = [s for (ln, d, _), s in zip(runs, shifts) if "_l" not in d]     # the tunnel's other-spacing lines keep shift 0
    assert plain == [tuple(s) for s in U.SHIFTS[scene]]
    for (ln, desc, run_dir), s in zip(runs, shifts):
        assert desc.startswith(U.shift_name(s)) and os.path.normpath(run_dir) == os.path.normpath(os.path.join("out", folder, desc))


def test_benchmark_ensembles_read_the_scripts_summaries():
    """The spread of the circular opening and the line crack reads the keys their scripts write (the summary names)."""
    from yade_mpm_paper.report.uncertainty_sections import QUANTITIES
    c = QUANTITIES["circular_opening"](None, dict(l2_rel_error_max=0.005, l2_rel_error_near_max=0.004, hoop_stress_theta0_MPa=11.4,
                                                  hoop_stress_theta90_MPa=48.3))
    assert sorted(c.values()) == [0.004, 0.005, 11.4, 48.3]
    p = QUANTITIES["penny_crack"](None, dict(uy_l2_rel_error=0.07, uy_center_rel_error=-0.01, syy_ahead_l2_rel_error=0.09,
                                             paper_comparison=dict(da_paper_cells=[34.0, 67.0, 91.0], initiation_t_paper_s=0.03)))
    assert p["Δa at t = 0.4 s [cells] (paper 72)"] == 91.0 and p["first growth, t on the paper's axis [s]"] == 0.03
    assert p["u_y L2 rel. error (Sneddon)"] == 0.07 and len(p) == 7
