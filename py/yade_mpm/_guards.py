"""Checks at the entrance of the compiled core that belong to the Python side (installed once by
``import yade_mpm``):

- ``OMP_NUM_THREADS`` above the thread cap of ``setThreads`` (max(16, 4 × processors)) is lowered to
  the cap with a warning before libgomp reads it: libgomp aborts with 1000 and crashes with 100000
  (if YADE started OpenMP first, YADE itself may already have crashed; the core's threads are capped).
- ``Solver.view("id")`` is read-only: the ids name the particles (``get`` orders every field by
  them, checkpoints and contact reactions refer to them); duplicates written through the view went
  unnoticed.
- ``Solver.reserve(n)`` refuses, naming n, a count whose particle arrays do not fit in this machine's
  memory (the core's allocation failed with an empty MemoryError).
"""
import math
import numbers
import os
import warnings


def _thread_cap():
    return max(16, 4 * (os.cpu_count() or 1))      # = setThreads' range (pkg-mpm/python/bindings.cpp maxThreads)


def cap_omp_threads(environ=os.environ):
    """Lower an oversized OMP_NUM_THREADS (also the first entry of a nested list "a,b") to the cap, with a
    warning; leaves anything else to libgomp. Returns the value now in the environment (or None)."""
    raw = environ.get("OMP_NUM_THREADS")
    if raw is None:
        return None
    first, _, rest = raw.strip().partition(",")
    try:
        n = int(first)
    except ValueError:
        return raw
    cap = _thread_cap()
    if n > cap:
        environ["OMP_NUM_THREADS"] = str(cap) + ("," + rest if rest else "")
        warnings.warn(f"OMP_NUM_THREADS = {raw} is more than yade_mpm's thread cap max(16, 4 × processors) = {cap}: "
                      f"using {cap} (libgomp aborts or crashes with thousands of threads)", RuntimeWarning, stacklevel=3)
    return environ["OMP_NUM_THREADS"]


def cap_core_threads(core):
    """When OpenMP was initialised before ``import yade_mpm`` (e.g. by YADE) with more threads than the
    cap, the core's parallel regions are lowered to the cap (``setThreads``), with a warning."""
    if core.getThreads() > _thread_cap():
        warnings.warn(f"OpenMP was started with {core.getThreads()} threads before yade_mpm was imported: yade_mpm uses "
                      f"{_thread_cap()} (its cap)", RuntimeWarning, stacklevel=3)
        core.setThreads(_thread_cap())


def _physical_memory():
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def install(core):
    """Wraps Solver2D/Solver3D.view and .reserve (the compiled methods stay reachable as ``_view_raw``,
    ``_reserve_raw`` for the checkpoint restore)."""
    for cls in (core.Solver2D, core.Solver3D):
        if hasattr(cls, "_view_raw"):
            continue
        raw_view, raw_reserve = cls.view, cls.reserve

        def view(self, name, _raw=raw_view):
            v = _raw(self, name)
            if isinstance(name, str) and name == "id":
                v = v.view()                       # keeps the solver's view token alive through .base
                v.flags.writeable = False
            return v

        def reserve(self, particles, _raw=raw_reserve):
            n = particles
            if isinstance(n, numbers.Real) and not isinstance(n, bool) and math.isfinite(n) and n == int(n) and n > 0:
                need, phys = int(n) * self._bytesPerParticle, _physical_memory()
                if phys and need > phys:
                    raise ValueError(f"reserve: particles = {int(n):,} need {need / 1e9:.3g} GB of particle arrays "
                                     f"({self._bytesPerParticle} bytes each), more than this machine's {phys / 1e9:.3g} GB")
            return _raw(self, particles)

        view.__doc__ = ("view(name) -> live NumPy view (STORAGE order, no copy) of a particle array: x0.., v0.., C0.., "
                        "sig0.. (undamaged stress), trac0.., mass, vol, vol0, epsP, damage, eps0, nFlaw, id and material "
                        "(both read-only). Power users; for analysis use yade_mpm.get / fields (copies in id order).")
        reserve.__doc__ = raw_reserve.__doc__
        cls._view_raw, cls._reserve_raw = raw_view, raw_reserve
        cls.view, cls.reserve = view, reserve
