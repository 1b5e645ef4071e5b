"""Wall time of a scene whose material moves, with and without dynamic load balance (doc/developer/scaling.md):
the drifting block of `yade_mpm_paper.cases.drifting_block` on N MPI ranks.

    scripts/tools/mpi_run.sh 2 1 scripts/tools/mpi_rebalance.py --spacing 0.00125 --steps 700                  # re-cut at 1.1
    scripts/tools/mpi_run.sh 2 1 scripts/tools/mpi_rebalance.py --spacing 0.00125 --steps 700 --rebalance inf   # never

Every rank prints one JSON line: rank, particles on the rank at the end, slab layout, re-cuts, max/mean of
the per-rank counts at the last re-sort, particles migrated, wall seconds of the run."""
import argparse
import json
import math
import time


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spacing", type=float, default=0.00125, help="grid spacing [m] (0.01 m: 960 particles)")
    ap.add_argument("--steps", type=int, default=700, help="steps (700 at 1.25 mm: the block moves ~0.2 m)")
    ap.add_argument("--rebalance", type=float, default=1.1, help="Solver.mpiRebalance (inf: never re-cut)")
    a = ap.parse_args()
    if not (a.spacing > 0 and math.isfinite(a.spacing)) or a.steps < 1:
        ap.error("--spacing must be > 0 [m] and --steps ≥ 1")
    from yade_mpm_paper import cases
    s = cases.drifting_block(a.spacing, rebalance=a.rebalance)
    t0 = time.perf_counter()
    s.run(a.steps)
    wall = time.perf_counter() - t0
    i = s.mpiInfo() if hasattr(s, "mpiInfo") else {"rank": 0, "size": 1, "firstLayers": [], "rebalances": 0, "imbalance": 1.0, "migrated": 0}
    print(json.dumps(dict(rank=i["rank"], ranks=i["size"], particles=s.numParticles, first_layers=list(i["firstLayers"]),
                          rebalances=i["rebalances"], imbalance=i["imbalance"], migrated=i["migrated"], seconds=wall,
                          rebalance=a.rebalance, steps=a.steps, spacing=a.spacing)), flush=True)


if __name__ == "__main__":
    main()
