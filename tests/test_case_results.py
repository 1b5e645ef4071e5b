"""The run records of yade_mpm_paper.cases.tunnel_results / uniaxial_results on constructed curves whose
answers are known (the scripts' end-to-end tests run them on real runs: test_tunnel_script, test_studies)."""
import json

import numpy as np
import pytest

from yade_mpm_paper.cases import tunnel_results, uniaxial_results


def entry(case, stresses):
    return {"case": case, "axial_stress_MPa_at": [{"displacement_mm": 0.1 * k, "stress_MPa": s} for k, s in enumerate(stresses)]}


def test_fig17_ordering_counts_the_samples_where_it_holds():
    e = [entry("intact", [0, 10, 20, 30]), entry("open_flaw", [0, 9, 21, 29]), entry("filled_flaw", [0, 11, 22, 29.5])]
    o = tunnel_results.ordering(e)
    assert o == dict(samples=3, holds=1, fraction=pytest.approx(1 / 3))   # 0.1 mm holds; 0.2 (open above), 0.3 (filled below) do not
    assert tunnel_results.ordering(e[:2]) is None


def test_sampled_curve_every_step_in_mm_and_MPa():
    curve = [[0.0, 0.0, 0.0], [1.0, 0.2e-3, 4e6], [2.0, 0.45e-3, 9e6]]            # time, displacement [m], stress [Pa]
    s = tunnel_results.sample_curve(curve, 0.1)
    assert [p["displacement_mm"] for p in s] == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4])
    assert [p["stress_MPa"] for p in s] == pytest.approx([0.0, 2.0, 4.0, 6.0, 8.0])


def test_peak_and_modulus_of_a_linear_then_softening_curve():
    eps = np.linspace(0, 2e-3, 201)
    E = 7.3e9                                   # a synthetic modulus (not a rock set's)
    sig = np.where(eps <= 1e-3, E * eps, E * 1e-3 - 5e9 * (eps - 1e-3))
    k, e_fit = uniaxial_results.peak_and_modulus(eps, sig)
    assert eps[k] == pytest.approx(1e-3) and e_fit == pytest.approx(E, rel=1e-9)
    assert np.isnan(uniaxial_results.peak_and_modulus(eps[:3], sig[:3])[1])     # too few points before the peak


def test_a_reaction_spike_is_not_the_peak(tmp_path):
    # A one-step spike of the platen reaction (a diverging fragment under the platen's edge) after a smooth peak: the
    # peak and the modulus are those of the smooth curve, and the spikes are counted; a record written before spikes
    # were told apart is derived again from its curve.csv.
    eps = np.linspace(0, 2e-3, 201)
    E = 7.3e9
    sig = np.where(eps <= 1e-3, E * eps, E * 1e-3 - 2e9 * (eps - 1e-3))
    clean = uniaxial_results.peak_and_modulus(eps, sig)
    spiky = sig.copy()
    spiky[150] *= 4.0                                                            # 4 × the value, one sample
    spiky[60] += 0.45 * sig[59]                                                  # below the share: not a spike
    assert list(uniaxial_results.reaction_spikes(spiky)) == [150]
    assert uniaxial_results.peak_and_modulus(eps, spiky) == clean
    assert len(uniaxial_results.reaction_spikes(sig)) == 0
    t = np.arange(len(eps)) * 1e-7
    np.savetxt(tmp_path / "curve.csv", np.column_stack([t, eps, spiky / 1e6]), delimiter=",", header="time_s,axial_strain,axial_stress_MPa")
    entry = dict(dir=str(tmp_path), peak_stress_MPa=float(spiky.max() / 1e6), strain_at_peak=0.0)
    assert uniaxial_results.rescore(entry)
    assert entry["peak_stress_MPa"] == pytest.approx(sig.max() / 1e6) and entry["strain_at_peak"] == pytest.approx(1e-3)
    assert entry["reaction_spikes"] == dict(count=1, first_time_s=pytest.approx(t[150]), largest_MPa=pytest.approx(spiky[150] / 1e6))
    assert json.load(open(tmp_path / "run.json"))["peak_stress_MPa"] == entry["peak_stress_MPa"]
    assert not uniaxial_results.rescore(entry)                                   # done once


def test_softened_only_past_a_real_peak():
    rise = [(t, 0.0, 1e6 * t) for t in range(11)]                              # peak 10 MPa at t = 10
    assert not uniaxial_results.softened(rise, 10.0)
    drop = rise + [(13.0, 0.0, 5.9e6)]
    assert uniaxial_results.softened(drop, 13.0)                                # < 60 % of the peak, t > 1.2 × 10
    assert not uniaxial_results.softened(drop, 11.5)                            # too soon after the peak
    small = [(t, 0.0, 1e5 * t) for t in range(11)] + [(13.0, 0.0, 1e5)]
    assert not uniaxial_results.softened(small, 13.0)                           # a peak below 5 MPa is no peak


def test_run_names():
    assert uniaxial_results.run_name("open", 0.4, 1.0) == "open"
    assert uniaxial_results.run_name("filled", 0.4, 0.0) == "filled_mu0.4_c0MPa"


def test_compression_run_keeps_the_curve_when_the_solver_stops_the_run(tmp_path):
    # A long run that the solver stops (a particle off the grid, a particle without a fit) must keep what it measured:
    # curve.csv up to the error, result.reason "error" and the message. Here a particle is moved off the grid
    # through a view at step 30, which the solver refuses at the next step.
    import yade_mpm as ym
    from yade_mpm import runner
    from yade_mpm_paper import cases
    s, sc = cases.uniaxial_flaw("intact", 0.005, side_room=0.01)

    def spoil(solver):
        if solver.steps == 30:
            solver.view("x1")[0] = 10.0
    r = uniaxial_results.compression_run(s, sc, str(tmp_path), 1e-3, 1e9, "spoilt", lambda solver: None, dict(steps=1000),
                                         dict(period=1.0), [runner.Output(spoil, steps=1)])
    assert r["result"].reason == "error" and "outside the grid" in r["result"].error, r["result"].error
    c = np.loadtxt(tmp_path / "curve.csv", delimiter=",", skiprows=1)
    assert len(c) == 30 and np.all(np.diff(c[:, 0]) > 0) and c[-1, 2] > 0       # every step before the refused one
    assert len(r["t"]) == 30 and r["peak"] == int(np.argmax(r["sig"]))


def test_compression_run_ends_cleanly_on_sigterm(tmp_path):
    # kill PID of a background loading run: the curve up to the signal is written and the run says "interrupted"
    import os
    import signal
    from yade_mpm import runner
    from yade_mpm_paper import cases
    s, sc = cases.uniaxial_flaw("intact", 0.005, side_room=0.01)

    def term(solver):
        if solver.steps == 20:
            os.kill(os.getpid(), signal.SIGTERM)
    r = uniaxial_results.compression_run(s, sc, str(tmp_path), 1e-3, 1e9, "term", lambda solver: None, dict(steps=1000),
                                         dict(period=1.0), [runner.Output(term, steps=1)])
    assert r["result"].reason == "interrupted"
    c = np.loadtxt(tmp_path / "curve.csv", delimiter=",", skiprows=1)
    assert 20 <= len(c) <= 21 and c[-1, 2] > 0
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL       # the handler is gone after the run


def test_end_analytics_of_a_run_stopped_without_a_fit():
    # A run the solver stopped because a particle has no WLS fit (every stencil node excluded) still reports its
    # cracks: the end analytics read no field that needs a fit at the current positions (the material velocity
    # does, and raises). Here every node is excluded, so no particle has a fit.
    import yade_mpm as ym
    from yade_mpm import analysis
    from yade_mpm_paper import cases
    s, sc = cases.uniaxial_flaw("intact", 0.005, side_room=0.01)
    s.run(3)
    for i in range(len(s._excludedNodes())):
        try:
            s._setNodeExcluded(i, True)
        except ValueError:                                  # a ghost node: excluded already
            pass
    with pytest.raises(ym.MpmSimulationError, match="no active grid node"):
        ym.get(s, "vel")
    lattice = analysis.Lattice(ym.get(s, "pos"), s.spacing / 2, origin=(0, 0))
    end = uniaxial_results.end_analytics(s, lattice, None, {}, s.spacing)
    assert end["damaged_fraction_end"] == 0.0 and end["cracks_end"] == []
