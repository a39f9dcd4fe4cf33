#!/bin/sh
# deps.sh — make sure the Debian packages pound needs are installed.
# As root, installs what is missing; otherwise prints the one apt-get line
# needed and fails.  Usage: scripts/deps.sh [--ci|--bench]   (--ci adds
# CI-only tools: python3, clang-format and ctags (make format-check, make
# house), OpenMPI for the MPI build `make MPI=1`, which the
# quick start does not need, and Siconos numerics, which bench/siconos_lcp
# is timed against, and the stress suite's clang, LLVM OpenMP and libFuzzer;
# --bench adds Siconos numerics alone; --stress the stress suite's tools;
# --python the Python package's: NumPy, pytest, Matplotlib, h5py, pip, mypy, cffi,
# nbconvert, ipykernel; and xarray with h5netcdf and netCDF-C's ncdump, which
# make formats-check opens every HDF5 file with)
set -u
pkgs="gcc make pkg-config libgsl-dev libsuitesparse-dev libhdf5-dev hdf5-tools libjansson-dev gnuplot-nox"
[ "${1:-}" = "--ci" ] && pkgs="$pkgs python3 libopenmpi-dev openmpi-bin libsiconos-numerics-dev clang-format universal-ctags"
stress="python3 python3-numpy python3-pytest clang libomp-dev libclang-rt-dev util-linux"
# the Python package's tests and the files read back with h5py (and xarray's
# h5netcdf, netCDF-C's ncdump); its type check (mypy), its notebook
# (nbconvert on an ipykernel: python/check.sh) and the check of its ctypes
# mirrors against the headers read by cffi
py="python3 python3-venv python3-numpy python3-pytest python3-matplotlib python3-h5py python3-pip python3-setuptools python3-wheel python3-pandas python3-xarray python3-h5netcdf netcdf-bin mypy python3-nbconvert python3-ipykernel python3-cffi"
[ "${1:-}" = "--ci" ] && pkgs="$pkgs $py groff-base g++"
[ "${1:-}" = "--python" ] && pkgs="$pkgs $py"
[ "${1:-}" = "--ci" ] && pkgs="$pkgs $stress"
[ "${1:-}" = "--stress" ] && pkgs="$pkgs $stress"
[ "${1:-}" = "--bench" ] && pkgs="$pkgs libsiconos-numerics-dev"
missing=""
for p in $pkgs; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
if [ "$(id -u)" = 0 ]; then
    echo "deps: installing$missing" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >&2 && apt-get install -y -qq --no-install-recommends $missing >&2 && exit 0
    echo "deps: apt-get failed" >&2
    exit 1
fi
echo "deps: missing packages; run:  sudo apt-get install -y$missing" >&2
exit 1
