"""The README's example and every file under examples/ run as tests."""
import glob
import os
import re
import subprocess
import sys

from helpers import ROOT


def test_readme_example_is_examples_first_scene():
    readme = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    block = re.search(r"```python\n(.*?)```", readme, re.S).group(1)
    example = open(os.path.join(ROOT, "examples", "first_scene.py"), encoding="utf-8").read()
    missing = [line for line in block.splitlines() if line.strip() and line not in example.splitlines()
               and line != "O.run(2000, True)"]           # the file takes the step count from its command line
    assert not missing, missing


def test_first_scene_reaches_kirsch_at_the_crown(tmp_path):
    """2000 damped steps: the crown hoop stress within 5 % of Kirsch's 3σxx − σyy = −50 MPa (−48.6 on its 5 cm grid)."""
    r = subprocess.run([sys.executable, os.path.join(ROOT, "examples", "first_scene.py")], cwd=tmp_path, capture_output=True,
                       text=True, timeout=600, env=dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=os.path.join(ROOT, "py")))
    assert r.returncode == 0, r.stderr[-3000:]
    m = re.search(r"after (\d+) steps; crown hoop stress σxx = (-?[\d.]+) MPa \(Kirsch at the wall: (-?\d+) MPa\)", r.stdout)
    assert m, r.stdout[-2000:]
    steps, hoop, kirsch = int(m.group(1)), float(m.group(2)), float(m.group(3))
    assert steps == 2000 and kirsch == -50 and abs(hoop / kirsch - 1) < 0.05, m.group(0)
    assert (tmp_path / "out" / "first_scene" / "particles.vtu").stat().st_size > 100_000


def test_every_example_is_run_by_a_test():
    tests = "".join(open(p).read() for p in glob.glob(os.path.join(ROOT, "tests", "test_*.py")))
    for path in glob.glob(os.path.join(ROOT, "examples", "*.py")):
        name = os.path.basename(path)
        assert f'"{name}"' in tests or f"'{name}'" in tests, f"examples/{name} is run by no test"
