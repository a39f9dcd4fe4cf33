#!/bin/sh
# python/check.sh — the Python package's check: build libpound.so and the
# pound CLI from the same sources (or take $POUND_LIBRARY and $POUND_BIN),
# install the package offline into a temporary venv, run its tests with
# Debian's Python.  Exits nonzero on any failure.
#
#   sh python/check.sh [pytest args...]
#
# Before the build: python/pound/_structs.py (the ctypes mirrors of the
# public structs) must be what scripts/gen_py_structs.py generates from the
# headers.  After the tests: the types (mypy: the package, and
# tests/typing_usage.py with --strict against the install, which needs its
# py.typed) and the notebook examples/pound_tour.ipynb executed with
# nbconvert on a kernel of that install (at most $NB_TIMEOUT s, default 300;
# it takes 7 to 24 s).
#
# Environment: POUND_LIBRARY (a built libpound.so: nothing is built),
# POUND_BIN (the CLI the tests compare with, default: the one built next to
# the library, else build/pound), PY_BUILD (build folder, default build-py),
# PYTHON (default /usr/bin/python3: NumPy, pytest, Matplotlib, pip, mypy, cffi,
# nbconvert, ipykernel: scripts/deps.sh --python installs them).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
PYTHON=${PYTHON:-/usr/bin/python3}
PY_BUILD=${PY_BUILD:-build-py}
MAKE=${MAKE:-make}
jobs=$(nproc 2>/dev/null || echo 2)

# the mirrors against the headers (stale: the diff, and exit 1)
"$PYTHON" "$root/scripts/gen_py_structs.py" --check

if [ -z "${POUND_LIBRARY:-}" ]; then
    # the library and the CLI from one make run: the bit-identity tests need both
    # built from the same sources
    cd "$root"
    $MAKE --no-print-directory BUILD="$PY_BUILD" -j"$jobs" shared "$PY_BUILD/pound"
    POUND_LIBRARY="$root/$PY_BUILD/libpound.so"
    POUND_BIN=${POUND_BIN:-$root/$PY_BUILD/pound}
fi
POUND_BIN=${POUND_BIN:-$root/build/pound}
export POUND_LIBRARY POUND_BIN

tmp=$(mktemp -d "${TMPDIR:-/tmp}/pound-py.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
# The README's install, word for word, in a fresh venv (Debian's python3
# with NumPy, pytest, Matplotlib): the package bundles the library at
# install time (python/setup.py), so it imports with no POUND_LIBRARY.
(cd "$root" && env -u POUND_LIBRARY "$PYTHON" -m venv --system-site-packages "$tmp/V" &&
    env -u POUND_LIBRARY "$tmp/V/bin/python" -m pip install --no-build-isolation --no-index \
        ./python) >"$tmp/pip.log" 2>&1 ||
    { cat "$tmp/pip.log" >&2; exit 1; }
rm -rf "$here/build" "$here"/*.egg-info # what pip's in-tree build leaves
(cd "$tmp" && env -u POUND_LIBRARY "$tmp/V/bin/python" -c '
import os, pound
want = os.path.join(os.path.dirname(pound.__file__), "libpound.so")
assert pound.library_path == want, (pound.library_path, want)
print("pound", pound.version(), "imports with its bundled", pound.library_path)') ||
    { echo "python: the installed package does not find its bundled library" >&2; exit 1; }
# the tests, on that install, against the library and the CLI of one build
cd "$tmp" # not the source tree: the tests import the installed package
"$tmp/V/bin/python" -c 'import pound, sys; print("pound", pound.version(), "from",
    pound.__file__, "on", pound.library_path, file=sys.stderr)'
MPLBACKEND=Agg "$tmp/V/bin/python" -m pytest -q -p no:cacheprovider "$here/tests" "$@"

need() { # a module of the venv's Python, or a clear error
    "$tmp/V/bin/python" -c "import $1" 2>/dev/null ||
        { echo "python: $1 is not importable by $PYTHON: install $2" \
               "(sh scripts/deps.sh --python)" >&2; exit 1; }
}
# the types: the package's own code, then a user's code against the install
need mypy mypy
"$tmp/V/bin/python" -m mypy --config-file "$here/pyproject.toml" --cache-dir "$tmp/mypy" \
    "$here/pound"
"$tmp/V/bin/python" -m mypy --config-file "$here/pyproject.toml" --cache-dir "$tmp/mypy" \
    --strict "$here/tests/typing_usage.py"
# the notebook, on a kernel of the install (its own data and config folders: no
# kernel of the user's takes its place), outputs written to $tmp only
need nbconvert python3-nbconvert
need ipykernel python3-ipykernel
export JUPYTER_DATA_DIR="$tmp/jupyter" JUPYTER_CONFIG_DIR="$tmp/jupyter-config" \
    JUPYTER_RUNTIME_DIR="$tmp/jupyter-run" IPYTHONDIR="$tmp/ipython" PYDEVD_DISABLE_FILE_VALIDATION=1
"$tmp/V/bin/python" -m ipykernel install --prefix "$tmp/V" --name pound-check >/dev/null 2>&1
start=$(date +%s)
timeout "${NB_TIMEOUT:-300}" \
    "$tmp/V/bin/python" -m nbconvert --to notebook --execute \
    --ExecutePreprocessor.kernel_name=pound-check --ExecutePreprocessor.timeout=120 \
    --output-dir "$tmp" "$here/examples/pound_tour.ipynb" >"$tmp/nb.log" 2>&1 ||
    { cat "$tmp/nb.log" >&2; echo "python: examples/pound_tour.ipynb failed" >&2; exit 1; }
echo "python: examples/pound_tour.ipynb ran in $(($(date +%s) - start)) s"
