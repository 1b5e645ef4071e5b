"""Run a yade-batch table on a Dask cluster: every line a separate process (`yade -n -x SCRIPT` with
YADE_BATCH=TABLE:LINE, as yade-batch runs it), on this machine or on many.

    /usr/bin/python3 scripts/studies/sweep.py TABLE SCRIPT                                  # LocalCluster, loopback only
    /usr/bin/python3 scripts/studies/sweep.py TABLE SCRIPT --scheduler tcp://HOST:8786      # a running cluster

LocalCluster: workers = cores / --threads-per-run, one run at a time each. A running cluster: start
`dask-scheduler` on one node and `dask-worker tcp://HOST:8786 --nthreads RUNS` on every node (under Slurm:
one worker per node, doc/guide/studies.md); the table, the script and the study folder must be on a file system
every node sees, at the same path. A line runs in its own folder OUT/<description>/ (yade_mpm_paper.batch) with
its log in log.txt; a line whose summary.csv exists is skipped (resume = the same command again); a line
that fails (bad parameter, solver error, its worker died) is reported with its message and log and the
others go on; Ctrl-C (SIGINT/SIGTERM) stops the running lines and keeps the finished ones. At the end, the
study report (scripts/studies/study_report.py): OUT/study.csv, study.md and plots. Exit status 0 when every line
is done, 1 otherwise.
"""
import argparse
import math
import os
import signal
import sys
import time
import uuid

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import study_report  # noqa: E402  (the sibling script: merged CSV and plots)
from yade_mpm_paper import batch  # noqa: E402


def parse(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("table", help="parameter table (yade-batch format; doc/guide/studies.md)")
    ap.add_argument("script", help="the script every line runs (it reads its line with readParamsFromTable)")
    ap.add_argument("--scheduler", default=None, help="address of a running Dask scheduler, tcp://HOST:8786 (default: a LocalCluster)")
    ap.add_argument("--workers", type=int, default=None, help="LocalCluster workers (default: cores / threads per run)")
    ap.add_argument("--threads-per-run", type=int, default=1, help="OpenMP threads of each run (default %(default)s)")
    ap.add_argument("--runner", choices=("yade", "python"), default="yade",
                    help="run a line as `yade -n -x SCRIPT` (default) or `python3 SCRIPT` (the worker's interpreter)")
    ap.add_argument("--lines", default=None, help="only these table lines, e.g. 3,5-9 (line numbers as in an editor)")
    ap.add_argument("--retries", type=int, default=0,
                    help="LocalCluster: times a line whose worker died is started again (default 0: reported failed; rerun to complete)")
    ap.add_argument("--line-timeout", type=float, default=0.0, help="wall seconds after which a run is stopped and failed (0 = none)")
    ap.add_argument("--progress", type=float, default=30.0, help="wall seconds between progress lines (default %(default)s)")
    ap.add_argument("--no-report", dest="report", action="store_false", help="skip the study report at the end")
    a = ap.parse_args(argv)
    for name in ("table", "script"):
        if not os.path.isfile(getattr(a, name)):
            ap.error(f"{name} {getattr(a, name)!r}: no such file")
    if a.threads_per_run < 1 or (a.workers is not None and a.workers < 1) or a.retries < 0:
        ap.error("--threads-per-run and --workers must be ≥ 1, --retries ≥ 0")
    if not (a.progress > 0 and a.line_timeout >= 0):
        ap.error("--progress must be > 0 s and --line-timeout ≥ 0 s")
    return a


def pick_lines(spec, available):
    if not spec:
        return available
    want = set()
    for part in spec.split(","):
        lo, _, hi = part.partition("-")
        want |= set(range(int(lo), int(hi or lo) + 1))
    missing = sorted(want - set(available))
    if missing:
        raise SystemExit(f"--lines: no run on table line(s) {missing}; runs are on lines {available}")
    return [ln for ln in available if ln in want]


# --------------------------------------------------------------------------- on a worker: one line
def run_line(line, command, env, cwd, run_dir, timeout, stop_name):
    """Run one table line as a child process (its output in RUN/log.txt); stop it when the sweep's stop
    Event is set or after `timeout` s. The child dies with this worker (PR_SET_PDEATHSIG). Returns a dict."""
    import ctypes
    import socket
    import subprocess
    run_dir = os.path.join(cwd, run_dir)
    if os.path.exists(os.path.join(run_dir, "summary.csv")):   # done (Dask may recompute a task whose result it lost)
        return dict(line=line, rc=0, wall=0.0, host=socket.gethostname(), reason=None)
    os.makedirs(run_dir, exist_ok=True)
    for f in ("error.txt", "job.json"):             # batch.ERROR, batch.JOB (no yade_mpm import needed on the worker)
        if os.path.exists(os.path.join(run_dir, f)):
            os.remove(os.path.join(run_dir, f))
    if command[0] == "python":
        command = [sys.executable] + command[1:]

    def die_with_worker():
        ctypes.CDLL("libc.so.6").prctl(1, signal.SIGTERM)      # PR_SET_PDEATHSIG

    stop = None
    try:
        from distributed import Event
        stop = Event(stop_name)
    except Exception:                                # not in a worker (or no client): no stop request possible
        pass
    t0, reason = time.time(), None
    with open(os.path.join(run_dir, "log.txt"), "w") as log:
        p = subprocess.Popen(command, cwd=cwd, env=dict(os.environ, **env), stdout=log, stderr=subprocess.STDOUT,
                             preexec_fn=die_with_worker, start_new_session=True)
        while True:
            try:
                rc = p.wait(timeout=1.0)
                break
            except subprocess.TimeoutExpired:
                pass
            if reason is None and stop is not None and stop.is_set():
                reason = "stopped by the sweep (Ctrl-C)"
            if reason is None and timeout and time.time() - t0 > timeout:
                reason = f"stopped after --line-timeout {timeout:g} s"
            if reason:
                p.terminate()
                try:
                    rc = p.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    p.kill()
                    rc = p.wait()
                break
    return dict(line=line, rc=rc, wall=time.time() - t0, host=socket.gethostname(), reason=reason)


# --------------------------------------------------------------------------- the sweep
def fmt_s(s):
    if s is None or not math.isfinite(s):
        return "?"
    s = int(round(s))
    return f"{s // 3600}h{s // 60 % 60:02d}m" if s >= 3600 else (f"{s // 60}m{s % 60:02d}s" if s >= 60 else f"{s}s")


def log_tail(run_dir, n=6):
    p = os.path.join(run_dir, "log.txt")
    if not os.path.exists(p):
        return ""
    with open(p, errors="replace") as f:
        return "".join(f.readlines()[-n:])


def record_failure(run_dir, message, replace=False):
    """error.txt of a line the script could not record itself (killed, crashed, stopped); `replace`: also
    when the script wrote one (a run the sweep stopped)."""
    p = os.path.join(run_dir, batch.ERROR)
    if replace or not os.path.exists(p):
        os.makedirs(run_dir, exist_ok=True)
        with open(p, "w") as f:
            f.write(message + "\n")
    with open(p) as f:
        return f.read().strip()


class Stop:
    """SIGINT / SIGTERM → a flag the loop polls (the runs stop through the Dask Event)."""

    def __init__(self):
        self.requested = None
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self.handler)

    def handler(self, signum, frame):
        if self.requested:                           # a second Ctrl-C: leave at once
            raise KeyboardInterrupt
        self.requested = signal.Signals(signum).name
        print(f"\n[sweep] {self.requested}: stopping the running lines (finished ones are kept; again to quit at once)", flush=True)


def open_client(a):
    import dask
    from distributed import Client, LocalCluster
    if a.scheduler:
        c = Client(a.scheduler, timeout=60)
        return c, None, f"cluster {a.scheduler}"
    n = a.workers or max(1, (os.cpu_count() or 1) // a.threads_per_run)
    dask.config.set({"distributed.scheduler.allowed-failures": a.retries})   # a dead worker's line: failed (or retried)
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)   # the workers (and their runs) inherit it: a terminal's Ctrl-C
    try:                                                 # reaches only this process, which stops the runs in order
        cl = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None)
    finally:
        signal.signal(signal.SIGINT, old)
    return Client(cl), cl, f"LocalCluster {cl.scheduler_address}: {n} workers"


def line_command(a, script):
    """The command every table line runs (`yade -n -x SCRIPT` or `python SCRIPT`) and its environment: OpenMP
    threads per run, no display, this process's PYTHONPATH passed on."""
    if a.runner == "yade":
        command = ["yade", f"--threads={a.threads_per_run}", "-n", "-x", script]
    else:
        command = ["python", script]
    env = {"OMP_NUM_THREADS": str(a.threads_per_run), "DISPLAY": ""}
    if os.environ.get("PYTHONPATH"):
        env["PYTHONPATH"] = os.environ["PYTHONPATH"]
    return command, env


class Sweep:
    """The lines still to run, handed to the Dask workers one per free worker thread, and what became of them:
    finished, failed (line -> message) or interrupted. The running lines stop through the Dask Event `ev`."""

    def __init__(self, a, client, slots, table, info, todo, command, env, stop, n_chosen, n_done):
        from distributed import Event
        self.a, self.client, self.slots, self.table, self.info = a, client, slots, table, info
        self.command, self.env, self.stop, self.n_chosen, self.n_done = command, env, stop, n_chosen, n_done
        self.token = uuid.uuid4().hex[:8]
        self.ev = Event(f"sweep-stop-{self.token}", client=client)
        self.futs, self.queue, self.pending = {}, list(todo), set()
        self.t0, self.last, self.walls = time.time(), 0.0, []
        self.failed, self.finished, self.interrupted = {}, [], []

    def submit(self):
        """Keep one line per worker thread in flight: a line is handed to a worker only when one is free, so
        a worker that dies takes only the line it was running with it (and workers may join or leave)."""
        self.slots = sum(self.client.nthreads().values())
        while self.queue and len(self.pending) < max(self.slots, 1) and not self.stop.requested:
            ln = self.queue.pop(0)
            f = self.client.submit(run_line, ln, self.command, dict(self.env, YADE_BATCH=f"{self.table}:{ln}"), os.getcwd(),
                                   self.info[ln][1], self.a.line_timeout, self.ev.name, key=f"sweep-{self.token}-line{ln}", pure=False)
            self.futs[f] = ln
            self.pending.add(f)

    def progress(self, force=False):
        """A progress line (done, running, failed, waiting, ETA) every --progress seconds, or now (force)."""
        now = time.time()
        if not force and now - self.last < self.a.progress:
            return
        self.last = now
        mean = sum(self.walls) / len(self.walls) if self.walls else None
        eta = mean * (len(self.queue) + 0.5 * len(self.pending)) / max(self.slots, 1) if mean else None
        print(f"[sweep] {self.n_done + len(self.finished)}/{self.n_chosen} done, {len(self.pending)} running, {len(self.failed)} failed, "
              f"{len(self.queue)} waiting; elapsed {fmt_s(now - self.t0)}, ETA {fmt_s(eta)}", flush=True)

    def collect(self, f):
        """A line whose task ended: finished (its summary.csv written), interrupted by the sweep, or failed (its
        error.txt says why: exit status, timeout or the worker that died, with the last lines of its log)."""
        self.pending.discard(f)
        ln = self.futs.pop(f)                        # forget it: Dask would rerun a line whose result a dead worker held
        desc, run_dir = self.info[ln]
        if f.status == "finished":
            r = f.result()
            self.walls.append(r["wall"])
            if r["rc"] == 0 and os.path.exists(os.path.join(run_dir, batch.SUMMARY)):
                self.finished.append(ln)
                print(f"[sweep] line {ln} ({desc}) done in {fmt_s(r['wall'])} on {r['host']}", flush=True)
                return
            if r["reason"] and r["reason"].startswith("stopped by the sweep"):
                self.interrupted.append(ln)
                record_failure(run_dir, f"interrupted: {r['reason']}", replace=True)
                return
            msg = record_failure(run_dir, f"{r['reason'] or 'exit status %d' % r['rc']} on {r['host']}; last lines of the log:\n"
                                 + log_tail(run_dir))
        else:                                   # the task itself failed: its worker died (KilledWorker), …
            exc = f.exception()
            msg = record_failure(run_dir, f"{type(exc).__name__}: the worker running this line died or failed ({exc}); "
                                 "last lines of the log:\n" + log_tail(run_dir))
        self.failed[ln] = msg
        print(f"[sweep] line {ln} ({desc}) FAILED: {msg.splitlines()[0]} (log: {os.path.join(run_dir, 'log.txt')})", flush=True)

    def run(self):
        """Until every line has ended (or, after a stop request, every running line has)."""
        from distributed import wait
        self.submit()
        while self.pending or (self.queue and not self.stop.requested):
            if self.stop.requested and not self.ev.is_set():     # the running lines stop through the Event
                self.ev.set()
            try:
                finished_now = wait(list(self.pending), timeout=1.0, return_when="FIRST_COMPLETED").done if self.pending else ()
            except TimeoutError:
                finished_now = ()
            if not self.pending:
                time.sleep(1.0)                         # no worker yet (a cluster still starting)
            for f in finished_now:
                self.collect(f)
            for f in finished_now:
                f.release()
            self.submit()
            self.progress(force=bool(finished_now))


def run_lines(a, table, script, info, todo, n_chosen, n_done):
    """The lines `todo` on a cluster (open_client), Ctrl-C handled (Stop); returns (failed, finished, interrupted)."""
    stop = Stop()
    client, cluster, where = open_client(a)
    slots = sum(client.nthreads().values()) or 1
    print(f"[sweep] {where}, {slots} runs at a time, {a.threads_per_run} thread(s) per run, runner {a.runner}", flush=True)
    command, env = line_command(a, script)
    sweep = Sweep(a, client, slots, table, info, todo, command, env, stop, n_chosen, n_done)
    try:
        sweep.run()
    except KeyboardInterrupt:
        print("[sweep] quitting at once", flush=True)
    finally:
        sweep.interrupted += [sweep.futs[f] for f in sweep.pending] + sweep.queue
        client.close()
        if cluster is not None:
            cluster.close()
    return sweep.failed, sweep.finished, sweep.interrupted


def main(argv=None):
    a = parse(argv)
    table, script = os.path.abspath(a.table), os.path.abspath(a.script)
    all_lines = batch.lines(table)
    chosen = pick_lines(a.lines, [ln for ln, _, _ in all_lines])
    info = {ln: (d, r) for ln, d, r in all_lines if ln in chosen}
    done = [ln for ln in chosen if os.path.exists(os.path.join(info[ln][1], batch.SUMMARY))]
    todo = [ln for ln in chosen if ln not in done]
    print(f"[sweep] {a.table}: {len(chosen)} lines, {len(done)} done earlier (skipped), {len(todo)} to run", flush=True)
    failed, finished, interrupted = run_lines(a, table, script, info, todo, len(chosen), len(done)) if todo else ({}, [], [])
    missing = len(chosen) - len(done) - len(finished)
    print(f"[sweep] {len(done) + len(finished)}/{len(chosen)} lines done ({len(finished)} now), {len(failed)} failed, "
          f"{len(set(interrupted))} interrupted" + (f"; run the same command again to complete the {missing} missing" if missing else ""),
          flush=True)
    for ln, msg in sorted(failed.items()):
        print(f"  line {ln} ({info[ln][0]}): {msg.splitlines()[0]}")
    if a.report:
        paths = study_report.write(table)
        print(f"[sweep] study report: {', '.join(paths)}", flush=True)
    return 0 if missing == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
