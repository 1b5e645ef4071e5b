"""Per-step wall time of the benchmark block (scripts/tools/bench.py's build_scene: granite on a fixed floor,
slip side walls, initial pure-shear velocity) on 1 process or N MPI ranks (doc/developer/scaling.md):

    /usr/bin/python3 scripts/tools/mpi_bench.py --cells 50 50 25            # serial core
    scripts/tools/mpi_run.sh 2 1 scripts/tools/mpi_bench.py --cells 50 50 25      # 2 ranks × 1 thread

    scripts/tools/mpi_run.sh 4 1 scripts/tools/mpi_bench.py --cells 50 50 25 --distribute   # each rank builds its slab

Every rank prints one JSON line (rank, particles, seconds per step, phase times per step, memory: the peak
resident set VmHWM [B] after import, after the build, after the first step and at the end, the node layers,
nodes and bytes of grid and particles the rank holds); the ranks
step in lock-step (two shared-node exchanges and one reduction per step), so rank 0's time is the
step time. Timings on a loaded host are labelled as such in doc/developer/scaling.md. (The benchmark's scenes
live beside it in scripts/tools/bench_scenes.py.)"""
import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, nargs="+", default=[50, 50, 25], help="block size in cells (2 or 3 numbers)")
    ap.add_argument("--material", choices=["elastic", "dpgk"], default="elastic")
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--warmup", type=int, default=3)
    ap.add_argument("--distribute", action="store_true", help="under MPI each rank builds only its slab (yade_mpm.parallel.distribute)")
    a = ap.parse_args()
    if len(a.cells) not in (2, 3) or min(a.cells) < 1:
        ap.error(f"--cells = {a.cells} must be 2 or 3 integers ≥ 1")
    if a.steps < 1 or a.warmup < 0:
        ap.error("--steps must be ≥ 1 and --warmup ≥ 0")
    from bench_scenes import build_scene
    import yade_mpm as ym
    peak = {"import": vmhwm()}
    s = build_scene(len(a.cells), a.material, tuple(a.cells), distribute=a.distribute)
    peak["build"] = vmhwm()
    n_built = s.numParticles
    n_total = int(round(ym._core.mpiSum(float(n_built)))) if a.distribute and hasattr(ym._core, "mpiSum") else n_built
    s.run(1)
    peak["first_step"] = vmhwm()
    s.run(max(a.warmup - 1, 0))
    p0 = dict(s._phaseTimes())
    t0 = time.perf_counter()
    s.run(a.steps)
    dt = (time.perf_counter() - t0) / a.steps
    ph = {k: (v - p0.get(k, 0.0)) / a.steps for k, v in dict(s._phaseTimes()).items()}
    peak["end"] = vmhwm()
    info = s.mpiInfo() if hasattr(s, "mpiInfo") else {"rank": 0, "size": 1, "firstLayers": [], "haloBytesSent": 0,
                                                      "gridNodes": len(s._nodePositions()), "distributedBuild": False}
    print(json.dumps(dict(rank=info["rank"], ranks=info["size"], threads=ym.getThreads(), particles_total=n_total,
                          particles_built=n_built, particles=s.numParticles, seconds_per_step=dt, phase_seconds_per_step=ph,
                          first_layers=list(info["firstLayers"]), halo_bytes_sent=info["haloBytesSent"],
                          distributed_build=bool(info["distributedBuild"]), grid_nodes=int(info["gridNodes"]),
                          held_layers=list(info.get("heldLayers", [])), grid_bytes=info.get("gridBytes"),
                          particle_bytes=info.get("particleBytes"), peak_rss=peak, vm_peak=vmhwm("VmPeak:"))), flush=True)


def vmhwm(field="VmHWM:"):
    """This process's peak resident set so far [B] (VmHWM of /proc/self/status, or `field`, e.g. VmPeak: the peak
    address space; 0 where unavailable)."""
    try:
        with open("/proc/self/status") as f:
            return next((int(line.split()[1]) * 1024 for line in f if line.startswith(field)), 0)
    except OSError:
        return 0


if __name__ == "__main__":
    main()
