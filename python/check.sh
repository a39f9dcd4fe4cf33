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
# a venv that sees Debian's NumPy, pytest and Matplotlib; the package installed offline
"$PYTHON" -m venv --system-site-packages --without-pip "$tmp/venv"
# from a copy: pip builds in the tree it is given (build/, *.egg-info)
mkdir "$tmp/src"
cp -R "$here/pyproject.toml" "$here/README.md" "$here/pound" "$tmp/src/"
"$tmp/venv/bin/python" -m pip install --quiet --no-build-isolation --no-index --no-deps \
    --disable-pip-version-check "$tmp/src" >"$tmp/pip.log" 2>&1 ||
    { cat "$tmp/pip.log" >&2; exit 1; }
cd "$tmp" # not the source tree: the tests import the installed package
"$tmp/venv/bin/python" -c 'import pound, sys; print("pound", pound.version(), "from",
    pound.__file__, "on", pound.library_path, file=sys.stderr)'
MPLBACKEND=Agg "$tmp/venv/bin/python" -m pytest -q -p no:cacheprovider "$here/tests" "$@"
