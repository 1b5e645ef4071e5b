"""yade_mpm: weighted-least-squares material point method (WLS-MPM) for YADE.

Core solver in C++ (pkg-mpm/, module ``yade_mpm._core``, built into build/py/yade_mpm), driven from YADE's O.engines through
``MpmEngine``. Quantities are SI; stress is tension-positive; 2D is plane strain per unit thickness.
"""
import os as _os

# Threads that wait at a barrier spin only briefly (~10 µs) and then sleep: spinning long steals the
# core a descheduled partner needs on a loaded 2-core host, sleeping at once slows the ~12 barriers
# of a step on an idle one (both measured with scripts/tools/bench.py). Results do not depend on it.
# Effective only if OpenMP was not initialised earlier in the process (e.g. by YADE); users may override.
_os.environ.setdefault("GOMP_SPINCOUNT", "10000")

from . import _build, _guards
_build.extend(__path__)     # the compiled modules live in <checkout>/build/py/yade_mpm (yade_mpm._build)
_guards.cap_omp_threads()   # before libgomp reads OMP_NUM_THREADS (loaded with _core)
from . import parallel
_core = parallel.load_core(__name__)   # the serial core, or under mpirun the MPI build (doc/developer/scaling.md)
from ._core import Solver2D, Solver3D, MpmSimulationError, getThreads, ContactParams
from . import _core
from .threads import setThreads   # the user's count; otherwise the faster of all / half the cores (yade_mpm.threads)
_guards.install(_core)      # Solver.view("id") read-only, Solver.reserve(n) checked against the memory
_guards.cap_core_threads(_core)
from .materials import ElasticMat, DpGkMat
from .fields import get, fields, removed
from .scene import make_solver, add_region, set_initial_stress, boundary_particles, apply_traction, apply_face_traction
from .geometry import Box, Circle, Disc, Polygon
from .engine import MpmEngine
from .bodies import RigidBodies
from .spheres import DemSpheres
from . import rocks, runner, output, analysis  # noqa: E402  (rock sets, run loop, result files, crack analytics)
from . import checkpoint  # noqa: E402  (save/resume a whole simulation)

# The public names, each with one line in doc/guide/api.md; everything else lives in its submodule
# (yade_mpm.scene, .geometry, .fields, .engine, .bodies, .progress, .materials).
__all__ = ["Solver2D", "Solver3D", "MpmSimulationError", "setThreads", "getThreads", "ElasticMat", "DpGkMat",
           "make_solver", "add_region", "set_initial_stress", "boundary_particles", "apply_traction", "apply_face_traction",
           "Box", "Circle", "Disc", "Polygon", "get", "fields", "removed", "MpmEngine", "RigidBodies", "ContactParams",
           "DemSpheres", "rocks", "runner", "output", "checkpoint", "analysis"]
