"""scripts/paper/report.py names folders relative to the repository: the generated doc/validation/report.md holds no
absolute path of the machine it was made on (also for output folders elsewhere)."""
import os
import re
import subprocess
import sys
from helpers import script_path

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ABSOLUTE = re.compile(r"(?<![\w.])/(?:work|home|tmp|root|mnt|srv|opt|var)/")   # /usr/bin/python3 in commands is fine


def test_generated_report_names_no_absolute_path(tmp_path):
    out = tmp_path / "elsewhere" / "out"
    out.mkdir(parents=True)
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "py"))
    r = subprocess.run([sys.executable, script_path("report.py"), "--root", str(out), "--doc", str(tmp_path / "doc"),
                        "--dir", f"penny_crack_damage={tmp_path / 'crack_runs' / 'c02'}"], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    text = (tmp_path / "doc" / "validation" / "report.md").read_text()
    assert str(tmp_path) not in text and not ABSOLUTE.search(text), ABSOLUTE.search(text)
    assert "…/elsewhere/out (outside the repository)" in text


def test_validation_md_has_no_absolute_path():
    text = open(os.path.join(ROOT, "doc", "validation", "report.md")).read()
    hit = ABSOLUTE.search(text) or (os.path.dirname(ROOT) + "/" in text)
    assert not hit, hit


def test_baseline_from_a_tunnel_run_and_the_variant_matrix(tmp_path):
    """fidelity_variants.py --baseline-from: the baseline row from a finished tunnel_spalling.py case folder (synthetic
    here), and report.py's matrix shows the toe gap, the left-side spalling and the plastic-strain columns from it."""
    import json

    import numpy as np
    case = tmp_path / "runs" / "tunnel" / "filled_flaw"          # outside the report's root
    case.mkdir(parents=True)
    rep = dict(softened_fraction=0.0, bands=[], toe_link_to_opening="nowhere", toe_failed_gap_mm=9.5, toe_failed_nearest="left wall",
               spalled_by_place_mm2={"left wall": 80.0, "left corner": 11.0, "left spandrel": 7.0}, left_waist_inward_mm=dict(p90=0.368))
    json.dump(dict(snapshots={"08ms": dict(rep, toe_failed_gap_mm=10.5), "20ms": rep}, first_crack=dict(time=2.1e-4, location="flaw toe"),
                   finished=True), open(case / "case.json", "w"))
    json.dump(dict(cases=[dict(case="filled_flaw", grid_spacing_m=0.002, particles=20748, steps=56734, wall_time_s=700.0)]),
              open(case.parent / "summary.json", "w"))
    for key, top in (("08ms", 0.01), ("20ms", 0.04)):
        np.savez_compressed(case / f"snapshot_{key}.npz", plastic_strain=np.linspace(0, top, 101))
    d = np.linspace(0, 2, 201)
    np.savetxt(case / "axial_stress.csv", np.column_stack([d / 100, d, 100 * d]), delimiter=",", header="time_s,displacement_mm,axial_stress_MPa")
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "py"))
    run = lambda *args: subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env, timeout=120, cwd=tmp_path)
    r = run(script_path("fidelity_variants.py"), "--scene", "tunnel", "--baseline-from", "runs/tunnel/filled_flaw",
            "--out", "out/fidelity_variants")
    assert r.returncode == 0, r.stderr[-2000:]
    j = json.load(open(tmp_path / "out" / "fidelity_variants" / "tunnel_filled_flaw_baseline.json"))
    assert j["stress_MPa_at_mm"]["0.5"] == 50.0 and j["stress_MPa_at_mm"]["2"] == 200.0
    assert j["snapshots"]["20ms"]["eps_p_max"] == 0.04 and j["snapshots"]["8ms"]["eps_p_max"] == 0.01
    assert j["snapshots"]["20ms"]["eps_p_soft_end"] == 0.9 * 0.1 and j["first_crack"] == dict(time_s=2.1e-4, at="flaw toe")
    r = run(script_path("report.py"), "--root", "out", "--doc", "doc")
    assert r.returncode == 0, r.stderr[-2000:]
    text = (tmp_path / "doc" / "validation" / "report.md").read_text()
    row = next(line for line in text.splitlines() if line.startswith("| baseline"))
    assert "| 9.5, left wall |" in row and "| 80 / 11 / 7 |" in row and "0.04 / 0.04 (0.09)" in row
