"""The one run loop (yade_mpm.runner) and the VTU series writer (yade_mpm.output.VtuSeries), on a small
block at rest: no load, so Δt = C·l/c_p exactly (c_p the P-wave speed of the rock) and every stop and
output time can be predicted independently of the loop."""
import base64
import math
import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import yade_mpm as ym
from yade_mpm import output, rocks, runner


def block():
    s = ym.make_solver((0, 0), (0.2, 0.2), 0.02)
    mat = rocks.granite()
    ym.add_region(s, mat, (0, 0), (0.2, 0.2))
    return s, s.courant * s.spacing / mat.pWaveSpeed()


def test_end_time_and_max_steps():
    s, dt = block()
    res = runner.run(s, end_time=100.5 * dt)
    assert res.reason == "end_time" and res.steps == 101 and s.steps == 101
    res = runner.run(s, end_time=np.float64(1.0), max_steps=np.int64(17))   # counts the steps of this call
    assert res.reason == "max_steps" and res.steps == 17 and s.steps == 118
    assert runner.run(s, end_time=s.time).steps == 0         # already there: no step


def test_output_triggers():
    s, dt = block()
    by_period, by_steps, by_times, ends = [], [], [], []
    times = [10.5 * dt, 10.7 * dt, 40.2 * dt, 1.0]             # the last lies beyond the end
    res = runner.run(s, end_time=60.5 * dt, outputs=[
        runner.Output(lambda s: by_period.append(s.steps), period=7.3 * dt),
        runner.Output(lambda s: by_steps.append(s.steps), steps=11),
        runner.Output(lambda s: by_times.append(s.steps), times=times),
        runner.Output(lambda s: ends.append(s.steps), at_start=True, at_end=True)])
    assert res.steps == 61
    # period: the first step at least 7.3 Δt after the previous call (t = 0 at the start): steps 8, 16, 24, …
    assert by_period == list(range(8, 62, 8))
    assert by_steps == [11, 22, 33, 44, 55]
    assert by_times == [11, 41]                              # 10.5 and 10.7 Δt both end at step 11: one call
    assert ends == [0, 61]


def test_stop_criteria():
    s, _ = block()
    res = runner.run(s, end_time=1.0, stop=lambda s: s.steps >= 13)
    assert res.reason == "stop" and s.steps == 13
    calls = []

    def converged(s):
        calls.append(s.steps)
        if len(calls) == 3:
            return runner.STOP

    res = runner.run(s, end_time=1.0, outputs=[runner.Output(converged, steps=5, at_end=True)])
    assert res.reason == "stop" and s.steps == 28 and calls == [18, 23, 28]   # at_end: not twice at step 28


def test_keyboard_interrupt_writes_outputs_so_far(tmp_path):
    s, dt = block()
    series = output.VtuSeries(str(tmp_path), "p")
    final = []

    def ctrl_c(s):
        if s.steps == 25:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        runner.run(s, end_time=1.0, every=[(10 * dt * (1 - 1e-9), series.write)],
                   outputs=[runner.Output(ctrl_c, steps=1), runner.Output(lambda s: final.append(s.steps), at_end=True)])
    assert final == [25]
    steps = [int(ds.get("file")[2:10]) for ds in ET.parse(tmp_path / "p.pvd").getroot().iter("DataSet")]
    assert steps == [10, 20]
    res = runner.run(s, end_time=1.0, on_interrupt="return", outputs=[runner.Output(ctrl_c, steps=1)],
                     stop=lambda s: s.steps > 100)
    assert res.reason == "stop"                               # step 25 is behind: no interrupt now
    s2, _ = block()
    res = runner.run(s2, end_time=1.0, on_interrupt="return", outputs=[runner.Output(ctrl_c, steps=1)])
    assert res.reason == "interrupted" and s2.steps == 25


def _decode(text):
    raw = base64.b64decode(text.strip())
    n = int(np.frombuffer(raw[:8], "<u8")[0])
    return raw[8:8 + n]


def test_vtu_series_index_and_data(tmp_path):
    """The .pvd lists every file with its simulated time; each .vtu holds the particle positions of that
    moment (decoded here from the base64 + UInt64-length layout ParaView expects)."""
    s, _ = block()
    s.view("v0")[:] = 1.0                                    # move rigidly: x(t) = x0 + t
    s.requestSort()
    dt = s.courant * s.spacing / (rocks.granite().pWaveSpeed() + 1.0)   # C·l/(c_p + max‖v‖)
    x0 = ym.get(s, "pos")
    series = output.VtuSeries(str(tmp_path / "series"))
    runner.run(s, max_steps=30, every=[(12 * dt * (1 - 1e-9), series.write)],
               outputs=[runner.Output(series.write, at_start=True, at_end=True)])
    root = ET.parse(tmp_path / "series" / "particles.pvd").getroot()
    assert root.get("type") == "Collection"
    entries = [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]
    assert [f for _, f in entries] == [f"particles_{k:08d}.vtu" for k in (0, 12, 24, 30)]
    for t, f in entries:
        vtu = ET.parse(tmp_path / "series" / f).getroot()
        piece = vtu.find("UnstructuredGrid/Piece")
        n = int(piece.get("NumberOfPoints"))
        assert n == s.numParticles
        pts = np.frombuffer(_decode(piece.find("Points/DataArray").text), "<f8").reshape(n, 3)
        ids = next(a for a in piece.iter("DataArray") if a.get("Name") == "id")
        order = np.argsort(np.frombuffer(_decode(ids.text), "<i8"))
        k = int(f[10:18])
        assert t == pytest.approx(k * dt, rel=1e-12)
        # a free block at uniform velocity translates rigidly (no stress, no gravity)
        assert np.allclose(pts[order, 0], x0[:, 0] + t, rtol=0, atol=1e-12)
        assert np.allclose(pts[order, 1], x0[:, 1], rtol=0, atol=1e-12)
        assert np.all(pts[:, 2] == 0)


@pytest.mark.parametrize("kw, name", [(dict(end_time=math.nan), "end_time"), (dict(max_steps=-1), "max_steps"),
                                      (dict(max_steps=2.5), "max_steps"), (dict(stop=3), "stop"),
                                      (dict(every=[(0.0, print)]), "period"), (dict(every=[print]), "every"),
                                      (dict(outputs=[print]), "outputs"), (dict(on_interrupt="ignore"), "on_interrupt"),
                                      (dict(progress=-1), "progress"), (dict(), "never end")])
def test_bad_arguments(kw, name):
    s, _ = block()
    with pytest.raises(ValueError, match=name):
        runner.run(s, **kw)
    assert s.steps == 0
    with pytest.raises(ValueError, match="steps"):
        runner.Output(print, steps=0)
    with pytest.raises(ValueError, match="at least one"):
        runner.Output(print)


def test_real_sigint_stops_after_the_outputs(tmp_path):
    """Ctrl-C as the OS delivers it (SIGINT to this process, Python's default handler) in the middle of
    a run: the at_end outputs see the last completed step and the .pvd lists every file written.
    The test installs Python's default SIGINT handler itself (a process started from a non-interactive
    background shell inherits SIGINT ignored, and the signal would be dropped) and bounds the run to 200
    steps, so a signal that does not arrive fails it at once instead of running to end_time."""
    import signal
    s, dt = block()
    series = output.VtuSeries(str(tmp_path))

    def ctrl_c(s):
        if s.steps == 25:
            os.kill(os.getpid(), signal.SIGINT)

    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        res = runner.run(s, end_time=1.0, max_steps=200, on_interrupt="return", every=[(10 * dt * (1 - 1e-9), series.write)],
                         outputs=[runner.Output(ctrl_c, steps=1), runner.Output(series.write, at_end=True)])
    finally:
        signal.signal(signal.SIGINT, old)
    assert res.reason == "interrupted" and 25 <= s.steps <= 26, res
    files = [d.get("file") for d in ET.parse(tmp_path / "particles.pvd").getroot().iter("DataSet")]
    assert files == [f"particles_{k:08d}.vtu" for k in (10, 20, s.steps)]
    assert all((tmp_path / f).exists() for f in files)


def test_solver_error_propagates_or_returns_with_its_message():
    """The intact body pushed off the grid (the stability suite's grid_edge case) stops the solver: by default the error
    propagates; with on_error="return" the run returns reason "error" with the solver's message and the steps it took;
    a bad on_error is named."""
    from yade_mpm_paper.validation import stability_cases as sc
    s, _ = sc.case_grid_edge(True)
    with pytest.raises(ym.MpmSimulationError):
        runner.run(s, max_steps=10000)
    s, _ = sc.case_grid_edge(True)
    r = runner.run(s, max_steps=10000, on_error="return")
    assert r.reason == "error" and "left the grid" in r.error and 0 < r.steps < 10000 and s.steps == r.steps
    assert "error=" in repr(r)
    with pytest.raises(ValueError, match="on_error = 'ignore' must be 'raise' or 'return'"):
        runner.run(s, max_steps=1, on_error="ignore")
    s, _ = sc.case_grid_edge(True)
    assert runner.run(s, max_steps=1).error is None


def test_progress_line_reports_the_step_and_flags_a_fallen_one():
    """The progress line shows the last Δt; one below Progress.DT_DROP of the largest seen is flagged (a run that slows
    by that factor says why it may, doc/validation/stability.md)."""
    import io
    s, _ = block()
    s.run(3)
    out = io.StringIO()
    prog = ym.progress.Progress(1.0, "p", interval=0.0, stream=out)
    prog.update(s.steps, s.time, force=True, solver=s)
    dt = s.lastDt
    assert f"Δt {dt:.3g} s" in out.getvalue() and "expanding" not in out.getvalue()

    class Fallen:                                   # the same solver's account, a step 10× below the largest seen
        lastDt = dt / 10
        _removedAccount = staticmethod(s._removedAccount)
    prog.update(s.steps, s.time, force=True, solver=Fallen())
    last = out.getvalue().splitlines()[-1]
    assert f"Δt {dt / 10:.3g} s (1/10 of the largest" in last, last
