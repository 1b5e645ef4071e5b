"""Progress lines for long runs: step, simulated time, wall time and ETA."""
import sys
import time


class Progress:
    """Call ``update(step, t)`` as often as you like; prints at most every `interval` wall seconds.
    The ETA comes from the fraction done of `end_time` [s] (simulated), or else of `total_steps`. With a
    `solver` (set by ``runner.run``, or ``update(…, solver=s)``) a line also reports the last time step and, once
    there are any, the particles removed after leaving the grid (Solver.outside): count and mass (this rank's under
    MPI). A step below DT_DROP of the largest one seen is flagged: the run then slows by that factor
    (doc/validation/stability.md, "Failed particles that keep expanding")."""

    DT_DROP = 0.25

    def __init__(self, end_time, label="mpm", interval=10.0, stream=sys.stdout, total_steps=None):
        from .geometry import _integer, _number
        if end_time is not None and _number(end_time, "Progress end_time", "s") < 0:
            raise ValueError(f"Progress end_time = {end_time} s is outside the allowed range [0, inf) (or None)")
        if _number(interval, "Progress interval", "s") < 0:
            raise ValueError(f"Progress interval = {interval} s is outside the allowed range [0, inf)")
        if total_steps is not None:
            _integer(total_steps, "Progress total_steps", 0)
        self.end_time, self.label, self.interval, self.stream = end_time, label, interval, stream
        self.total_steps = total_steps
        self.start = time.time()
        self.last = self.start
        self.t0 = self.step0 = None
        self.solver = None
        self.dt_max = 0.0

    def fraction(self, step, t):
        """Fraction of the run done since the first update (None when neither end is known)."""
        if self.end_time:
            return min(1.0, (t - self.t0) / max(self.end_time - self.t0, 1e-300))
        if self.total_steps:
            return min(1.0, (step - self.step0) / self.total_steps)
        return None

    def update(self, step, t, force=False, solver=None):
        if solver is not None:
            self.solver = solver
        now = time.time()
        if self.t0 is None:
            self.t0, self.step0 = t, step
        if not force and now - self.last < self.interval:
            return
        self.last = now
        elapsed = now - self.start
        frac = self.fraction(step, t)
        eta = elapsed * (1 - frac) / frac if frac else float("nan")
        pct = f" ({100 * frac:5.1f} %)" if frac is not None else ""
        print(f"[{self.label}] step {step:9d}  t = {t:.6e} s{pct}  wall {elapsed:7.1f} s  ETA {eta:7.1f} s{self._dt()}{self._removed()}",
              file=self.stream, flush=True)

    def _dt(self):
        dt = float(self.solver.lastDt) if self.solver is not None else 0.0
        if not dt > 0:
            return ""
        self.dt_max = max(self.dt_max, dt)
        low = dt < self.DT_DROP * self.dt_max
        return f"  Δt {dt:.3g} s" + (f" (1/{self.dt_max / dt:.0f} of the largest: a failed particle expanding?)" if low else "")

    def _removed(self):
        if self.solver is None:
            return ""
        acc = self.solver._removedAccount(allRanks=False)   # no collective: ranks print at their own times
        return f"  removed {acc['count']} ({acc['mass']:.4g} kg)" if acc["count"] else ""
