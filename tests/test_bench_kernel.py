"""scripts/tools/bench_kernel.py's all-float variant of the ceiling kernel (issue 19's single-precision bound)."""
import os
import re
import shutil
import subprocess
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts", "tools"))
import bench_kernel  # noqa: E402

SNIPPET = """typedef double v4d __attribute__((vector_size(32)));
static inline v4d splat(double a) { return (v4d){a, a, a, a}; }
    double t_p2g = 0, t_grid = 0;
        double t0 = omp_get_wtime();
    double w = 0.5 * t3 - t2 + 2.0 / 3.0, e = 1e-4, k = 2.5e+3, n = 3;
    dc = std::min(dc, 1.0);
    printf("wall=%.3fs %.4e\\n", x, y);
"""


def test_float_source_converts_values_vectors_and_literals_but_not_timers():
    s = bench_kernel.float_source(SNIPPET)
    assert "typedef float v4d __attribute__((vector_size(16)));" in s      # 4 lanes of float
    assert "double t_p2g = 0, t_grid = 0;" in s and "double t0 = omp_get_wtime();" in s
    assert "float w = 0.5f * t3 - t2 + 2.0f / 3.0f, e = 1e-4f, k = 2.5e+3f, n = 3;" in s
    assert "std::min(dc, 1.0f)" in s
    assert 'printf("wall=%.3fs %.4e\\n", x, y);' in s                      # format strings untouched
    assert not re.search(r"\bdouble\b", s.replace("double t_p2g", "").replace("double t0", ""))


@pytest.mark.skipif(not os.path.exists(bench_kernel.SOURCE) or not shutil.which("g++"), reason="ceiling kernel source or g++ absent")
def test_float_kernel_builds_and_runs_the_block(tmp_path):
    exe = bench_kernel.build_kernel(bench_kernel.SOURCE, str(tmp_path), "float")
    out = subprocess.run([exe, "--dim", "2", "--bx", "20", "--by", "10", "--mat", "elastic", "--steps", "20", "--warmup", "2"],
                         env=dict(os.environ, OMP_NUM_THREADS="1"), capture_output=True, text=True, check=True).stdout
    assert "finite=1" in out and re.search(r"CPU [\d.]+", out)
