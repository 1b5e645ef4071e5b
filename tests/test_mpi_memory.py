"""A scene larger than one process may hold runs on 4 MPI ranks (yade_mpm.parallel.distribute, doc/developer/scaling.md
"Memory per rank"): the benchmark block (scripts/tools/mpi_bench.py) built distributed on 4 ranks reports each
rank's peak virtual size; under an address-space limit (`ulimit -v`) just above the largest of them, the same
scene on 1 process fails for want of memory while the 4 ranks, each under that same limit, build and step it.
Skipped without mpirun or the MPI core (fails when setup found MPI); runs are bounded by timeouts."""
import json
import os
import subprocess
import sys

from test_mpi import LAUNCH, ROOT, needs_mpi

pytestmark = needs_mpi
BENCH = os.path.join(ROOT, "scripts", "tools", "mpi_bench.py")
CELLS = ["48", "48", "128"]   # 3D, 2.4 M particles: ≈ 0.8 GB of address space on 1 process, ≈ 0.5 GB per rank on 4


def _run(limit_kb, ranks):
    env = dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=os.path.join(ROOT, "py"))
    env.pop("YADE_MPM_MPI", None)
    args = ["--cells", *CELLS, "--steps", "1", "--warmup", "1"]
    cmd = [sys.executable, BENCH, *args] if ranks == 1 else [LAUNCH, str(ranks), "1", BENCH, *args, "--distribute"]
    shell = (f"ulimit -v {limit_kb}; " if limit_kb else "") + " ".join(f"'{c}'" for c in cmd)
    return subprocess.run(["bash", "-c", shell], env=env, capture_output=True, text=True, timeout=1200)


def _records(text):
    """The JSON records of the ranks (mpirun may join two ranks' lines into one)."""
    dec, out, i = json.JSONDecoder(), [], 0
    while (j := text.find('{"rank"', i)) >= 0:
        rec, i = dec.raw_decode(text, j)
        out.append(rec)
    return out


def test_four_ranks_hold_what_one_cannot():
    free = _run(None, 4)
    assert free.returncode == 0, (free.stdout[-2000:], free.stderr[-3000:])
    lines = _records(free.stdout)
    assert len(lines) == 4 and all(x["distributed_build"] for x in lines)
    peak = max(x["vm_peak"] for x in lines)          # [B] the largest rank's address space
    limit_kb = int(peak * 1.05 / 1024) + 1
    one = _run(limit_kb, 1)
    assert one.returncode != 0, f"1 process held the scene under ulimit -v {limit_kb} kB"
    assert any(w in one.stderr for w in ("MemoryError", "bad_alloc", "Unable to allocate", "memory")), one.stderr[-3000:]
    four = _run(limit_kb, 4)
    assert four.returncode == 0, (limit_kb, four.stdout[-2000:], four.stderr[-3000:])
    n = [x["particles_total"] for x in _records(four.stdout)]
    print(f"ulimit -v {limit_kb} kB: 1 process failed, 4 ranks ran {n[0]} particles")
