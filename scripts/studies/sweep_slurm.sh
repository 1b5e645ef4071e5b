#!/bin/bash
# A study on a Slurm cluster (doc/guide/studies.md): the Dask scheduler and scripts/studies/sweep.py on the first node of
# the allocation, one dask-worker per node (srun), each running cpus-per-task / THREADS_PER_RUN lines at a time.
# Run from the checkout, on a file system every node sees at the same path (the table's `out` is relative to it):
#   sbatch --nodes=4 --cpus-per-task=32 scripts/studies/sweep_slurm.sh scripts/paper/tunnel_spalling.table scripts/paper/tunnel_spalling.py
#   THREADS_PER_RUN=2 sbatch ... (OpenMP threads of each run); extra arguments go to sweep.py
#SBATCH --job-name=yade-mpm-study
#SBATCH --ntasks-per-node=1
#SBATCH --time=24:00:00
set -u
TABLE=$1; SCRIPT=$2; shift 2
THREADS=${THREADS_PER_RUN:-1}
CPUS=${SLURM_CPUS_PER_TASK:-$(nproc)}
HEAD=$(hostname)
LOG=${SLURM_SUBMIT_DIR:-.}/slurm-${SLURM_JOB_ID:-local}
dask-scheduler --host "$HEAD" --port 8786 --no-dashboard > "$LOG.scheduler.log" 2>&1 &
SCHED=$!
sleep 10
srun --ntasks="${SLURM_JOB_NUM_NODES:-1}" --ntasks-per-node=1 \
    dask-worker "tcp://$HEAD:8786" --nworkers 1 --nthreads $((CPUS / THREADS)) --no-dashboard --death-timeout 120 \
    > "$LOG.workers.log" 2>&1 &
WORKERS=$!
/usr/bin/python3 scripts/studies/sweep.py "$TABLE" "$SCRIPT" --scheduler "tcp://$HEAD:8786" --threads-per-run "$THREADS" "$@"
STATUS=$?
kill "$WORKERS" "$SCHED" 2>/dev/null
wait
exit $STATUS
