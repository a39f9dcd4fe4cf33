#!/bin/sh
# python/check.sh — the Python package's check: build libpound.so and the
# pound CLI from the same sources (or take $POUND_LIBRARY and $POUND_BIN),
# install the package offline into a temporary venv, run its tests with
# Debian's Python.  Exits nonzero on any failure.
#
#   sh python/check.sh [pytest args...]
#
# Environment: POUND_LIBRARY (a built libpound.so: nothing is built),
# POUND_BIN (the CLI the tests compare with, default: the one built next to
# the library, else build/pound), PY_BUILD (build folder, default build-py),
# PYTHON (default /usr/bin/python3: NumPy, pytest, Matplotlib, pip).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
PYTHON=${PYTHON:-/usr/bin/python3}
PY_BUILD=${PY_BUILD:-build-py}
MAKE=${MAKE:-make}
jobs=$(nproc 2>/dev/null || echo 2)

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
