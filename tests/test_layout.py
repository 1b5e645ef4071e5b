"""The project's layout, checked from the files (doc/developer/testing.md, doc/reference/architecture.md): two houses (the user package
`yade_mpm`, the paper's reproduction `yade_mpm_paper`), no import circle, a small public namespace listed in the
guide, docs without issue numbers or commit hashes in the guide and reference, short source files."""
import ast
import glob
import os
import re

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PY = os.path.join(ROOT, "py")
MAX_LINES = 400            # every Python and C++ source file
MAX_SCRIPT_FUNCTION = 80   # every function of a script


def _modules():
    mods = {}
    for pkg in ("yade_mpm", "yade_mpm_paper"):
        for path in glob.glob(os.path.join(PY, pkg, "**", "*.py"), recursive=True):
            rel = os.path.relpath(path, PY)[:-3].replace(os.sep, ".")
            mods[rel[:-len(".__init__")] if rel.endswith(".__init__") else rel] = path
    return mods


def _imports(mods):
    """module -> the package modules it imports (module level or inside functions: a lazy import is still an edge)."""
    graph = {}
    for m, path in mods.items():
        is_pkg = path.endswith("__init__.py")
        edges = set()
        for n in ast.walk(ast.parse(open(path).read())):
            if isinstance(n, ast.Import):
                names = [a.name for a in n.names]
            elif isinstance(n, ast.ImportFrom):
                base = n.module or ""
                if n.level:
                    parts = m.split(".") if is_pkg else m.split(".")[:-1]
                    parts = parts[:len(parts) - n.level + 1]
                    base = ".".join(parts + ([n.module] if n.module else []))
                names = [base] + [f"{base}.{a.name}" for a in n.names]
            else:
                continue
            edges |= {x for x in names if x in mods and x != m}
        graph[m] = edges
    return graph


def test_no_import_circle_and_the_user_package_never_imports_the_papers():
    graph = _imports(_modules())
    into_paper = sorted((m, r) for m, rs in graph.items() if m.split(".")[0] == "yade_mpm" for r in rs
                        if r.split(".")[0] == "yade_mpm_paper")
    assert not into_paper, into_paper

    def parents(m):
        p = m.split(".")
        return {".".join(p[:i]) for i in range(1, len(p))}

    # a package importing its own children and a child naming its package (`from . import x`) are not circles
    state, cycles = {}, []

    def visit(v, path):
        state[v] = 1
        for w in sorted(graph[v] - parents(v)):
            if state.get(w) == 1:
                cycles.append(path[path.index(w):] + [w])
            elif w not in state:
                visit(w, path + [w])
        state[v] = 2

    for v in sorted(graph):
        if v not in state:
            visit(v, [v])
    assert not cycles, cycles


def test_public_names_at_most_30_and_each_in_the_guide():
    import yade_mpm as ym
    assert len(ym.__all__) <= 30, len(ym.__all__)
    assert all(hasattr(ym, n) for n in ym.__all__)
    api = open(os.path.join(ROOT, "doc", "guide", "api.md")).read()
    missing = [n for n in ym.__all__ if not re.search(rf"`(ym\.|yade_mpm\.)?{n}\b", api)]
    assert not missing, f"public names without their line in doc/guide/api.md: {missing}"


def test_guide_and_reference_name_no_issue_or_commit_and_no_doc_is_named_after_a_commit():
    bad = []
    for path in glob.glob(os.path.join(ROOT, "doc", "guide", "*.md")) + glob.glob(os.path.join(ROOT, "doc", "reference", "*.md")) \
            + [os.path.join(ROOT, "doc", "README.md")]:
        for k, line in enumerate(open(path), 1):
            if re.search(r"\b[Ii]ssues? ?#?\d+|(?<![\w&])#\d+\b|\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}\b", line):
                bad.append(f"{os.path.relpath(path, ROOT)}:{k}: {line.strip()[:100]}")
    assert not bad, "\n".join(bad)
    named = [p for p in glob.glob(os.path.join(ROOT, "doc", "**", "*"), recursive=True)
             if re.search(r"_(?=[0-9a-f]*\d)[0-9a-f]{7,40}\.", os.path.basename(p))]
    assert not named, named


def _sources():
    for pattern in ("py/**/*.py", "scripts/**/*.py", "examples/**/*.py", "tests/**/*.py", "pkg-mpm/**/*.hpp",
                    "pkg-mpm/**/*.cpp", "tests/cpp/*.cpp", "tests/cpp/*.hpp"):
        yield from glob.glob(os.path.join(ROOT, pattern), recursive=True)


def test_every_source_file_is_shorter_than_400_lines():
    long = {os.path.relpath(p, ROOT): n for p in _sources() if (n := sum(1 for _ in open(p))) >= MAX_LINES}
    assert not long, long


def test_no_script_function_longer_than_80_lines():
    long = []
    for path in glob.glob(os.path.join(ROOT, "scripts", "**", "*.py"), recursive=True) + glob.glob(os.path.join(ROOT, "examples", "*.py")):
        for n in ast.walk(ast.parse(open(path).read())):
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and n.end_lineno - n.lineno + 1 > MAX_SCRIPT_FUNCTION:
                long.append(f"{os.path.relpath(path, ROOT)}:{n.lineno} {n.name}() {n.end_lineno - n.lineno + 1} lines")
    assert not long, "\n".join(long)


def test_no_contact_header_includes_an_mpi_header():
    bad = []
    for path in glob.glob(os.path.join(ROOT, "pkg-mpm", "contact", "*")):
        for k, line in enumerate(open(path), 1):
            if re.search(r'#\s*include\s*[<"](mpi\.h|mpi/|Mpi|ContactMpi|HaloExchange|Decomposition)', line) or "MPI_" in line:
                bad.append(f"{os.path.relpath(path, ROOT)}:{k}: {line.strip()}")
    assert not bad, "\n".join(bad)


def _documented_solver_members():
    api = open(os.path.join(ROOT, "doc", "guide", "api.md")).read()
    section = api.split("## The solver's members", 1)[1].split("\n## ", 1)[0]
    return [m.group(1) for m in re.finditer(r"^\| `(\w+)", section, re.M)]


def test_solver_public_members_are_the_documented_list():
    """One obvious way: the solver's public members (no leading underscore) are exactly the documented table of
    doc/guide/api.md, one line each; the rest is the adapters' plumbing (leading underscore)."""
    import yade_mpm as ym
    doc = _documented_solver_members()
    assert len(doc) == len(set(doc)), sorted(n for n in doc if doc.count(n) > 1)
    mpi_only = {"mpiInfo"}
    for cls in (ym.Solver2D, ym.Solver3D):
        public = {n for n in dir(cls) if not n.startswith("_")}
        assert public - set(doc) == set(), f"{cls.__name__}: public members without their line in doc/guide/api.md"
        assert set(doc) - public - mpi_only == set(), f"{cls.__name__}: documented members that do not exist"
        assert "step" not in public and "advance" not in public
    assert len(doc) <= 36, len(doc)


def test_compiled_modules_live_in_the_build_folder_out_of_the_source_tree():
    from yade_mpm import _build
    import yade_mpm as ym
    assert os.path.dirname(os.path.abspath(ym._core.__file__)) == _build.module_dir()
    assert not glob.glob(os.path.join(PY, "yade_mpm", "_core*.so")), "a stale module in the package folder (run ./setup.sh)"


def test_build_folder_override_and_a_clear_error_without_a_build(tmp_path):
    import subprocess
    import sys
    from yade_mpm import _build
    code = "import yade_mpm, os; print(os.path.dirname(yade_mpm._core.__file__))"
    base = dict(os.environ, PYTHONPATH=PY, OMP_NUM_THREADS="1")
    ok = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                        env=dict(base, YADE_MPM_BUILD_DIR=_build.build_dir()))
    assert ok.returncode == 0 and ok.stdout.strip() == _build.module_dir(), ok.stderr
    bad = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                         env=dict(base, YADE_MPM_BUILD_DIR=str(tmp_path)))
    assert bad.returncode != 0
    assert "ImportError" in bad.stderr and "YADE_MPM_BUILD_DIR" in bad.stderr and str(tmp_path) in bad.stderr, bad.stderr
