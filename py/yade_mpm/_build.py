"""Where the compiled core lives. CMake builds out of the source tree: the extension modules ``_core`` and
``_core_mpi`` are written to ``<checkout>/build/py/yade_mpm`` (``./setup.sh``), not into this package folder.
``import yade_mpm`` puts that folder first on the package's search path, so ``from ._core import …`` finds
them wherever the package is imported from (the ``.pth`` file, the tests, YADE and its subprocesses).

``YADE_MPM_BUILD_DIR`` names another CMake build folder (the ``-B`` of ``cmake``); its ``py/yade_mpm``
holds the modules.
"""
import os

ENV = "YADE_MPM_BUILD_DIR"
_CHECKOUT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def build_dir(environ=os.environ):
    """The CMake build folder: $YADE_MPM_BUILD_DIR, else <checkout>/build."""
    env = environ.get(ENV, "").strip()
    return os.path.abspath(os.path.expanduser(env)) if env else os.path.join(_CHECKOUT, "build")


def module_dir(environ=os.environ):
    """The folder holding the compiled modules (_core, _core_mpi)."""
    return os.path.join(build_dir(environ), "py", "yade_mpm")


def extend(path, environ=os.environ):
    """Puts module_dir() first on the package search path `path` (the package's __path__); ImportError naming
    the folder and the fix if no compiled core is there."""
    d = module_dir(environ)
    if not any(f.startswith("_core.") and f.endswith(".so") for f in (os.listdir(d) if os.path.isdir(d) else ())):
        how = f"{ENV} = {environ[ENV]!r}" if environ.get(ENV, "").strip() else f"{_CHECKOUT}/build"
        raise ImportError(f"yade_mpm: the compiled core (_core*.so) is not in {d} (build folder from {how}): run ./setup.sh "
                          f"in {_CHECKOUT}, or set {ENV} to the CMake build folder that holds py/yade_mpm/_core*.so")
    if d not in path:
        path.insert(0, d)
    return d
