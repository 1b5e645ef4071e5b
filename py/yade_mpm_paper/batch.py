"""Parameter studies: every reference script as a yade-batch job (YADE's ``readParamsFromTable``
convention), shared with ``scripts/studies/sweep.py`` (the same table on a Dask cluster).

A table is YADE's (``yade.utils.TableParamReader``): the first non-comment line names the columns, each
further line is one run; values are Python literals (strings quoted, ``=`` repeats the line above); the
``description`` column names a run (YADE builds one from the values when it is absent); columns starting
with ``!`` are for yade-batch (``!THREADS``). Every other column is a command-line option of the script,
by its argparse name (``spacing``, ``end_time``, …: the option's declaration is the parameter's one
declaration, default and type included), plus ``out``, the study folder (default ``out/<table name>``).

Line L of TABLE runs in its own folder OUT/<description>/ (``line_dir``), given to the script as --out;
there it writes summary.csv (``write_summary``: one row per run, the run's parameters and results, no
wall times, so a line and a direct run with the same options give the same bytes), job.json (wall time,
host, status) and, when it fails, error.txt (the message). A line whose summary.csv exists is done.

In a script::

    a = batch.parse_args(ap, argv)   # the command line, or under yade-batch / sweep.py the table line
    ...
    batch.write_summary(a.out, rows)
    if __name__ == "__main__":
        batch.main(main)             # table line: error.txt + job.json; bad input: a one-line message
"""
import argparse
import ast
import json
import math
import os
import re
import socket
import sys
import time

SUMMARY = "summary.csv"
ERROR = "error.txt"
JOB = "job.json"


class BadParameter(ValueError):
    """An invalid option or table value (raised instead of argparse's exit under a table line)."""


def table_line():
    """(table path, line number) of the table line this process runs (env YADE_BATCH = 'TABLE:LINE',
    set by yade-batch and scripts/studies/sweep.py), or None for a direct run."""
    spec = os.environ.get("YADE_BATCH", "")
    if not spec:
        return None
    path, _, line = spec.rpartition(":")
    if not path or not line.isdigit():
        raise BadParameter(f"YADE_BATCH = {spec!r} must be TABLE:LINE")
    return path, int(line)


def read_table(path):
    """{line number: {column: raw text}} of a table (YADE's reader; 'description' always present)."""
    if not os.path.isfile(path):
        raise BadParameter(f"table {path!r}: no such file")
    from yade.utils import TableParamReader
    return TableParamReader(path).paramDict()


def _literal(text):
    """A table value as readParamsFromTable reads it (eval with the math module's names)."""
    return eval(text, dict(math.__dict__))       # noqa: S307  (YADE's convention: values are Python expressions)


def line_dir(path, line, raw=None):
    """The run folder of a table line: OUT/<description>, OUT = the line's `out` value or out/<table name>."""
    raw = raw if raw is not None else read_table(path)[line]
    out = _literal(raw["out"]) if "out" in raw else os.path.join("out", os.path.splitext(os.path.basename(path))[0])
    desc = re.sub(r"[^A-Za-z0-9_.=,+-]+", "_", raw["description"]).strip("._") or f"line{line}"
    return os.path.join(str(out), desc)


def lines(path):
    """[(line number, description, run folder)] of every run of a table, in file order."""
    tab = read_table(path)
    return [(ln, tab[ln]["description"], line_dir(path, ln, tab[ln])) for ln in sorted(tab)]


def _options(parser):
    """{dest: action} of the options a table may set (every option except help and --out)."""
    return {a.dest: a for a in parser._actions if a.option_strings and a.dest not in ("help", "out")}


def _argv(action, value):
    """Command-line words that give `action` the table value `value`."""
    if isinstance(action, (argparse._StoreTrueAction, argparse._StoreFalseAction)):
        want = isinstance(action, argparse._StoreTrueAction)
        if not isinstance(value, (bool, int)) or value not in (0, 1):
            raise BadParameter(f"{action.dest} = {value!r} must be True/False (or 1/0)")
        return [action.option_strings[0]] if bool(value) == want else []
    if isinstance(action, argparse._StoreConstAction) or action.nargs == 0:
        raise BadParameter(f"{action.dest}: a flag that a table cannot set")
    vals = list(value) if isinstance(value, (list, tuple)) else [value]
    return [action.option_strings[0]] + [repr(v) if isinstance(v, float) else str(v) for v in vals]


def parse_args(parser, argv=None):
    """The script's options: from `argv` for a direct run; under a table line (``table_line()``) from
    that line, read with ``yade.utils.readParamsFromTable`` (defaults: the parser's), turned into the
    same command-line words a direct run would give (so both go through the same checks) with
    --out = the line's folder; words in `argv` come after (override). Sets ``a.table`` = dict(table,
    line, description, params) or None."""
    tl = table_line()
    if tl is None:
        a = parser.parse_args(argv)
        a.table = None
        return a
    path, line = tl
    raw = read_table(path)
    if line not in raw:
        raise BadParameter(f"table {path!r} has no run on line {line} (runs on lines {sorted(raw)})")
    opts = _options(parser)
    cols = [c for c in raw[line] if c != "description" and not c.startswith("!")]
    bad = [c for c in cols if c not in opts and c != "out"]
    if bad:
        raise BadParameter(f"table {path}: column(s) {bad} are not options of {parser.prog}; allowed: out, {', '.join(sorted(opts))}")
    from yade import utils
    try:
        utils.readParamsFromTable(tableFileLine=f"{path}:{line}", noTableOk=False,
                                  out="", **{d: a.default for d, a in opts.items()})
    except (NameError, SyntaxError) as e:
        raise BadParameter(f"table {path} line {line}: a value is not a Python literal ({e}); quote strings") from e
    from yade.params import table as row
    words = []
    for c in cols:
        if c != "out":
            words += _argv(opts[c], getattr(row, c))
    words += ["--out", line_dir(path, line, raw[line])]
    a = parser.parse_args(words + list(argv or []))
    a.table = dict(table=path, line=line, description=raw[line]["description"],
                   params={c: getattr(row, c) for c in cols})
    return a


def _cell(v):
    if isinstance(v, float):
        return repr(v)                                # shortest round-trip text: the same bits back
    if v is None:
        return ""
    return str(v)


def write_summary(out_dir, rows):
    """OUT/summary.csv: one row per run (dicts with the same keys, in order), floats in their shortest
    exact text. Written to a temporary file and renamed: it exists only complete (it marks a line done)."""
    if not rows:
        raise ValueError("write_summary: no rows")
    keys = list(rows[0])
    os.makedirs(out_dir, exist_ok=True)
    import csv
    tmp = os.path.join(out_dir, SUMMARY + ".tmp")
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(keys)
        for r in rows:
            if list(r) != keys:
                raise ValueError(f"write_summary: row keys {list(r)} differ from the first row's {keys}")
            w.writerow([_cell(r[k]) for k in keys])
    os.replace(tmp, os.path.join(out_dir, SUMMARY))


def read_summary(out_dir):
    """Rows of OUT/summary.csv as dicts of text ({} list when absent)."""
    import csv
    p = os.path.join(out_dir, SUMMARY)
    if not os.path.exists(p):
        return []
    with open(p, newline="") as f:
        return list(csv.DictReader(f))


def _raise_bad(self, message):
    raise BadParameter(f"{self.prog}: {message}")


def main(fn):
    """Run a script's ``main`` (no arguments; it reads sys.argv). Direct run: a ValueError (bad input)
    is one line on stderr, exit status 2. Table line: the line's folder gets error.txt (the message)
    when it fails and job.json either way (status, wall time, host); exit status 1 on failure."""
    tl = table_line()
    if tl is None:
        try:
            return fn()
        except ValueError as e:
            print(f"{os.path.basename(sys.argv[0])}: error: {e}", file=sys.stderr)
            sys.exit(2)
    t0 = time.time()
    try:
        run = line_dir(*tl)
    except Exception as e:                           # unreadable table: nothing to write into
        print(f"error: {type(e).__name__}: {e}", file=sys.stderr)
        sys.exit(1)
    os.makedirs(run, exist_ok=True)
    for f in (ERROR, JOB):
        if os.path.exists(os.path.join(run, f)):
            os.remove(os.path.join(run, f))
    status, msg = "ok", None
    error = argparse.ArgumentParser.error
    argparse.ArgumentParser.error = _raise_bad      # argparse and the scripts' own checks raise, not exit
    try:
        fn()
    except SystemExit as e:
        if e.code not in (0, None):
            status, msg = "failed", f"exit status {e.code}"
    except BaseException as e:                       # noqa: B902  (recorded; the process exits with status 1)
        status, msg = ("interrupted" if isinstance(e, KeyboardInterrupt) else "failed"), f"{type(e).__name__}: {e}"
        if not isinstance(e, (ValueError, KeyboardInterrupt)):
            import traceback
            traceback.print_exc()
    finally:
        argparse.ArgumentParser.error = error
    if status == "ok" and not os.path.exists(os.path.join(run, SUMMARY)):
        status, msg = "failed", "the script ended without writing summary.csv (stopped before the end?)"
    with open(os.path.join(run, JOB), "w") as f:
        json.dump(dict(status=status, wall_time_s=round(time.time() - t0, 3), host=socket.gethostname(), pid=os.getpid(),
                       table=tl[0], line=tl[1], finished=time.strftime("%Y-%m-%dT%H:%M:%S")), f, indent=1)
    if msg:
        with open(os.path.join(run, ERROR), "w") as f:
            f.write(msg + "\n")
        print(f"[{run}] {status}: {msg}", file=sys.stderr, flush=True)
        sys.exit(1)


def literal(text):
    """A summary.csv cell back as a number when it is one (else the text; '' → None)."""
    if text == "":
        return None
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text
