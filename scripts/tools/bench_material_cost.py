"""What the constitutive update costs per particle and step: the same block with the elastic material,
the DP–GK material with plasticity and damage switched off, and the full DP–GK material (elastic
loading, so no particle yields or damages: the extra cost is the checks alone).

    /usr/bin/python3 scripts/tools/bench_material_cost.py --out out/bench_material
"""
import argparse
import os
import time

import yade_mpm as ym
import yade_mpm.output as out
from yade_mpm import rocks



def measure(mat, size, h, steps):
    s = ym.make_solver((0, 0), (size, size), h)
    ym.add_region(s, mat, (0, 0), (size, size))
    ym.set_initial_stress(s, (-10e6, -5e6, -4e6, 0.0))   # inside every criterion
    s.gravity = (0.0, -9.81)
    s.run(5)
    p0 = dict(s._phaseTimes())
    t0 = time.time()
    s.run(steps)
    wall = time.time() - t0
    p1 = s._phaseTimes()
    n = s.numParticles * steps
    return dict(particles=s.numParticles, ns_per_particle_step=1e9 * wall / n,
                stress_ns_per_particle_step=1e9 * (p1["stress"] - p0["stress"]) / n)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--size", type=float, default=2.0, help="block side [m]")
    ap.add_argument("--spacing", type=float, default=0.01, help="grid spacing [m]")
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3, help="best of this many runs")
    a = ap.parse_args()
    ym.setThreads(a.threads)
    cases = {"elastic": rocks.granite(),
             "dpgk_off": rocks.granite_dpgk(plasticity=False, damage=False),
             "dpgk_full": rocks.granite_dpgk()}
    res = {}
    for name, mat in cases.items():
        runs = [measure(mat, a.size, a.spacing, a.steps) for _ in range(a.repeat)]
        res[name] = min(runs, key=lambda r: r["ns_per_particle_step"])
        print(f"{name:10s} {res[name]['ns_per_particle_step']:8.1f} ns/particle/step, stress phase "
              f"{res[name]['stress_ns_per_particle_step']:6.1f}", flush=True)
    os.makedirs(a.out, exist_ok=True)
    out.write_summary(a.out, dict(threads=a.threads, steps=a.steps, cases=res))


if __name__ == "__main__":
    main()
