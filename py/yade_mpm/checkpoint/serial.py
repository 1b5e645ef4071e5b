"""The state a checkpoint holds (solver arrays, YADE scene, MpmEngine registry), its fingerprints, and
``save`` / ``load`` of one process; N MPI ranks hand their pieces to mpi.py."""
import hashlib
import json
import os
import sys
import time

import numpy as np

from .. import _core
from ..engine import MpmEngine, _registry as _engines
from ..fields import SYM_NAMES, dim_of
from . import mpi as cmpi
from .format import FORMAT, CheckpointError, build_id, check_same_build, diff, read, write

_STATE_SCALARS = ("steps", "time", "lastDt", "externalWork", "vmax", "rhoMin", "massFloor", "needSort", "needCheck")


# ------------------------------------------------------------------------------------ solver state
def _field_names(solver):
    d = dim_of(solver)
    return ([f"x{a}" for a in range(d)] + [f"v{a}" for a in range(d)] + [f"C{k}" for k in range(d * d)]
            + ["mass", "vol", "vol0"] + [f"sig{k}" for k in range(len(SYM_NAMES[d]))]
            + [f"trac{a}" for a in range(d)] + ["epsP", "damage", "eps0", "nFlaw"])


def _particle_arrays(solver):
    """Every allocated particle array (live views, storage order), keyed by name; refuses a core that
    holds arrays this module does not know (a checkpoint must never miss state)."""
    out = {}
    for n in _field_names(solver):
        try:
            out[n] = solver.view(n)
        except ValueError:
            pass                                  # optional array not allocated in this scene
    nreal = solver._getResumeState()["realFields"]
    if len(out) != nreal:
        raise CheckpointError(f"the core holds {nreal} particle arrays but the checkpoint knows {len(out)} "
                              f"({', '.join(out)}); update yade_mpm.checkpoint._field_names")
    out["id"] = solver._view_raw("id")          # writable: the restore writes the saved ids (user views are read-only)
    out["material"] = solver.view("material")    # material index per particle (uint8), follows the sort like id
    return out


def _digest(*arrays):
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]


def solver_fingerprint(solver, ids=None):
    """What makes a solver's scene this scene and not another: dimension, grid, particle count, the
    particles' masses, initial volumes and surface loads (in id order), the materials, the contact groups'
    parameters. These never change while stepping: a fresh scene and a checkpoint of it mid-run agree.
    ids: only these particles (MPI: a rank's piece against the freshly built, replicated scene)."""
    arrs = _particle_arrays(solver)
    order = np.argsort(arrs["id"], kind="stable")
    if ids is not None:
        ids = np.sort(np.asarray(ids))
        k = np.clip(np.searchsorted(arrs["id"][order], ids), 0, max(len(order) - 1, 0))
        if len(order) == 0 or not np.array_equal(arrs["id"][order][k], ids):
            raise CheckpointError("the checkpoint's particle ids are not all in this scene")
        order = order[k]
    loads = [arrs[f"trac{a}"][order] for a in range(dim_of(solver)) if f"trac{a}" in arrs]
    return {"dim": dim_of(solver), "origin": list(solver.origin), "spacing": solver.spacing,
            "cells": list(solver.cells), "particles": int(len(order)),
            "arrays": sorted(k for k in arrs if k not in ("id", "material")),
            "mass_vol0": _digest(arrs["mass"][order], arrs["vol0"][order]),
            "loads": _digest(*loads) if loads else None, "materialKinds": [int(k) for k in solver._materialKinds],
            "materials": [solver.material(i).toDict() for i in range(solver.numMaterials)],
            "contact": [solver._contactParams(g).toDict() for g in range(solver._numContactGroups)],   # ContactParams.hpp
            "material_index": _digest(arrs["material"][order])}


_REMOVED = ("id", "step", "time", "pos", "vel", "mass", "damage", "face", "material", "reason")
# Fingerprint entries of the particles themselves: a distributed build's rank holds other particles than its piece
# (checked there: the total over the ranks)
_PER_PARTICLE = ("particles", "arrays", "mass_vol0", "loads", "material_index")


def _scene_only(fingerprint):
    """A solver fingerprint without its per-particle entries."""
    return {k: v for k, v in fingerprint.items() if k not in _PER_PARTICLE}


def _solver_state(solver):
    arrs = {k: np.array(v, copy=True) for k, v in _particle_arrays(solver).items()}
    for k, v in solver._removedParticles().items():   # particles removed after leaving the grid (this rank's)
        arrs[f"removed_{k}"] = np.array(v, copy=True)
    rs = solver._getResumeState()
    arrs["blockStart"] = np.array(rs["blockStart"], copy=True)
    arrs["scalars"] = np.array([float(rs[k]) for k in _STATE_SCALARS], dtype=np.float64)
    for g in range(solver._numContactGroups):          # the kinematic law's start of the next step
        ids, lam, dt = solver._kinematicWarmStart(g)
        arrs[f"warm{g}_ids"], arrs[f"warm{g}_impulses"], arrs[f"warm{g}_dt"] = ids, lam, np.array([dt])
    return arrs


def _restore_solver(solver, arrs, settings):
    """Particle arrays, clock and the other resume state from `arrs`, and the solver settings (state too:
    a script may change them during a run) from `settings` (``Solver.settings()`` when saved)."""
    sc = dict(zip(_STATE_SCALARS, arrs["scalars"].tolist()))
    for k in ("steps",):
        sc[k] = int(sc[k])
    for k in ("needSort", "needCheck"):
        sc[k] = bool(sc[k])
    sc["blockStart"] = arrs["blockStart"]
    # the removed particles and their account; the fresh scene's arrays cut to the saved particle count
    solver._restoreRemoved({k: arrs[f"removed_{k}"] for k in _REMOVED}, len(arrs["id"]))
    views = _particle_arrays(solver)
    for k in views:                               # shapes were checked before anything was changed
        if views[k].shape != arrs[k].shape:
            raise CheckpointError(f"particle array {k}: shape {arrs[k].shape} in the checkpoint, {views[k].shape} here")
    old = solver.settings()
    settings = dict(settings)
    settings.setdefault("velocityUpdate", "pic")  # saved before the setting existed: those runs used Eq. 6
    try:
        solver.setSettings(settings)              # all or nothing, each value checked against its range
        solver._setResumeState(sc)                 # checks the block schedule before changing anything
    except ValueError as e:
        solver.setSettings(old)
        raise CheckpointError(f"checkpoint: {e}") from None
    for g in range(solver._numContactGroups):
        if f"warm{g}_ids" in arrs:                  # absent in a checkpoint saved before the warm start existed
            solver._setKinematicWarmStart(g, arrs[f"warm{g}_ids"], arrs[f"warm{g}_impulses"], float(arrs[f"warm{g}_dt"][0]))
    for k, v in views.items():
        if k != "material":                       # read-only view: set below through the API
            np.copyto(v, arrs[k])
    changed = views["material"] != arrs["material"]
    for m in np.unique(arrs["material"][changed]):
        solver.setParticleMaterial(np.flatnonzero(changed & (arrs["material"] == m)), int(m))
    for k in ("eps0", "nFlaw"):                   # the saved values, not the ones recomputed for the new material
        if changed.any() and k in views:
            np.copyto(views[k], arrs[k])


# -------------------------------------------------------------------------------------- YADE state
def _yade_O():
    return sys.modules["yade"].O if "yade" in sys.modules else None


def _body_state(O):
    """Body states as float64 arrays (to check bitwise after O.load)."""
    rows = []
    for b in O.bodies:
        s, q = (None, None) if b is None else (b.state, b.state.ori)
        rows.append([np.nan] * 16 if s is None else list(s.pos) + list(s.vel) + list(s.angVel) + [q[0], q[1], q[2], q[3]] + list(s.refPos))
    return np.array(rows, dtype=np.float64).reshape(-1, 16)


def yade_fingerprint(O):
    """Bodies (count, shape and material classes, dynamic or not) and engines (classes and labels)."""
    bodies = [None if b is None else [type(b.shape).__name__, type(b.material).__name__, bool(b.dynamic)]
              for b in O.bodies]
    engines = [[type(e).__name__, e.label] for e in O.engines]
    return {"bodies": bodies, "engines": engines}


def _yade_blob(O, tmpdir):
    tmp = os.path.join(tmpdir, f".yade-scene-{os.getpid()}.yade")   # binary archive: doubles bitwise
    O.save(tmp)
    try:
        with open(tmp, "rb") as f:
            return np.frombuffer(f.read(), dtype=np.uint8).copy()
    finally:
        os.remove(tmp)


# -------------------------------------------------------------------------------------------- save
def _engines_in_scene(O):
    labels = {e.label for e in O.engines} if O is not None else set()
    return {lab: e for lab, e in _engines.items() if lab in labels}


def _resolve_solvers(solvers, O):
    if solvers is None:
        engines = _engines_in_scene(O)
        if not engines:
            raise ValueError("solvers: no MpmEngine is in O.engines; pass solvers=solver or {name: solver}")
        return {lab: e.solver for lab, e in engines.items()}
    if isinstance(solvers, (_core.Solver2D, _core.Solver3D)):
        eng = [lab for lab, e in _engines_in_scene(O).items() if e.solver is solvers]
        return {eng[0] if eng else "solver": solvers}
    if isinstance(solvers, dict) and solvers and all(isinstance(v, (_core.Solver2D, _core.Solver3D)) for v in solvers.values()):
        return dict(solvers)
    raise ValueError("solvers must be None (the MpmEngines in O.engines), a Solver2D/3D or a non-empty {name: solver} dict")


def save(path, solvers=None, yade=None, meta=None, extra=None):
    """Write a checkpoint of the whole simulation to `path` (atomically: a crash while writing leaves
    the previous file intact). solvers: None = the solvers of the MpmEngines in O.engines, or a solver,
    or {name: solver}; yade: include the YADE scene (None = when yade is imported and O has bodies or
    engines); meta: a JSON-able dict stored alongside (e.g. the case and grid spacing; ``load`` with
    the same meta refuses a checkpoint with another one); extra: JSON-able state of the calling script
    (e.g. the curve recorded so far), returned by ``load`` as ``header["extra"]``. Call between steps
    (not from inside a PyRunner). Returns the number of bytes written."""
    mpi = cmpi.active()                           # N > 1 ranks: a piece per rank and an index (checkpoint_mpi)
    if os.path.isdir(path):
        raise ValueError(f"checkpoint path {path} is a directory: give a file name, e.g. {os.path.join(path, 'run.ckpt')}")
    O = _yade_O()
    with_yade = (O is not None and (len(O.bodies) > 0 or len(O.engines) > 0)) if yade is None else bool(yade)
    if with_yade and O is None:
        raise ValueError("yade=True but yade is not imported")
    sol = _resolve_solvers(solvers, O if with_yade else None)
    for name, v in (("meta", meta), ("extra", extra)):
        try:
            json.dumps(v)                          # must be JSON-able: fail before writing anything
        except (TypeError, ValueError) as e:
            raise ValueError(f"{name} must be JSON-serialisable (dicts, lists, numbers, strings): {e}") from None
    arrays, header = {}, {"format": FORMAT, "build": build_id(), "written": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()),
                          "meta": meta, "extra": extra, "solvers": {}, "settings": {}, "yade": None}
    if mpi:
        header["mpi"] = {name: cmpi.header_of(s) for name, s in sol.items()}   # a collective: every rank saves
    header["removed"] = {name: int(s._removedAccount()["count"]) for name, s in sol.items()}   # MPI: over the ranks
    for name, s in sol.items():
        header["solvers"][name] = solver_fingerprint(s)
        header["settings"][name] = s.settings()   # JSON floats round-trip exactly
        for k, v in _solver_state(s).items():
            arrays[f"solver/{name}/{k}"] = v
    if with_yade:
        d = os.path.dirname(os.path.abspath(path))
        os.makedirs(d, exist_ok=True)
        arrays["yade/scene"] = _yade_blob(O, d)
        arrays["yade/bodies"] = _body_state(O)
        arrays["yade/clock"] = np.array([O.time, float(O.iter), O.dt], dtype=np.float64)
        engines = _engines_in_scene(O)
        header["yade"] = dict(yade_fingerprint(O), mpm_engines={lab: dict(e.checkpoint_state(), solver=next((k for k, v in sol.items() if v is e.solver), None))
                                                                 for lab, e in engines.items()})
    if not mpi:
        return write(path, header, arrays)
    return cmpi.save_pieces(path, header, arrays, sol, write)



def load(path, solvers=None, yade=None, meta=None):
    """Restore a checkpoint into the freshly built scene. solvers: as for ``save`` (None = the
    MpmEngines registered under the labels the checkpoint names, i.e. the ones the scene script just
    created); yade: restore the YADE scene (None = if the checkpoint has one); meta: if given, must
    equal the meta stored by ``save``. Everything is checked before anything changes; on mismatch a
    CheckpointError lists the differences. Returns the header (meta, time written, fingerprints)."""
    header, arrays = read(path, check_build=False)
    cmpi.refuse_other_count(path, header)   # N ranks resume only an N-rank checkpoint (before the build:
    check_same_build(path, header)                               # 1 process and N ranks run different builds of the core)
    if cmpi.active():
        return cmpi.load_piece(path, header, solvers, yade, meta, _load)
    return _load(path, header, arrays, solvers, yade, meta)


def _load(path, header, arrays, solvers, yade, meta, mpi=None):
    if meta is not None and json.loads(json.dumps(meta)) != header.get("meta"):
        raise CheckpointError(f"checkpoint {path} is for another scene: " + "; ".join(diff(header.get("meta"), json.loads(json.dumps(meta)), "meta.")))
    saved_yade = header.get("yade")
    with_yade = saved_yade is not None if yade is None else bool(yade)
    if with_yade and saved_yade is None:
        raise CheckpointError(f"checkpoint {path} holds no YADE scene (yade=True asked)")
    O = _yade_O() if with_yade else None
    if with_yade and O is None:
        import yade  # noqa: F401  (the checkpoint has a YADE scene: load it)
        O = _yade_O()
    # which solver receives which saved state
    names = list(header["solvers"])
    if solvers is None:
        sol = {}
        for n in names:
            lab = next((lab for lab, st in (saved_yade or {}).get("mpm_engines", {}).items() if st.get("solver") == n), n)
            if lab not in _engines:
                raise CheckpointError(f"checkpoint {path}: solver '{n}' belongs to MpmEngine '{lab}', which this scene has not "
                                      f"created; build the scene first (MpmEngine(solver, label='{lab}')) or pass solvers=")
            sol[n] = _engines[lab].solver
    elif isinstance(solvers, (_core.Solver2D, _core.Solver3D)):
        if len(names) != 1:
            raise CheckpointError(f"checkpoint {path} holds {len(names)} solvers ({', '.join(names)}); pass solvers={{name: solver}}")
        sol = {names[0]: solvers}
    elif isinstance(solvers, dict):
        sol = dict(solvers)
        if set(sol) != set(names):
            raise CheckpointError(f"checkpoint {path} holds solvers {sorted(names)}, given {sorted(sol)}")
    else:
        raise ValueError("solvers must be None, a Solver2D/3D or a {name: solver} dict")
    problems, spread = [], {}
    for n, s in sol.items():
        gone = int(header.get("removed", {}).get(n, 0))          # particles removed after leaving the grid
        # MPI: this rank's particles of the fresh scene; after removals: the particles still in the computation
        ids = arrays[f"solver/{n}/id"] if (mpi or gone) else None
        spread[n] = bool(mpi) and bool(s.mpiInfo().get("distributedBuild"))   # each rank built only its slab (distribute)
        # the scene's particles: every rank's of a distributed build (a collective: all its ranks are here), else this rank's
        here = int(round(_core.mpiSum(float(s.numParticles)))) if spread[n] else s.numParticles
        if mpi and mpi[n]["total"] + gone != here:
            problems.append(f"solver {n}: {mpi[n]['total']} particles over the ranks and {gone} removed in the checkpoint, "
                            f"{here} in this scene")
        if not mpi and gone and len(ids) + gone != s.numParticles:
            problems.append(f"solver {n}: {len(ids)} particles and {gone} removed in the checkpoint, {s.numParticles} in this scene")
        try:
            if spread[n]:   # the rank's slab holds other particles than its piece: the scene's grid, materials and contact
                problems += diff(_scene_only(header["solvers"][n]), _scene_only(solver_fingerprint(s)), f"solver {n}: ")
            else:
                problems += diff(header["solvers"][n], solver_fingerprint(s, ids), f"solver {n}: ")
        except CheckpointError as e:
            problems.append(f"solver {n}: {e}")
        saved, here = sorted(header["settings"][n]), sorted(s.settings())
        if saved != here:
            problems.append(f"solver {n}: settings {saved} in the checkpoint, {here} in this core")
    if with_yade:
        here = yade_fingerprint(O)
        if here["bodies"] or here["engines"]:     # a scene was built: it must be the saved one
            problems += diff({k: saved_yade[k] for k in ("bodies", "engines")}, here, "YADE ")
    if mpi is not None:                           # every rank's checks passed, or every rank refuses
        if not cmpi.agree(not problems) and not problems:
            problems.append("another MPI rank refused its piece (its message names the difference)")
    if problems:
        raise CheckpointError(f"checkpoint {path} is for another scene: " + "; ".join(problems[:8])
                              + (f" (+{len(problems) - 8} more)" if len(problems) > 8 else ""))
    for n, s in sol.items():                      # every check passed: now change the state
        mine = {k.split("/", 2)[2]: v for k, v in arrays.items() if k.startswith(f"solver/{n}/")}
        if mpi:                                   # the slab layout; the arrays sized to this rank's particles
            s._mpiRestoreSlab(mpi[n]["firstLayers"], mpi[n]["particles"], traction="trac0" in mine, damageState="damage" in mine,
                              flaws="nFlaw" in mine)
            if spread[n]:                             # an optional array the rank's piece has not (none of its
                mine.update({k: np.zeros_like(v) for k, v in _particle_arrays(s).items() if k not in mine})   # particles had a traction): 0
        _restore_solver(s, mine, header["settings"][n])
    if with_yade:
        d = os.path.dirname(os.path.abspath(path))
        tmp = os.path.join(d, f".yade-scene-{os.getpid()}.yade")
        arrays["yade/scene"].tofile(tmp)
        try:
            O.load(tmp)
        finally:
            os.remove(tmp)
        if not np.array_equal(_body_state(O), arrays["yade/bodies"], equal_nan=True):
            raise CheckpointError(f"checkpoint {path}: YADE body states differ after O.load (YADE serialization is not bitwise)")
        clock = arrays["yade/clock"]
        if not (O.time == clock[0] and O.iter == int(clock[1]) and O.dt == clock[2]):
            raise CheckpointError(f"checkpoint {path}: O.time/O.iter/O.dt differ after O.load")
        for lab, st in saved_yade.get("mpm_engines", {}).items():   # the PyRunners name engines by label
            s = sol[st["solver"]]
            e = _engines.get(lab)
            if e is None or e.solver is not s:
                e = MpmEngine(s, label=lab)
            e.restore_checkpoint_state(st)
    return header

