"""yade_mpm: weighted-least-squares material point method (WLS-MPM) for YADE.

Core solver in C++ (pkg-mpm/, module ``yade_mpm._core``), driven from YADE's O.engines through
``MpmEngine``. Quantities are SI; stress is tension-positive; 2D is plane strain per unit thickness.
"""
import os as _os

# Threads that wait at a barrier spin only briefly (~10 µs) and then sleep: spinning long steals the
# core a descheduled partner needs on a loaded 2-core host, sleeping at once slows the ~12 barriers
# of a step on an idle one (both measured with scripts/tools/bench.py). Results do not depend on it.
# Effective only if OpenMP was not initialised earlier in the process (e.g. by YADE); users may override.
_os.environ.setdefault("GOMP_SPINCOUNT", "10000")

from . import _guards
_guards.cap_omp_threads()   # before libgomp reads OMP_NUM_THREADS (loaded with _core)
from . import parallel
_core = parallel.load_core(__name__)   # the serial core, or under mpirun the MPI build (doc/scaling.md)
from ._core import (Solver2D, Solver3D, MpmSimulationError, setThreads, getThreads, dpgkPointUpdate2D, dpgkPointUpdate3D,
                    dpgkFlawThresholds, dpgkThresholdScale)
from . import _core
_guards.install(_core)      # Solver.view("id") read-only, Solver.reserve(n) checked against the memory
_guards.cap_core_threads(_core)
from .materials import ElasticMat, DpGkMat
from .fields import get, fields, FIELDS, id_order, views, removed, SYM_NAMES
from .scene import (check_setting, setting_default, courant_option, check_courant, make_solver, add_region, set_initial_stress, boundary_particles, apply_traction,
                    apply_face_traction, consistent_row_weights)
from .geometry import Circle, Box, Disc, Polygon, rotated_rectangle, fill_region
from .engine import MpmEngine, engine
from ._core import ContactParams
from .bodies import RigidBodies, contact_params
from .spheres import DemSpheres
from .progress import Progress
from . import rocks, runner, output  # noqa: E402  (rock sets, run loop, result files)
from . import checkpoint  # noqa: E402  (save/resume a whole simulation)

__all__ = ["Solver2D", "Solver3D", "MpmSimulationError", "setThreads", "getThreads", "ElasticMat", "DpGkMat",
           "check_setting", "setting_default", "courant_option", "check_courant", "make_solver", "add_region", "views", "get", "id_order", "removed", "set_initial_stress", "boundary_particles",
           "apply_traction", "apply_face_traction", "consistent_row_weights", "Circle", "Box", "Disc", "Polygon", "rotated_rectangle", "fill_region", "MpmEngine", "engine", "RigidBodies", "ContactParams", "contact_params", "DemSpheres",
           "Progress", "SYM_NAMES", "dpgkPointUpdate2D", "dpgkPointUpdate3D", "dpgkFlawThresholds",
           "dpgkThresholdScale"]
