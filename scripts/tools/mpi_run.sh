#!/bin/bash
# Runs a yade_mpm script on N MPI ranks of this machine with Debian's Open MPI (doc/developer/scaling.md):
#   scripts/tools/mpi_run.sh N [THREADS] script.py [args…]
# N ranks × THREADS OpenMP threads each (default 1). Every rank runs the same script; yade_mpm loads its
# MPI core (_core_mpi) because mpirun sets OMPI_COMM_WORLD_SIZE. --oversubscribe allows more ranks than
# cores (tests on small hosts); --bind-to none leaves the threads of a rank free to move.
# Open MPI refuses to run as root unless OMPI_ALLOW_RUN_AS_ROOT=1 and OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# are set: this launcher sets them (containers often run as root).
set -euo pipefail
if [ $# -lt 2 ]; then echo "usage: $0 RANKS [THREADS] script.py [args…]" >&2; exit 2; fi
N=$1; shift
T=1
if [[ "$1" =~ ^[0-9]+$ ]]; then T=$1; shift; fi
[[ "$N" =~ ^[1-9][0-9]*$ ]] || { echo "RANKS = '$N' must be an integer ≥ 1" >&2; exit 2; }
[[ "$T" =~ ^[1-9][0-9]*$ ]] || { echo "THREADS = '$T' must be an integer ≥ 1" >&2; exit 2; }
here=$(cd "$(dirname "$0")/../.." && pwd)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# A rank waiting in MPI yields its core (shared or loaded hosts: busy polling slowed the 2-rank tunnel
# 3.9×, doc/developer/scaling.md); OMPI_MCA_mpi_yield_when_idle=0 restores Open MPI's polling on dedicated cores.
export OMPI_MCA_mpi_yield_when_idle=${OMPI_MCA_mpi_yield_when_idle:-1}
export OMP_NUM_THREADS=$T
export PYTHONPATH="$here/py${PYTHONPATH:+:$PYTHONPATH}"
pass=(-x OMP_NUM_THREADS -x PYTHONPATH)
[ -n "${YADE_MPM_MPI:-}" ] && pass+=(-x YADE_MPM_MPI)
[ -n "${YADE_MPM_BUILD_DIR:-}" ] && pass+=(-x YADE_MPM_BUILD_DIR)   # another build folder (py/yade_mpm/_build.py), on every host
exec mpirun -np "$N" --oversubscribe --bind-to none "${pass[@]}" /usr/bin/python3 "$@"
