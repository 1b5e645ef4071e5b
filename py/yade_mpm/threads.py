"""How many OpenMP threads the step uses, and the automatic choice on a shared host.

A step's threads meet at about a dozen barriers. When another job shares the cores, a thread that waits at a
barrier sleeps and wakes late, and a run with as many threads as cores can fall far below a one-thread run
(doc/developer/performance.md, "Threads and barriers"). The results do not depend on the thread count (the same
bits for any count), so the count can change between any two steps. Unless the user chose a count
(``setThreads`` or OMP_NUM_THREADS), the :class:`Governor` runs at all the process's cores and every
`probe_every` wall seconds times one window of steps at half of them; it keeps whichever ran more steps per second
(by more than `margin`), so a shared host does not punish the default and an idle one keeps every core.
The engine (``MpmEngine``) and ``runner.run`` report each step's wall time to it."""
import os
import time

from . import _core


def available_cores():
    """Cores this process may run on (its CPU affinity)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


class Governor:
    """Keeps the faster of two thread counts, hi (all cores) and lo = hi // 2, measured in alternating windows.

    window [s]: wall time of one measuring window (at least `min_steps` steps); probe_every [s]: wall time between
    probes of the other count (the first after `first_probe` s); margin: the other count is kept only if it ran faster by more than this fraction."""

    def __init__(self, hi=None, window=0.5, min_steps=20, probe_every=30.0, first_probe=2.0, margin=0.1, clock=time.perf_counter,
                 set_threads=None):
        self.hi = int(hi or available_cores())
        self.lo = max(1, self.hi // 2)
        self.window, self.min_steps, self.probe_every, self.first_probe, self.margin = window, min_steps, probe_every, first_probe, margin
        self.clock, self.set_threads = clock, set_threads or _core.setThreads
        self.enabled = self.hi > 1
        self.current = self.hi
        self.probing = False
        self.base_rate = None               # steps/s of the count in use, last window before a probe
        self.last_probe = None
        self.switches = 0
        self._reset()

    def _reset(self):
        self.steps, self.wall = 0, 0.0

    def tick(self, step_wall):
        """Account one step of `step_wall` wall seconds; may change the thread count for the next step."""
        if not self.enabled:
            return
        now = self.clock()
        if self.last_probe is None:                          # the first probe comes early: a short run is helped too
            self.last_probe = now - self.probe_every + self.first_probe
        self.steps += 1
        self.wall += step_wall
        if self.steps < self.min_steps or self.wall < self.window:
            return
        rate = self.steps / self.wall
        self._reset()
        if self.probing:                                     # the other count's window is done: keep the faster
            self.probing = False
            if not rate > self.base_rate * (1 + self.margin):
                self._use(self.hi if self.current == self.lo else self.lo)
            else:
                self.switches += 1
            self.last_probe = now
        elif now - self.last_probe >= self.probe_every:      # time to try the other count
            self.base_rate = rate
            self.probing = True
            self._use(self.lo if self.current == self.hi else self.hi)

    def _use(self, n):
        self.current = n
        self.set_threads(n)


_governor = None


def governor():
    """The process's governor, or None when the user chose the thread count (setThreads, OMP_NUM_THREADS)."""
    global _governor
    if _governor is None and "OMP_NUM_THREADS" not in os.environ:
        _governor = Governor()
    return _governor if _governor is not None and _governor.enabled else None


def setThreads(n):
    """Use n OpenMP threads for the MPM step from now on (1 ≤ n ≤ max(16, 4 × processors)); the automatic
    choice (:class:`Governor`) stops."""
    global _governor
    _core.setThreads(n)
    _governor = Governor(hi=1)              # disabled: the user chose
