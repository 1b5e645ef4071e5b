"""Every script under scripts/ still runs: the scripts without a test of their own, each on a small case
(one thread, a few seconds), checked for exit status 0 and the output it promises. Scripts tested
elsewhere: tunnel_spalling, uniaxial_flaw, circular_opening, penny_crack (test_courant, test_tunnel_script,
test_case_results …), stability, report, study_report, sweep, fidelity_variants, bench, bench_kernel,
regress (test_bad_input), mpi_run.sh (test_mpi)."""
import csv
import json
import os
import subprocess
import sys

import pytest
from helpers import script_path

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))



def run(script, *args, env=None, timeout=300):
    e = dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=os.path.join(ROOT, "py"), **(env or {}))
    r = subprocess.run([sys.executable, script_path(script), *map(str, args)], env=e, capture_output=True,
                       text=True, timeout=timeout)
    return r


def ok(r):
    assert r.returncode == 0, (r.stdout[-2000:], r.stderr[-3000:])
    return r.stdout


def test_compare_bonded_small(tmp_path):
    """The MPM intact uniaxial run to 0.03 % strain and the Kirsch part on a 0.6 m block (three MPM grids, one
    sphere size); summary.json with both parts and no stopped run."""
    out = ok(run("compare_bonded.py", "--out", tmp_path, "--parts", "mpm_intact,kirsch", "--mpm-spacing", 0.0025,
                 "--max-strain", 0.0003, "--kirsch-domain", 0.6, "--kirsch-mpm-spacing", 0.05, "--kirsch-dem-radii", 0.05))
    s = json.load(open(tmp_path / "summary.json"))
    assert s["stopped"] == [] and [r["method"] for r in s["kirsch"]] == ["mpm"] * 3 + ["jcfpm"]
    assert (tmp_path / "mpm_intact.npz").exists() and "wrote" in out


def test_compare_bonded_names_a_failed_run_and_goes_on(tmp_path):
    """A part that fails (a grid spacing circular_opening.py refuses) is named in the summary and the exit
    status; the other runs still ran."""
    r = run("compare_bonded.py", "--out", tmp_path, "--parts", "kirsch", "--kirsch-domain", 0.6, "--kirsch-mpm-spacing", 0.04,
            "--kirsch-dem-radii", 0.05)
    assert r.returncode == 1, r.stderr[-2000:]
    s = json.load(open(tmp_path / "summary.json"))
    assert [x.split(":")[0] for x in s["stopped"]] == ["kirsch/mpm 80 mm", "kirsch/mpm 40 mm"]
    assert [x["method"] for x in s["kirsch"]] == ["mpm", "jcfpm"]          # the 60 mm run and the JCFpm run


def test_hybrid_rockfall_small(tmp_path):
    out = ok(run("hybrid_rockfall.py", "--out", tmp_path, "--spacing", 0.02, "--length", 0.6, "--height", 0.1,
                 "--end-time", 3e-4, "--vtu-every", 0, "--threads", 1, "--progress", 100))
    assert "600 MPM particles" in out and (tmp_path / "summary.json").exists()


def test_tunnel_variants_small():
    out = ok(run("tunnel_variants.py", "--case", "intact", "--spacing", 0.0025, "--end-time", 5e-5))
    res = json.loads(out.split("RESULT ", 1)[1].splitlines()[0])
    assert res["case"] == "intact" and res["steps"] > 0


def test_uniaxial_flaw_3d_small(tmp_path):
    ok(run("uniaxial_flaw_3d.py", "--out", tmp_path, "--spacing", 0.004, "--slab-cells", 2, "--end-time", 3e-4))
    assert (tmp_path / "compare.json").exists() and (tmp_path / "3d" / "run.json").exists()


def test_penny_prism_3d_small(tmp_path):
    out = ok(run("penny_prism_3d.py", "--out", tmp_path, "--spacing", 0.004, "--runs", "intact:z", "--end-time", 5e-5))
    assert "8000 particles" in out and (tmp_path / "summary.json").exists()


def test_penny_crack_compare_small(tmp_path):
    ok(run("penny_crack.py", "--out", tmp_path / "run", "--parts", "damage", "--size", 1.2, "--ramp-time", 0.004,
           "--end-time", 0.05, "--record-every", 0.005, "--laws", "benz-asphaug", "--progress", 1000))
    out = ok(run("penny_crack_compare.py", "--out", tmp_path / "cmp", f"a={tmp_path / 'run'}"))
    assert "| a | 0.02 |" in out and (tmp_path / "cmp.csv").exists() and (tmp_path / "cmp.png").exists()


def test_boundaries_study_slip(tmp_path):
    out = ok(run("boundaries_study.py", "--out", tmp_path, "--parts", "slip"))
    assert "slip-onesided" in out


def test_bench_material_cost_small(tmp_path):
    out = ok(run("bench_material_cost.py", "--out", tmp_path, "--size", 0.2, "--spacing", 0.02, "--steps", 5, "--repeat", 1))
    assert "dpgk_full" in out


def test_bench_ab_two_builds(tmp_path):
    """This build against itself, one repeat of the free elastic block."""
    ok(run("bench_ab.py", "a=py", "b=py", "--out", tmp_path, "--cases", "free_elastic", "--threads", 1, "--repeats", 1))
    assert (tmp_path / "summary.json").exists() and (tmp_path / "table.md").exists()


def test_mpi_scripts_on_one_process(tmp_path):
    """The MPI scripts run on one process too (mpi_tunnel with the serial core, mpi_checkpoint_big with the
    MPI build on one rank: save, resume, compare bitwise)."""
    rb = json.loads(ok(run("mpi_bench.py", "--cells", 10, 10, "--steps", 2, "--warmup", 1)).strip().splitlines()[-1])
    assert rb["particles_total"] == 400
    rr = json.loads(ok(run("mpi_rebalance.py", "--spacing", 0.01, "--steps", 10)).strip().splitlines()[-1])
    assert rr["particles"] > 0
    ok(run("mpi_tunnel.py", "run", "--out", tmp_path / "t", "--spacing", 0.0025, "--end-time", 5e-5))
    assert (tmp_path / "t" / "rank0.npz").exists()
    mpi = {"YADE_MPM_MPI": "1"}
    for mode in ("save", "resume"):
        ok(run("mpi_checkpoint_big.py", mode, "--out", tmp_path / "ck", "--cells", 6, 6, 6, "--steps", 2, env=mpi))
    assert "bitwise resume: True" in ok(run("mpi_checkpoint_big.py", "compare", "--out", tmp_path / "ck"))


def test_pic_dissipation_small(tmp_path):
    """One Courant number, one wavelength, 20 µs, both velocity updates: the CSV rows (FLIP keeps more), and bad
    input named."""
    ok(run("pic_dissipation.py", "--out", tmp_path, "--courant", "1", "--wavelengths", "25", "--time", "2e-5"))
    rows = {r["velocity_update"]: float(r["energy_left"]) for r in csv.DictReader(open(tmp_path / "pic_dissipation.csv"))}
    assert set(rows) == {"pic", "flip"} and 0.9 < rows["pic"] < rows["flip"] <= 1.0
    for bad in (["--courant", "2"], ["--velocity-update", "apic"]):
        r = run("pic_dissipation.py", "--out", tmp_path, *bad)
        assert r.returncode == 2 and bad[0] in r.stderr


def test_circular_opening_names_a_stopped_run_and_goes_on(tmp_path, monkeypatch):
    """A spacing of the convergence ladder that the solver stops (here: run_case raises the solver's error for the coarse
    spacing) is named under "stopped" with its message, the main run still runs and writes its results, exit status 1;
    if the main run stops, summary.json still says why."""
    import importlib.util
    import yade_mpm as ym
    spec = importlib.util.spec_from_file_location("circular_opening", script_path("circular_opening.py"))
    co = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(co)
    real = co.run_case

    def failing(bad):
        def run_case(l, *a, **k):
            if abs(l - bad) < 1e-12:
                raise ym.MpmSimulationError(f"MPM stopped at step 7: test failure at l = {l}")
            return real(l, *a, **k)
        return run_case
    args = ["--out", str(tmp_path / "a"), "--domain", "0.6", "--spacing", "0.05", "--convergence-spacings", "0.06", "0.05",
            "--no-vtu", "--max-time", "0.002"]
    monkeypatch.setattr(co, "run_case", failing(0.06))
    with pytest.raises(SystemExit) as e:
        co.main(args)
    assert e.value.code == 1
    s = json.load(open(tmp_path / "a" / "summary.json"))
    assert [x["grid_spacing_m"] for x in s["stopped"]] == [0.06] and "test failure" in s["stopped"][0]["error"]
    assert s["grid_spacing_m"] == 0.05 and [c["grid_spacing_m"] for c in s["convergence"]] == [0.05]
    args[1] = str(tmp_path / "b")
    monkeypatch.setattr(co, "run_case", failing(0.05))
    with pytest.raises(SystemExit) as e:
        co.main(args)
    assert e.value.code == 1
    s = json.load(open(tmp_path / "b" / "summary.json"))
    assert [x["grid_spacing_m"] for x in s["stopped"]] == [0.05] and [c["grid_spacing_m"] for c in s["convergence"]] == [0.06]
