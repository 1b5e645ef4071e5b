"""The one run loop of the scripts: step a solver until an end time, a step count or a stop criterion,
print progress lines with an ETA, and call output callbacks at simulated-time periods, step periods
or given simulated times.

    from yade_mpm import runner
    series = output.VtuSeries("out/run")                       # particles_NNNNNN.vtu + particles.pvd
    res = runner.run(solver, end_time=0.02, progress=10.0, label="tunnel",
                     every=[(1e-3, series.write)],             # every 1 ms of simulated time
                     outputs=[runner.Output(record, steps=100, at_end=True)],
                     stop=lambda s: s.kineticEnergy() < 1e-6)
    res.reason    # "end_time", "max_steps", "stop" or "interrupted"

With periodic checkpoints and a clean stop on SIGTERM as well (yade_mpm.checkpoint):

    ck = checkpoint.Checkpointer("out/run.ckpt", every_minutes=30, solvers=solver)
    with ck.signals():                                         # SIGINT/SIGTERM set ck.stop_requested
        runner.run(solver, end_time=T, stop=lambda s: ck.stop_requested,
                   outputs=[runner.Output(lambda s: ck.tick(s.steps), steps=100),
                            runner.Output(lambda s: ck.save(s.steps), at_end=True)])

A callback is ``f(solver)``; it may return ``runner.STOP`` to end the run after this step (a
convergence check that is expensive to evaluate every step). ``stop(solver)`` is evaluated after every
step. Ctrl-C (KeyboardInterrupt) ends the run cleanly: the ``at_end`` outputs are called with the
state of the last completed step, then the interrupt is re-raised (default) or the run returns with
reason "interrupted" (``on_interrupt="return"``). A solver error (``MpmSimulationError``; through YADE's
``O.step`` a ``RuntimeError``) ends the run at once, without the ``at_end`` outputs, since the state is then
half-updated: it propagates (default) or, with ``on_error="return"``, the run returns with reason "error" and the
message in ``RunResult.error`` (a script that runs several cases records it and goes on to the next).
"""
import math
import numbers
import signal
import time as _time

from .progress import Progress

# relative tolerance on simulated times: a step ending within 1e-12·t of a target counts as reaching it
# (a sum of Δt rarely hits a target exactly)
TIME_TOL = 1e-12


class SignalStop:
    """Context manager: SIGINT and SIGTERM ask the run to end at the next step boundary instead of killing
    the process (SIGINT too when the process started with it ignored, a background job). The first signal
    sets `requested` and `name` and calls `on_first(name)`; a signal while `already()` (default: `requested`)
    holds raises KeyboardInterrupt at once. Handlers restored on exit; outside the main thread none are
    installed. A run reads `requested` in its `stop` or an Output (the checkpointer's, compression_run's)."""

    def __init__(self, on_first=None, already=None):
        self.requested, self.name = False, None
        self.on_first, self.already = on_first, already or (lambda: self.requested)

    def __enter__(self):
        self.old = {}
        for sig in (signal.SIGINT, signal.SIGTERM):
            try:
                self.old[sig] = signal.signal(sig, self._handler)
            except ValueError:                    # not the main thread: no signal handling
                pass
        return self

    def _handler(self, signum, frame):
        if self.already():                        # second signal: give up the clean stop
            raise KeyboardInterrupt
        self.requested, self.name = True, signal.Signals(signum).name
        if self.on_first:
            self.on_first(self.name)

    def __exit__(self, *exc):
        for sig, h in self.old.items():
            signal.signal(sig, h)
        return False


class _Stop:
    def __repr__(self):
        return "runner.STOP"


STOP = _Stop()


class Output:
    """A callback ``f(solver)`` and when to call it (after a step; at most once per step):

    period   simulated seconds [s] since its last call (or the run's start), > 0
    steps    every `steps` steps of this run, integer ≥ 1
    times    simulated times [s]: once at the first step ending at or after each
    at_start once before the first step
    at_end   once after the last step (end time, step limit, stop, interrupt), unless already called
             at that step
    """

    def __init__(self, callback, period=None, steps=None, times=(), at_start=False, at_end=False):
        if not callable(callback):
            raise ValueError(f"callback = {callback!r} must be callable as f(solver)")
        if period is not None and not (_real(period) and period > 0):
            raise ValueError(f"period = {period!r} s must be a finite number > 0 (simulated seconds)")
        if steps is not None and not (_integer(steps) and steps >= 1):
            raise ValueError(f"steps = {steps!r} must be an integer ≥ 1")
        if not all(_real(t) for t in times):
            raise ValueError(f"times = {list(times)} must be finite simulated times [s]")
        times = [float(t) for t in times]
        if period is None and steps is None and not times and not at_start and not at_end:
            raise ValueError("Output needs at least one of period, steps, times, at_start, at_end")
        self.callback, self.period, self.steps = callback, period, steps
        self.times, self.at_start, self.at_end = sorted(times), bool(at_start), bool(at_end)

    def _begin(self, solver):
        self._last_time = solver.time
        start = solver.time                   # times before the run's start are dropped, the start itself is kept
        self._pending = [t for t in self.times if t >= start - TIME_TOL * abs(start)]
        self._called_at = None

    def _due(self, solver, taken):
        due = False
        if self.period is not None and _reached(solver.time, self._last_time + self.period):
            due = True
        if self.steps is not None and taken % self.steps == 0:
            due = True
        while self._pending and _reached(solver.time, self._pending[0]):
            self._pending.pop(0)
            due = True
        return due

    def _call(self, solver):
        self._last_time = solver.time
        self._called_at = solver.steps
        return self.callback(solver) is STOP


def _real(x):
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x)


def _integer(x):
    return isinstance(x, numbers.Integral) and not isinstance(x, bool)


def _reached(t, target):
    return t >= target - TIME_TOL * abs(target)


class RunResult:
    """How a run ended: reason ("end_time", "max_steps", "stop", "interrupted", "error"), steps taken in this
    run, simulated time at the end [s], wall time [s], and for "error" the solver's message (else None)."""

    def __init__(self, reason, steps, time, wall, error=None):
        self.reason, self.steps, self.time, self.wall, self.error = reason, steps, time, wall, error

    def __repr__(self):
        tail = f", error={self.error!r}" if self.error is not None else ""
        return f"RunResult(reason={self.reason!r}, steps={self.steps}, time={self.time:.6g}, wall={self.wall:.3g}{tail})"


def _outputs(every, outputs):
    res = []
    for e in every:
        if isinstance(e, Output):
            res.append(e)
            continue
        try:
            period, cb = e
        except (TypeError, ValueError):
            raise ValueError(f"every: entry {e!r} must be (period [s], callback) or an Output") from None
        res.append(Output(cb, period=period))
    for o in outputs:
        if not isinstance(o, Output):
            raise ValueError(f"outputs: entry {o!r} must be a runner.Output")
        res.append(o)
    return res


def run(solver, end_time=None, max_steps=None, progress=None, label="mpm", stop=None, every=(), outputs=(),
        before_step=None, on_interrupt="raise", advance=None, on_error="raise"):
    """Step `solver` until simulated time ≥ end_time [s] (absolute solver time), or `max_steps` steps of
    this call, or ``stop(solver)`` is true after a step, or an output callback returns STOP.

    progress: None (silent), wall seconds between progress lines, or a ``Progress``; label names the lines.
    every: [(period [s], callback), …] or Output objects; outputs: Output objects (see Output).
    before_step: f(solver) called before each step (e.g. to take ``stableDt()`` of the state before it).
    on_interrupt: "raise" (re-raise KeyboardInterrupt after the at_end outputs) or "return".
    on_error: "raise" (a solver error propagates) or "return" (RunResult with reason "error" and its message).
    advance: f() that advances the whole simulation by one step (default ``solver.run(1)``); YADE's
    ``O.step`` when the solver runs inside O.engines through an MpmEngine (rigid bodies, DEM).
    Returns a RunResult."""
    if end_time is not None and not _real(end_time):
        raise ValueError(f"end_time = {end_time!r} s must be a finite number (absolute simulated time) or None")
    if max_steps is not None and not (_integer(max_steps) and max_steps >= 0):
        raise ValueError(f"max_steps = {max_steps!r} must be an integer ≥ 0 or None")
    if stop is not None and not callable(stop):
        raise ValueError(f"stop = {stop!r} must be callable as stop(solver) -> bool")
    if before_step is not None and not callable(before_step):
        raise ValueError(f"before_step = {before_step!r} must be callable as f(solver)")
    if on_interrupt not in ("raise", "return"):
        raise ValueError(f"on_interrupt = {on_interrupt!r} must be 'raise' or 'return'")
    if on_error not in ("raise", "return"):
        raise ValueError(f"on_error = {on_error!r} must be 'raise' or 'return'")
    if advance is not None and not callable(advance):
        raise ValueError(f"advance = {advance!r} must be callable as f() (one step of the simulation)")
    step = advance if advance is not None else _governed(lambda: solver.run(1))   # through YADE the MpmEngine reports the steps
    outs = _outputs(every, outputs)
    if progress is None or progress is False:
        prog = None
    elif isinstance(progress, Progress):
        prog = progress
    elif _real(progress) and progress > 0:
        prog = Progress(end_time, label, float(progress), total_steps=max_steps)
    else:
        raise ValueError(f"progress = {progress!r} must be None, wall seconds > 0 or a Progress")
    if end_time is None and max_steps is None and stop is None and not outs:
        raise ValueError("run would never end: give end_time, max_steps, stop or an output that returns STOP")

    wall0 = _time.time()
    taken, reason = 0, None
    if prog is not None:
        prog.solver = solver                      # its lines report the particles removed after leaving the grid
        prog.update(solver.steps, solver.time)    # the first update fixes where the ETA counts from
    for o in outs:
        o._begin(solver)
    try:
        for o in outs:
            if o.at_start and o._call(solver):
                reason = "stop"
        while reason is None:
            if end_time is not None and _reached(solver.time, end_time):
                reason = "end_time"
                break
            if max_steps is not None and taken >= max_steps:
                reason = "max_steps"
                break
            if before_step is not None:
                before_step(solver)
            step()
            taken += 1
            if prog is not None:
                prog.update(solver.steps, solver.time)
            for o in outs:
                if o._due(solver, taken) and o._call(solver):
                    reason = "stop"
            if reason is None and stop is not None and stop(solver):
                reason = "stop"
    except KeyboardInterrupt:
        _finish(solver, outs, prog)
        if on_interrupt == "raise":
            raise
        return RunResult("interrupted", taken, solver.time, _time.time() - wall0)
    except RuntimeError as e:                      # MpmSimulationError, or through YADE's O.step a RuntimeError
        if on_error == "raise":
            raise
        return RunResult("error", taken, solver.time, _time.time() - wall0, error=str(e))
    _finish(solver, outs, prog)
    return RunResult(reason, taken, solver.time, _time.time() - wall0)


def _governed(step):
    """step(), its wall time reported to the thread governor (yade_mpm.threads) when one is active."""
    from .threads import governor
    if governor() is None:
        return step

    def timed():
        t = _time.perf_counter()
        step()
        gov = governor()
        if gov is not None:
            gov.tick(_time.perf_counter() - t)
    return timed


def _finish(solver, outs, prog):
    for o in outs:
        if o.at_end and o._called_at != solver.steps:
            o._call(solver)
    if prog is not None:
        prog.update(solver.steps, solver.time, force=True)
