"""The thread governor (yade_mpm.threads): on a shared host it keeps whichever thread count steps faster; the
count changes between steps without changing a bit of the results."""
import numpy as np
import pytest

import yade_mpm as ym
from yade_mpm import rocks, threads


class FakeHost:
    """A clock and a step whose wall time depends on the thread count in use (steps per second by count)."""

    def __init__(self, rates):
        self.t, self.rates, self.n, self.calls = 0.0, dict(rates), max(rates), []

    def clock(self):
        return self.t

    def set_threads(self, n):
        self.n = n
        self.calls.append(n)

    def run(self, gov, seconds):
        end = self.t + seconds
        while self.t < end:
            dt = 1.0 / self.rates[self.n]
            self.t += dt
            gov.tick(dt)


def test_keeps_the_faster_count_and_returns_when_the_load_goes():
    host = FakeHost({2: 100.0, 1: 60.0})                              # idle host: 2 threads faster
    g = threads.Governor(hi=2, window=0.5, probe_every=5.0, clock=host.clock, set_threads=host.set_threads)
    host.run(g, 30.0)
    assert host.n == 2 and 1 in host.calls                          # probed 1 thread, came back
    host.rates = {2: 25.0, 1: 90.0}                                  # another job arrived: 2 threads crawl
    host.run(g, 30.0)
    assert host.n == 1
    probes = len(host.calls)
    host.rates = {2: 100.0, 1: 60.0}                                 # the other job ended
    host.run(g, 30.0)
    assert host.n == 2 and len(host.calls) > probes
    assert g.switches >= 2


def test_margin_keeps_the_count_when_both_are_alike():
    host = FakeHost({2: 100.0, 1: 105.0})                            # within the 10 % margin: keep all cores
    g = threads.Governor(hi=2, window=0.5, probe_every=5.0, clock=host.clock, set_threads=host.set_threads)
    host.run(g, 60.0)
    assert host.n == 2 and g.switches == 0


def test_the_users_count_stops_the_governor():
    ym.setThreads(1)
    try:
        assert threads.governor() is None and ym.getThreads() == 1
        with pytest.raises(ValueError):
            ym.setThreads(0)
    finally:
        ym.setThreads(threads.available_cores())


def test_changing_the_count_between_steps_changes_no_bit():
    def scene():
        s = ym.make_solver((0.0, 0.0), (0.4, 0.3), 0.02)
        ym.add_region(s, rocks.granite_dpgk(), (0.0, 0.0), (0.4, 0.3), ppc=2)
        s.addBoundaryPlane(1, -1, 0.0, "slip")
        s.gravity = (0.0, -9.81e4)                                   # a hard push: plasticity and damage within 60 steps
        return s
    a, b = scene(), scene()
    try:
        for k in range(60):
            ym.setThreads(2)
            a.run(1)
            ym.setThreads(1 + k % 2)                                  # b alternates 1, 2, 1, ...
            b.run(1)
    finally:
        ym.setThreads(threads.available_cores())
    for f in ("pos", "vel", "stress", "damage", "plastic_strain"):
        assert np.array_equal(ym.get(a, f), ym.get(b, f)), f
    assert ym.get(a, "damage").max() > 0 or ym.get(a, "plastic_strain").max() > 0
