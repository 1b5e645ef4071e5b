"""Studies (issue 21): a table line is a run (yade_mpm_paper.batch), under yade-batch and under scripts/studies/sweep.py.

- yade-batch runs a coarse 2-line variant of scripts/paper/tunnel_spalling.table plus a line with a flaw angle
  outside the specimen: each good line's summary.csv is byte-identical to a direct run with the same
  options (1 thread under yade-batch, 2 in the direct run); the bad line fails alone and the merged
  report (scripts/studies/study_report.py) carries its message.
- scripts/studies/sweep.py on a LocalCluster with 2 workers runs a 4-line table (scripts/paper/circular_opening.py,
  coarse); one worker is killed (SIGKILL) while it runs a line: the lines finished before stay untouched,
  the killed line is reported failed and its run process dies with its worker; a rerun runs only that line.
- A table line reads as the same options as a command line; a misspelt column or an unquoted string is
  refused naming it; the shipped tables name only options of their scripts.
Every wait is bounded by a timeout.
"""
import csv
import os
import signal
import subprocess
import sys
import time
from helpers import script_path

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPTS = os.path.join(ROOT, "scripts", "studies")
ENV = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "py"), OMP_NUM_THREADS="2")
TUNNEL_COARSE = dict(spacing="0.0025", end_time="0.0001", checkpoint_every="'0'", vtu_every="0.001", pictures="False")
BAD_ANGLE = 30          # the 60 mm flaw's tip would leave the specimen (allowed ≈ [46, 128]° at 2.5 mm)


def write_table(path, columns, rows):
    with open(path, "w") as f:
        f.write("# test table\n" + " ".join(["description"] + columns) + "\n")
        for desc, vals in rows:
            f.write(" ".join([desc] + vals) + "\n")


def summary_bytes(run_dir):
    with open(os.path.join(run_dir, "summary.csv"), "rb") as f:
        return f.read()


def study_rows(path):
    with open(path, newline="") as f:
        return {r["description"]: r for r in csv.DictReader(f)}


def test_yade_batch_lines_equal_direct_runs_and_a_bad_line_fails_alone(tmp_path, monkeypatch):
    cols = ["cases", "flaw_angle", "filler_mu", "grout_young"] + list(TUNNEL_COARSE) + ["out"]
    coarse = list(TUNNEL_COARSE.values())
    good = {"filled_a50_mu0.3": ("filled_flaw", "50", "0.3", "10.8e9"), "grout_a75_E5.4": ("grout_flaw", "75", "0.6", "5.4e9")}
    rows = [(d, [f"'{c}'", a, m, e] + coarse + ["'study'"]) for d, (c, a, m, e) in good.items()]
    rows.append(("open_a30", ["'open_flaw'", str(BAD_ANGLE), "0.6", "10.8e9"] + coarse + ["'study'"]))
    table = tmp_path / "tunnel.table"
    write_table(table, cols, rows)
    batch = subprocess.Popen(["yade-batch", "-j", "2", "--job-threads", "1", "--log", str(tmp_path / "@.log"), "--plot-update", "0",
                              str(table), script_path("tunnel_spalling.py")], cwd=tmp_path, env=ENV,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    direct = {}
    for d, (c, a, m, e) in good.items():        # the same options on the command line, 2 threads, meanwhile
        direct[d] = subprocess.Popen([sys.executable, script_path("tunnel_spalling.py"), "--out", str(tmp_path / "direct" / d),
                                      "--cases", c, "--flaw-angle", a, "--filler-mu", m, "--grout-young", e, "--spacing", "0.0025",
                                      "--end-time", "0.0001", "--checkpoint-every", "0", "--vtu-every", "0.001", "--no-pictures"],
                                     cwd=tmp_path, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    out, _ = batch.communicate(timeout=300)
    for d, p in direct.items():
        log, _ = p.communicate(timeout=300)
        assert p.returncode == 0, log[-3000:]
    assert "FAILED" in out and out.count("done ") >= 2, out[-3000:]
    for d in good:
        assert summary_bytes(tmp_path / "study" / d) == summary_bytes(tmp_path / "direct" / d), d
    with open(tmp_path / "study" / "filled_a50_mu0.3" / "summary.csv", newline="") as f:
        (row,) = list(csv.DictReader(f))                     # one row, with the line's values
    assert row["case"] == "filled_flaw" and float(row["flaw_angle_deg"]) == 50.0 and float(row["filler_mu"]) == 0.3
    assert float(row["final_displacement_mm"]) > 0.0095 and float(row["peak_stress_MPa"]) > 0
    # the bad line: no summary, its message in error.txt, the merged report and study.md
    bad = tmp_path / "study" / "open_a30"
    assert not (bad / "summary.csv").exists()
    msg = (bad / "error.txt").read_text()
    assert msg.startswith("ValueError: flaw_angle = 30°") and "allowed at l = 2.5 mm: [46, 128]°" in msg, msg
    sys.path.insert(0, SCRIPTS)
    import study_report
    monkeypatch.chdir(tmp_path)                              # a table's `out` is relative to where the study runs
    paths = study_report.write(str(table))
    merged = study_rows(paths[0])
    assert {d: merged[d]["status"] for d in merged} == {"filled_a50_mu0.3": "ok", "grout_a75_E5.4": "ok", "open_a30": "failed"}
    assert merged["open_a30"]["message"] == msg.strip()
    assert float(merged["grout_a75_E5.4"]["grout_young_GPa"]) == 5.4 and merged["grout_a75_E5.4"]["filler_mu"] == ""
    assert "flaw_angle = 30°" in open(paths[1]).read()
    assert any(p.endswith("_vs_flaw_angle_deg.png") for p in paths[2:])


# ------------------------------------------------------------------------------------------------ sweep.py
def yade_runs(table):
    """{pid: (line, parent pid)} of the running processes of `table`'s lines (found by their YADE_BATCH)."""
    found = {}
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            env = open(f"/proc/{pid}/environ", "rb").read().split(b"\0")
            status = open(f"/proc/{pid}/status").read()
        except OSError:
            continue
        spec = [e for e in env if e.startswith(b"YADE_BATCH=" + str(table).encode() + b":")]
        if spec and "\nState:\tZ" not in status:
            ppid = int(status.split("\nPPid:\t")[1].split()[0])
            found[int(pid)] = (int(spec[0].rsplit(b":", 1)[1]), ppid)
    return found


def started(pid):
    """Start time of a process [clock ticks since boot] (0 when it has just ended)."""
    try:
        return int(open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()[19])
    except OSError:
        return 0


def sweep(tmp_path, table, log, *options):
    return subprocess.Popen([sys.executable, script_path("sweep.py"), str(table), script_path("circular_opening.py"),
                             "--progress", "2", *options], cwd=tmp_path, env=ENV, stdout=open(log, "w"),
                            stderr=subprocess.STDOUT, start_new_session=True)


def test_sweep_killed_worker_loses_no_finished_line_and_a_rerun_completes_only_the_missing(tmp_path):
    # circular opening, coarse: line "short" ends first, the others run a few seconds each (tol 1e-12: to max_time)
    cols = ["spacing", "domain", "tol", "max_time", "convergence", "vtu", "out"]
    rows = [("short", ["0.1", "1.2", "1e-12", "0.001", "False", "False", "'study'"])]
    rows += [(f"long{k}", ["0.05", "1.2", "1e-12", "0.008", "=", "=", "="]) for k in (1, 2, 3)]
    table = tmp_path / "co.table"
    write_table(table, cols, rows)
    study = tmp_path / "study"
    p = sweep(tmp_path, table, tmp_path / "sweep1.log", "--workers", "2", "--no-report")
    killed = None
    try:
        t_end = time.time() + 120
        while killed is None and time.time() < t_end and p.poll() is None:
            done = [d for d, _ in rows if (study / d / "summary.csv").exists()]
            runs = yade_runs(table)
            todo = {pid: v for pid, v in runs.items() if not (study / rows[v[0] - 3][0] / "summary.csv").exists()}
            if done and len(todo) == 2:                           # a line done, the next one started: kill the newest run
                before = {d: ((study / d / "summary.csv").stat().st_mtime_ns, summary_bytes(study / d)) for d in done}
                pid, (line, worker) = max(todo.items(), key=lambda kv: started(kv[0]))
                os.kill(worker, signal.SIGKILL)                   # its dask worker
                killed = (pid, line, rows[line - 3][0])
            time.sleep(0.2)
        assert killed, "no line finished while another was running: " + open(tmp_path / "sweep1.log").read()[-3000:]
        p.wait(timeout=150)
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
    log1 = open(tmp_path / "sweep1.log").read()
    pid, line, desc = killed
    t_end = time.time() + 20                                      # the run died with its worker (SIGTERM on parent death)
    while os.path.exists(f"/proc/{pid}") and "\nState:\tZ" not in open(f"/proc/{pid}/status").read() and time.time() < t_end:
        time.sleep(0.2)
    assert not os.path.exists(f"/proc/{pid}") or "\nState:\tZ" in open(f"/proc/{pid}/status").read(), "orphaned run"
    assert p.returncode == 1, log1[-3000:]
    assert f"line {line} ({desc}) FAILED: KilledWorker" in log1, log1[-3000:]
    assert "1 failed" in log1 and "run the same command again to complete the 1 missing" in log1
    assert not (study / desc / "summary.csv").exists() and "KilledWorker" in (study / desc / "error.txt").read_text()
    others = [d for d, _ in rows if d != desc]
    assert all((study / d / "summary.csv").exists() for d in others), log1[-3000:]
    for d, (mtime, data) in before.items():
        assert (study / d / "summary.csv").stat().st_mtime_ns == mtime and summary_bytes(study / d) == data
    after1 = {d: (study / d / "summary.csv").stat().st_mtime_ns for d in others}
    # the rerun: only the missing line runs; every finished summary stays as it was
    p2 = sweep(tmp_path, table, tmp_path / "sweep2.log", "--workers", "1")          # one line left: one worker
    try:
        p2.wait(timeout=120)
    finally:
        if p2.poll() is None:
            os.killpg(p2.pid, signal.SIGKILL)
    log2 = open(tmp_path / "sweep2.log").read()
    assert p2.returncode == 0, log2[-3000:]
    assert "4 lines, 3 done earlier (skipped), 1 to run" in log2 and f"line {line} ({desc}) done" in log2, log2[-3000:]
    assert {d: (study / d / "summary.csv").stat().st_mtime_ns for d in others} == after1
    merged = study_rows(study / "study.csv")
    assert sorted(merged) == sorted(d for d, _ in rows) and all(r["status"] == "ok" for r in merged.values())
    assert not (study / desc / "error.txt").exists()
    assert float(merged["long1"]["simulated_time_s"]) >= 0.008 and merged["long1"]["steps"] == merged["long2"]["steps"]


# ------------------------------------------------------------------------------------------------ tables
def test_table_line_becomes_the_command_line_and_bad_columns_are_named(tmp_path, monkeypatch):
    import argparse
    sys.path.insert(0, os.path.join(ROOT, "py"))
    from yade_mpm_paper import batch
    ap = argparse.ArgumentParser(prog="demo.py")
    ap.add_argument("--out", default="x")
    ap.add_argument("--spacing", type=float, default=0.002)
    ap.add_argument("--cases", default="intact")
    ap.add_argument("--no-pictures", dest="pictures", action="store_false")
    table = tmp_path / "t.table"
    write_table(table, ["spacing", "cases", "pictures"], [("a", ["0.0025", "'open_flaw'", "False"]), ("b", ["=", "'intact'", "True"])])
    monkeypatch.setenv("YADE_BATCH", f"{table}:3")
    a = batch.parse_args(ap, [])
    assert (a.spacing, a.cases, a.pictures, a.out) == (0.0025, "open_flaw", False, os.path.join("out", "t", "a"))
    monkeypatch.setenv("YADE_BATCH", f"{table}:4")
    a = batch.parse_args(ap, [])
    assert (a.spacing, a.cases, a.pictures, a.out) == (0.0025, "intact", True, os.path.join("out", "t", "b"))
    assert batch.lines(str(table)) == [(3, "a", os.path.join("out", "t", "a")), (4, "b", os.path.join("out", "t", "b"))]
    write_table(table, ["spacing", "flaw_angel"], [("a", ["0.0025", "30"])])
    monkeypatch.setenv("YADE_BATCH", f"{table}:3")
    try:
        batch.parse_args(ap, [])
        raise AssertionError("an unknown column was accepted")
    except batch.BadParameter as e:
        assert "['flaw_angel'] are not options of demo.py; allowed: out, cases, pictures, spacing" in str(e)
    write_table(table, ["spacing", "cases"], [("a", ["0.0025", "open_flaw"])])          # an unquoted string
    try:
        batch.parse_args(ap, [])
        raise AssertionError("an unquoted string was accepted")
    except batch.BadParameter as e:
        assert "not a Python literal" in str(e) and "quote strings" in str(e)


def test_shipped_tables_name_only_options_of_their_scripts():
    import re
    sys.path.insert(0, os.path.join(ROOT, "py"))
    from yade_mpm_paper import batch
    for name in ("tunnel_spalling", "uniaxial_flaw", "penny_crack", "circular_opening"):
        table = script_path(name + ".table")
        help_text = subprocess.run([sys.executable, script_path(name + ".py"), "--help"], env=ENV, capture_output=True,
                                   text=True, timeout=60).stdout
        options = set(re.findall(r"--([a-z][a-z0-9-]*)", help_text))
        runs = batch.lines(table)
        assert len(runs) >= 4 and len({r for _, _, r in runs}) == len(runs), name       # one folder per line
        for col in batch.read_table(table)[runs[0][0]]:
            if col not in ("description", "out"):
                assert col.replace("_", "-") in options or "no-" + col.replace("_", "-") in options, (name, col)
