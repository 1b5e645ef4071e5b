import os
import sys

# Tests run against this checkout's package even if another checkout registered itself on sys.path.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "py"))

import pytest  # noqa: E402

# Markers by file (doc/developer/testing.md): `-m quick` is the daily subset (< 2 minutes on 2 cores); the README's
# test command runs everything. A file's tests carry its topic marker; `slow` marks the tests that take longest.
TOPICS = {
    "unit": ["test_analysis", "test_bad_input", "test_entrance_errors", "test_fields", "test_layout", "test_params",
             "test_rocks", "test_runner", "test_shape_functions", "test_contact_params", "test_hazards", "test_bench_kernel",
             "test_uncertainty", "test_threads"],
    "physics": ["test_boundaries", "test_contact", "test_contact_yade", "test_contact_corners", "test_contact_initial_d0",
                "test_contact_kinematic", "test_contact_matrix", "test_contact_stick", "test_courant", "test_damage_threshold",
                "test_determinism", "test_dpgk", "test_dpgk_damage", "test_failed_bulking", "test_elastic_dynamics", "test_multimaterial", "test_outside",
                "test_checkpoint", "test_hybrid", "test_yade_hook", "test_examples", "test_pic_dissipation"],
    "paper": ["test_bonded", "test_filled_flaw_fem", "test_case_results", "test_circular_opening", "test_fidelity", "test_penny_crack", "test_penny_prism",
              "test_report", "test_scripts_smoke", "test_slab3d", "test_stability", "test_studies", "test_tunnel", "test_tunnel_script"],
    "mpi": ["test_mpi", "test_mpi_checkpoint", "test_mpi_contact", "test_mpi_outside", "test_mpi_rebalance", "test_mpi_spheres", "test_mpi_distributed", "test_mpi_memory"],
}
SLOW = {"test_filled_flaw_fem", "test_contact_matrix", "test_studies", "test_contact_params", "test_scripts_smoke", "test_contact_kinematic",
        "test_contact_corners", "test_tunnel_script", "test_mpi_contact", "test_slab3d", "test_mpi_spheres", "test_circular_opening",
        "test_penny_prism", "test_examples"}
_TOPIC_OF = {f: t for t, files in TOPICS.items() for f in files}


def pytest_configure(config):
    for name, text in (("unit", "API, input checks and layout: no physics run longer than a few steps"),
                       ("physics", "the solver against analytic solutions, conservation laws and independent calculations"),
                       ("paper", "the paper's reference cases, their scripts and the validation report"),
                       ("mpi", "N MPI ranks against one process"), ("slow", "the longest files (about 85 % of the suite's time)"),
                       ("quick", "the daily subset: every file not marked slow")):
        config.addinivalue_line("markers", f"{name}: {text}")


def pytest_collection_modifyitems(config, items):
    for item in items:
        f = os.path.splitext(os.path.basename(str(item.fspath)))[0]
        topic = _TOPIC_OF.get(f)
        if topic is None:
            raise pytest.UsageError(f"{f}.py has no topic marker: add it to TOPICS in tests/conftest.py")
        item.add_marker(getattr(pytest.mark, topic))
        item.add_marker(pytest.mark.slow if f in SLOW else pytest.mark.quick)
