"""scripts/report.py names folders relative to the repository: the generated doc/validation.md holds no
absolute path of the machine it was made on (also for output folders elsewhere)."""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ABSOLUTE = re.compile(r"(?<![\w.])/(?:work|home|tmp|root|mnt|srv|opt|var)/")   # /usr/bin/python3 in commands is fine


def test_generated_report_names_no_absolute_path(tmp_path):
    out = tmp_path / "elsewhere" / "out"
    out.mkdir(parents=True)
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "py"))
    r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "report.py"), "--root", str(out), "--doc", str(tmp_path / "doc"),
                        "--dir", f"penny_crack_damage={tmp_path / 'crack_runs' / 'c02'}"], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    text = (tmp_path / "doc" / "validation.md").read_text()
    assert str(tmp_path) not in text and not ABSOLUTE.search(text), ABSOLUTE.search(text)
    assert "…/elsewhere/out (outside the repository)" in text


def test_validation_md_has_no_absolute_path():
    text = open(os.path.join(ROOT, "doc", "validation.md")).read()
    hit = ABSOLUTE.search(text) or (os.path.dirname(ROOT) + "/" in text)
    assert not hit, hit
