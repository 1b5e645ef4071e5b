"""Progress lines for long runs: step, simulated time, wall time and ETA."""
import sys
import time


class Progress:
    """Call ``update(step, t)`` as often as you like; prints at most every `interval` wall seconds."""

    def __init__(self, end_time, label="mpm", interval=10.0, stream=sys.stdout):
        self.end_time, self.label, self.interval, self.stream = end_time, label, interval, stream
        self.start = time.time()
        self.last = self.start
        self.t0 = None

    def update(self, step, t, force=False):
        now = time.time()
        if self.t0 is None:
            self.t0 = t
        if not force and now - self.last < self.interval:
            return
        self.last = now
        elapsed = now - self.start
        frac = (t - self.t0) / max(self.end_time - self.t0, 1e-300) if self.end_time else 0.0
        eta = elapsed * (1 - frac) / frac if frac > 0 else float("nan")
        pct = f" ({100 * frac:5.1f} %)" if self.end_time else ""
        print(f"[{self.label}] step {step:9d}  t = {t:.6e} s{pct}  wall {elapsed:7.1f} s  ETA {eta:7.1f} s",
              file=self.stream, flush=True)
