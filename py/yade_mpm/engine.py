"""The YADE hook. Debian ships YADE without C++ headers, so the MPM solver cannot be compiled as a
YADE Engine subclass; it joins YADE's loop through YADE's own Python engine, a PyRunner with
iterPeriod=1 and initRun=True placed in O.engines like any engine:

    O.engines = [ForceResetter(), ..., MpmEngine(solver, label='mpm').runner(), NewtonIntegrator()]

Each YADE iteration it advances the MPM particles by O.dt, lowering O.dt first when the MPM stable
step requires it (and raising it back towards the step the user/DEM asked for when possible), so
O.time and O.iter stay the simulation's clock. The PyRunner carries the label, and
``yade_mpm.engine.by_label('mpm')`` returns this object from that label.

With rigid bodies (``bodies``, a ``yade_mpm.RigidBodies``), each step reads their kinematics from
O.bodies before the MPM step and adds the contact reactions to O.forces after it, so the PyRunner must
come after ForceResetter and before NewtonIntegrator."""
import time as _time

from .progress import Progress
from .threads import governor

_registry = {}


def by_label(label):
    """The MpmEngine registered under a YADE engine label."""
    try:
        return _registry[label]
    except KeyError:
        raise KeyError(f"no MPM engine labelled '{label}'; known: {sorted(_registry)}. The registry lives in "
                       "this Python process: after O.load (or in a new process) restore the MPM state with "
                       "yade_mpm.checkpoint.load(...), which registers the engines again") from None


class MpmEngine:
    def __init__(self, solver, label="mpm", progress_interval=None, end_time=None, bodies=None):
        """solver: a Solver2D/3D; label: YADE engine label; progress_interval: wall seconds between
        progress lines (None = silent); end_time: simulated end time [s] for the ETA; bodies: the
        RigidBodies or DemSpheres in contact with the particles, or a list of them (rigid platens and
        DEM spheres in one scene); None: no contact code runs."""
        from .scene import dim_of
        dim_of(solver)                                    # ValueError unless a Solver2D/Solver3D
        adapters = [] if bodies is None else list(bodies) if isinstance(bodies, (list, tuple)) else [bodies]
        for b in adapters:
            if getattr(b, "solver", None) is not solver or not (callable(getattr(b, "read", None)) and callable(getattr(b, "write", None))):
                raise ValueError("bodies must be a yade_mpm.RigidBodies / DemSpheres (or a list of them) built on this engine's solver")
        self.bodies = bodies
        self._adapters = adapters
        if not isinstance(label, str) or not label.isidentifier():
            raise ValueError(f"label = {label!r} must be a Python identifier (YADE exposes labels as names)")
        self.solver, self.label = solver, label
        self.user_dt = None       # the O.dt asked for by the user/DEM side
        self.last_set_dt = None   # the O.dt this engine set last
        self.error = None
        self.progress = Progress(end_time, label, progress_interval) if progress_interval else None
        _registry[label] = self

    def runner(self):
        """The PyRunner to place in O.engines (before NewtonIntegrator)."""
        from yade.wrapper import PyRunner
        cmd = f"__import__('yade_mpm').engine.by_label({self.label!r})._yade_step()"
        return PyRunner(command=cmd, iterPeriod=1, initRun=True, label=self.label)

    def checkpoint_state(self):
        """What a resumed run needs from this engine (yade_mpm.checkpoint): the O.dt asked for by the
        user/DEM side and the O.dt this engine set last (floats survive JSON exactly)."""
        return {"user_dt": self.user_dt, "last_set_dt": self.last_set_dt,
                "progress": None if self.progress is None else [self.progress.end_time, self.progress.interval]}

    def restore_checkpoint_state(self, state):
        self.user_dt, self.last_set_dt = state["user_dt"], state["last_set_dt"]
        if state.get("progress") and self.progress is None:
            self.progress = Progress(state["progress"][0], self.label, state["progress"][1])
        _registry[self.label] = self

    def _yade_step(self):
        from yade import O
        s = self.solver
        try:
            if s.steps == 0 and s.time == 0 and O.time != 0:
                s.time = O.time
            if self.user_dt is None or O.dt != self.last_set_dt:
                self.user_dt = O.dt  # someone else (user, DEM time stepper) set O.dt
            if s.autoDt:
                dt = min(self.user_dt, s.stableDt())
            else:
                dt = min(self.user_dt, s.fixedDt)
            if dt != O.dt:
                O.dt = dt
            self.last_set_dt = O.dt
            for b in self._adapters:
                b.read()
            t = _time.perf_counter()
            s._advance(O.dt)
            gov = governor()
            if gov is not None:
                gov.tick(_time.perf_counter() - t)   # on a shared host the faster thread count (yade_mpm.threads)
            for b in self._adapters:
                b.write()
        except Exception as e:  # stop YADE cleanly with the message instead of stepping on
            self.error = e
            O.pause()
            print(f"[{self.label}] MPM stopped: {e}", flush=True)
            raise
        if self.progress:
            self.progress.update(s.steps, s.time, solver=s)
