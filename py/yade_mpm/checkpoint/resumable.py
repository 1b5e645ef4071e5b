"""Runs that survive interruptions: periodic checkpoints of the whole simulation (``yade_mpm.checkpoint``),
SIGINT / SIGTERM turned into "write a last checkpoint and the outputs, then stop cleanly", and a
resumable run of one case in its own folder (``ResumableRun``), as the reference scripts use it:

    job = ResumableRun(solver, "out/case", state={"curve": []}, meta={"case": "A"}, every_minutes=5)
    if not (resume and job.finished(end_time)):           # finished earlier: job.state is its record
        resumed = resume and job.resume()                  # the folder's checkpoint into the built scene
        status = job.run(end_time, outputs=[runner.Output(record, steps=1)], advance=O.step)

``parse_every("10min")`` reads a checkpoint period given on a command line.
"""
import json
import math
import numbers
import os
import time

from ..runner import STOP, TIME_TOL, Output, SignalStop, run


def _real(x):
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x)


def parse_every(text, option="--checkpoint-every"):
    """A checkpoint period as typed on a command line: "N" (steps, N ≥ 1; "0" = only at the end and on
    an interrupt) or "Xmin" (wall minutes, X > 0). Returns (every_steps, every_minutes), None for the
    unused one; ValueError naming `option` and the accepted forms."""
    t = str(text).strip()
    try:
        if t.endswith("min"):
            m = float(t[:-3])
            if math.isfinite(m) and m > 0:
                return None, m
        elif t.isdigit():
            return (int(t) or None), None
    except ValueError:
        pass
    raise ValueError(f"{option} = {text!r} must be a step count ≥ 0 (0: only at the end) or wall minutes like '10min'")


def _any_rank(flag):
    """`flag` on any MPI rank (a collective under MPI; the flag itself on one process)."""
    from .. import parallel
    if parallel.size() == 1:
        return bool(flag)
    from .. import _core
    return _core.mpiSum(1.0 if flag else 0.0) > 0


class Checkpointer:
    """Periodic checkpoints and clean stops for a run loop.

        ck = Checkpointer("out/run.ckpt", every_steps=20000, every_minutes=None)
        with ck.signals():                     # SIGINT/SIGTERM: ck.stop_requested becomes True
            while not done:
                O.run(chunk, True)
                ck.tick(steps)                 # saves when due
                if ck.stop_requested:
                    ck.save(); write_outputs(); break

    every_steps: steps between checkpoints (None = not by steps); every_minutes: wall minutes
    between checkpoints (None = not by time). save() passes `solvers`, `meta` and `extra()` (a
    function returning the script's JSON-able state, or None) to ``save``."""

    def __init__(self, path, every_steps=None, every_minutes=None, solvers=None, meta=None, extra=None, verbose=True):
        if every_steps is not None and not (_real(every_steps) and every_steps == int(every_steps) and every_steps >= 1):
            raise ValueError(f"every_steps = {every_steps!r} must be an integer ≥ 1 (steps between checkpoints) or None")
        if every_minutes is not None and not (_real(every_minutes) and every_minutes > 0):
            raise ValueError(f"every_minutes = {every_minutes!r} must be a number > 0 (wall minutes between checkpoints) or None; "
                             "from a command line use parse_every('10min')")
        every_steps = None if every_steps is None else int(every_steps)
        every_minutes = None if every_minutes is None else float(every_minutes)
        self.path, self.every_steps, self.every_minutes = path, every_steps, every_minutes
        self.solvers, self.meta, self.verbose = solvers, meta, verbose
        self.extra = extra                        # None or f() -> JSON-able script state saved with each checkpoint
        self.last_step, self.last_wall = None, time.time()
        self.stop_requested, self.signal_name = False, None
        self.saved = 0

    def due(self, step):
        if self.last_step is None:
            self.last_step = step
        if self.every_steps is not None and step - self.last_step >= self.every_steps:
            return True
        return self.every_minutes is not None and time.time() - self.last_wall >= 60 * self.every_minutes

    def tick(self, step):
        """Save if a checkpoint is due at this step. Returns True if one was written. MPI: due on any rank
        (wall minutes differ between ranks) is due on every rank (a collective: every rank ticks)."""
        if _any_rank(self.due(step)):
            self.save(step)
            return True
        return False

    def save(self, step=None):
        from .serial import save
        nbytes = save(self.path, solvers=self.solvers, meta=self.meta, extra=self.extra() if self.extra else None)
        self.last_step = step if step is not None else self.last_step
        self.last_wall = time.time()
        self.saved += 1
        if self.verbose:
            print(f"[checkpoint] {self.path} ({nbytes / 1e6:.1f} MB)" + (f" at step {step}" if step is not None else ""), flush=True)

    def output(self, steps=50):
        """A ``runner.Output`` that checks every `steps` steps: writes a checkpoint when one is due and
        ends the run (``runner.STOP``, so the run's at_end outputs are written) after SIGINT/SIGTERM."""
        def check(solver):
            if _any_rank(self.stop_requested):    # MPI: a signal seen by one rank stops every rank
                self.stop_requested = True
                return STOP
            self.tick(solver.steps)
            return None
        return Output(check, steps=steps)

    def signals(self):
        """Context manager: SIGINT and SIGTERM set `stop_requested` (the loop then saves and stops)
        instead of killing the process; a second signal stops at once. Handlers restored on exit."""
        ck = self

        def first(name):
            ck.stop_requested, ck.signal_name = True, name
            print(f"\n[checkpoint] {name}: writing a last checkpoint and the outputs, then stopping "
                  "(send it again to stop at once)", flush=True)
        return SignalStop(first, already=lambda: ck.stop_requested)


class ResumableRun:
    """One case run in its own folder `directory`, resumable after an interruption.

    state: the script's JSON-able record (curves, events …), saved with every checkpoint and in
    DIR/state.json at the end; the run adds wall [s], steps_run (both summed over resumes), done,
    time [s], steps and, after a solver error, error. meta: JSON-able identity of the case, checked
    on resume (``checkpoint.load``). Checkpoints go to DIR/checkpoint.ckpt every `every_steps` steps
    or `every_minutes` wall minutes (both None: only at the end and on SIGINT/SIGTERM). engine: the
    ``MpmEngine`` whose ``error`` holds a solver error raised inside YADE's loop (YADE re-raises it
    as a RuntimeError)."""

    def __init__(self, solver, directory, state=None, meta=None, every_steps=None, every_minutes=None, engine=None):
        self.solver, self.dir, self.meta, self.engine = solver, str(directory), meta, engine
        os.makedirs(self.dir, exist_ok=True)
        self.ckpt = os.path.join(self.dir, "checkpoint.ckpt")
        self.state_file = os.path.join(self.dir, "state.json")
        self.state = dict(state or {})
        for k, v in (("wall", 0.0), ("steps_run", 0), ("done", False)):
            self.state.setdefault(k, v)
        self.ck = Checkpointer(self.ckpt, every_steps, every_minutes, meta=meta, extra=lambda: self.state)
        self.resumed, self.error, self.interrupted, self.stop_reason = False, None, False, None

    def finished(self, end_time):
        """True if an earlier run in this folder reached `end_time` [s] (its state.json says so); then
        ``state`` is that run's record."""
        if not os.path.exists(self.state_file):
            return False
        with open(self.state_file) as f:
            st = json.load(f)
        if st.get("done") and st.get("time", 0) >= end_time * (1 - TIME_TOL):
            self.state = st
            return True
        return False

    def resume(self):
        """Loads the folder's checkpoint into the freshly built scene (``checkpoint.load``: refuses
        another scene or build) and its record into ``state``. Returns False when there is none."""
        if not os.path.exists(self.ckpt):
            return False
        from .serial import load
        self.state = load(self.ckpt, meta=self.meta)["extra"]
        self.resumed = True
        return True

    def run(self, end_time, outputs=(), progress=None, label="mpm", advance=None, check_every=50):
        """``runner.run`` to `end_time` [s] with the checkpoints (checked every `check_every` steps) and
        the signal handling. Returns "finished" (end time reached), "stopped" (a signal or another stop:
        a last checkpoint was written, ``resume`` continues) or "failed" (the solver stopped with an
        error: ``error`` names it; no checkpoint, the state is half-updated)."""
        s, st = self.solver, self.state
        if s.time >= end_time * (1 - TIME_TOL):                 # a resumed run that had finished
            st["done"] = True
            return "finished"
        outs = list(outputs) + [self.ck.output(steps=check_every)]
        wall0, steps0, res = time.time(), s.steps, None
        with self.ck.signals():
            try:
                res = run(s, end_time=end_time, progress=progress, label=label, outputs=outs, advance=advance)
            except RuntimeError as e:                           # MpmSimulationError, or YADE's wrapper of it
                self.error = str(getattr(self.engine, "error", None) or e)
        st["wall"] += time.time() - wall0
        st["steps_run"] += s.steps - steps0
        if self.error:
            st["error"] = self.error
            return "failed"
        st["done"] = res.reason == "end_time"
        st["time"], st["steps"] = s.time, int(s.steps)
        self.ck.save(s.steps)                                   # the last state: resumable, or the finished run
        with open(self.state_file, "w") as f:                   # the record, readable without the build
            json.dump(st, f)
        self.interrupted, self.stop_reason = self.ck.stop_requested, self.ck.signal_name or res.reason
        return "finished" if st["done"] else "stopped"
