"""Shared fixtures: the CLI to compare with (POUND_BIN, default ../build/pound
next to this package's source), the repository's examples, and a comparison
of a Python result with the CLI's JSON that demands equal doubles."""
import json
import math
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
RECORDS = Path(os.environ.get("POUND_RECORDS", "/work/shared/data/records"))
# timings differ from run to run; everything else must be equal to the bit
TIMING_KEYS = {"cpu_s", "cpu_s_ref", "cpu_s_run", "wall_s", "threads", "ranks", "resumed"}


def pound_bin():
    return Path(os.environ.get("POUND_BIN", REPO / "python" / ".." / "build" / "pound"))


@pytest.fixture(scope="session")
def cli():
    """cli(*args) -> the JSON that `pound args... --json` prints."""
    exe = pound_bin()
    if not os.access(exe, os.X_OK):
        pytest.skip("no pound binary at %s (set POUND_BIN)" % exe)

    def run(*args):
        out = subprocess.run([str(exe)] + [str(a) for a in args] + ["--json"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, check=False)
        assert out.returncode in (0, 1), out.stderr.decode()
        return json.loads(out.stdout)
    return run


def differences(py, js, path=""):
    """Where py (a pound.Result) and js (the CLI's JSON) differ: every key of
    js must be in py with an equal value (== on doubles; null is NaN)."""
    out = []
    if isinstance(js, dict):
        for k, v in js.items():
            if k in TIMING_KEYS:
                continue
            if k not in py:
                out.append("%s%s: missing" % (path, k))
            else:
                out += differences(py[k], v, "%s%s." % (path, k))
    elif isinstance(js, list):
        py = list(py)
        if len(py) != len(js):
            return ["%s: %d entries, the CLI %d" % (path, len(py), len(js))]
        for i, (a, b) in enumerate(zip(py, js)):
            out += differences(a, b, "%s%d." % (path, i))
    elif js is None:
        if not (isinstance(py, float) and math.isnan(py)):
            out.append("%s %r, the CLI null" % (path, py))
    elif isinstance(js, (int, float)) and not isinstance(js, bool):
        if not (py == js and type(py) is not str):
            out.append("%s %r, the CLI %r" % (path, py, js))
    elif py != js:
        out.append("%s %r, the CLI %r" % (path, py, js))
    return out


@pytest.fixture
def same():
    def check(py, js):
        d = differences(py, js)
        assert not d, "differs from the CLI: " + "; ".join(d[:10])
    return check


def read_csv(path):
    """A CSV of the CLI's -o: its header and the columns (comments skipped)."""
    import numpy as np
    with open(path) as f:
        lines = [ln for ln in f if not ln.startswith("#")]
    header = lines[0].strip().split(",")
    data = np.loadtxt(lines[1:], delimiter=",", ndmin=2)
    return header, data
