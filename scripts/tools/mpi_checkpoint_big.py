"""Checkpoint and bitwise resume of a large 3D run on N MPI ranks (issue 22's bar: ≥ 2 million particles
under ``mpirun -np 2``; doc/developer/scaling.md "Checkpoints"). An elastic block (2 particles per cell per axis)
with a shearing initial velocity and gravity:

    scripts/tools/mpi_run.sh 2 1 scripts/tools/mpi_checkpoint_big.py save   --out out/mpi_ck   # K steps, save, K steps
    scripts/tools/mpi_run.sh 2 1 scripts/tools/mpi_checkpoint_big.py resume --out out/mpi_ck   # load, K steps
    /usr/bin/python3 scripts/tools/mpi_checkpoint_big.py compare --out out/mpi_ck

Each rank writes OUT/MODE.rK.json: the SHA-256 of every particle array after the last step (storage order),
particle counts, wall times of the build, the steps, the save / load, the checkpoint sizes and the peak
resident memory. `compare` checks that the resumed run's digests equal the straight run's, rank by rank."""
import argparse
import glob
import hashlib
import json
import os
import resource
import sys
import time

import numpy as np

NAMES = ["x0", "x1", "x2", "v0", "v1", "v2"] + [f"C{k}" for k in range(9)] + [f"sig{k}" for k in range(6)] + ["vol", "mass", "id"]


def scene(cells, l):
    import yade_mpm as ym
    hi = tuple(c * l for c in cells)
    s = ym.make_solver((0.0, 0.0, 0.0), hi, l, margin=2)
    ym.add_region(s, ym.ElasticMat(young=2e9, poisson=0.25, density=2000.0), (0.0, 0.0, 0.0), hi)
    s.gravity, s.sortPeriod = (0.0, 0.0, -9.81), 5
    x, z, vx, vz = s.view("x0"), s.view("x2"), s.view("v0"), s.view("v2")
    vz[:] = 20.0 + 3.0 * np.sin(np.pi * x / hi[0])
    vx[:] = 2.0 * np.cos(np.pi * z / hi[2])
    del x, z, vx, vz
    s.requestSort()
    return s


def run(a):
    import yade_mpm as ym
    from yade_mpm import checkpoint
    rank, ck = ym.parallel.rank(), os.path.join(a.out, "big.ckpt")
    os.makedirs(a.out, exist_ok=True)
    rec, t = {}, time.time()
    s = scene(a.cells, a.spacing)
    rec["build_s"], rec["particles_built"] = time.time() - t, int(s.numParticles)
    if a.mode == "save":
        t = time.time(); s.run(a.steps); rec["steps_before_s"] = time.time() - t
        t = time.time(); checkpoint.save(ck, s); rec["save_s"] = time.time() - t
        piece = ck + f".r{rank}"                   # N > 1 ranks: a piece per rank; one process: the file itself
        rec["piece_bytes"] = os.path.getsize(piece if os.path.exists(piece) else ck)
    else:
        t = time.time(); checkpoint.load(ck, s); rec["load_s"] = time.time() - t
    t = time.time(); s.run(a.steps); rec["steps_after_s"] = time.time() - t
    rec.update(rank=rank, size=ym.parallel.size(), steps=int(s.steps), time=s.time.hex(), particles_rank=int(s.numParticles),
               info={k: v for k, v in s.mpiInfo().items() if k != "firstLayers"} | {"firstLayers": list(s.mpiInfo()["firstLayers"])},
               digests={n: hashlib.sha256(np.ascontiguousarray(s.view(n)).tobytes()).hexdigest()[:16] for n in NAMES},
               peak_rss_GB=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2 ** 20)
    with open(os.path.join(a.out, f"{a.mode}.r{rank}.json"), "w") as f:
        json.dump(rec, f, indent=1)
    print(json.dumps(rec), flush=True)


def compare(a):
    ok = True
    for f in sorted(glob.glob(os.path.join(a.out, "save.r*.json"))):
        sv = json.load(open(f))
        rs = json.load(open(f.replace("save.", "resume.")))
        same = sv["digests"] == rs["digests"] and sv["time"] == rs["time"] and sv["steps"] == rs["steps"]
        ok = ok and same
        print(f"rank {sv['rank']}/{sv['size']}: {sv['particles_rank']} particles (of {sv['particles_built']}), steps {sv['steps']}, "
              f"resumed bitwise: {same}; save {sv['save_s']:.1f} s, load {rs['load_s']:.1f} s, piece {sv['piece_bytes'] / 1e6:.0f} MB, "
              f"peak RSS {max(sv['peak_rss_GB'], rs['peak_rss_GB']):.2f} GB, {sv['steps_after_s'] / a.steps:.2f} s/step")
    print("bitwise resume:", ok)
    return 0 if ok else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mode", choices=("save", "resume", "compare"))
    ap.add_argument("--out", default="out/mpi_ck")
    ap.add_argument("--cells", type=int, nargs=3, default=(64, 64, 62), help="cells of the block (default 64 64 62: 2,031,616 particles)")
    ap.add_argument("--spacing", type=float, default=0.01, help="grid spacing l [m] (default 0.01)")
    ap.add_argument("--steps", type=int, default=5, help="steps before and after the checkpoint (default 5)")
    a = ap.parse_args()
    if a.steps < 1 or min(a.cells) < 1:
        ap.error("--steps and --cells must be ≥ 1")
    return compare(a) if a.mode == "compare" else run(a)


if __name__ == "__main__":
    sys.exit(main())
