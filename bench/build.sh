#!/bin/sh
# build.sh — build siconos_lcp (pound's LCP solvers paired against Siconos
# numerics' Lemke and PGS on the problems of `pound bench --lcp`):
#   bench/build.sh [BUILD]      (BUILD defaults to build; run from the repo root
#                                after `make all`, which makes BUILD/libpound.a)
# Exit status 3, with "siconos numerics not installed: skipped", when its
# headers are missing (apt-get install libsiconos-numerics-dev).
# SICONOS_PREFIX (default /usr) and CC may be set in the environment.
set -eu
here=$(dirname "$0")
out=${1:-build}
prefix=${SICONOS_PREFIX:-/usr}
inc=$prefix/include/siconos
if [ ! -f "$inc/numerics/LCP_Solvers.h" ]; then
    echo "siconos numerics not installed: skipped"
    exit 3
fi
version=$(dpkg-query -W -f='${Version}' libsiconos-numerics-dev 2>/dev/null || echo unknown)
${CC:-cc} -std=c11 -O2 -Wall -Wextra -Wshadow -Wpedantic -Werror \
    -I"$here/../lcp" -I"$here/../core" \
    -isystem "$inc/numerics" -isystem "$inc" \
    -DSICONOS_NUMERICS_VERSION="\"$version\"" \
    "$here/siconos_lcp.c" -o "$out/siconos_lcp" "$out/libpound.a" \
    -L"$prefix/lib/x86_64-linux-gnu" -L"$prefix/lib" -lsiconos_numerics -lm
echo "built $out/siconos_lcp (Siconos numerics $version)"
