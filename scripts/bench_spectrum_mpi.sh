#!/bin/sh
# bench_spectrum_mpi.sh — the MPI figure of `pound bench --spectrum`: the
# same paper-scale sweep (200 Pi2 in [0.05, 5] x 4 Pi3 x 2 pulses x 2
# directivities, eps = 0.5, xi = 0.05, Moreau-Jean dt = Tp/2000) by the plain
# build on one thread and by the MPI build on NP ranks x 1 thread, best of
# two runs each; wall_s is measured inside pound (after MPI_Init), the
# launch time of mpirun is printed beside it.  The two HDF5 files must be
# byte-identical.
#
# Usage (from the project root, after `make all` and `make MPI=1`):
#     sh scripts/bench_spectrum_mpi.sh [NP]        (NP = 2 by default)
set -eu
np=${1:-2}
serial=build/pound
mpi=build-mpi/pound
[ -x "$serial" ] || { echo "bench_spectrum_mpi: $serial missing (make all)" >&2; exit 1; }
[ -x "$mpi" ] || { echo "bench_spectrum_mpi: $mpi missing (make MPI=1)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
sweep="--Pi2 0.05:5:200 --Pi3 0.001,0.01,0.1,1 --pulse sine,cosine --dir normal,reverse"
sweep="$sweep --eps 0.5 --xi 0.05 --dt-per-Tp 2000 --threads 1 --json"
asroot=""
[ "$(id -u)" = 0 ] && asroot="--allow-run-as-root"

# key value of a one-line JSON file
field() { sed -n "s/.*\"$2\":\([0-9.eE+-]*\).*/\1/p" "$1"; }
now() { date +%s.%N; }

best_serial=1e30; best_mpi=1e30; best_outer=1e30
for k in 1 2; do
    rm -f "$tmp/serial.h5" "$tmp/mpi.h5"
    "$serial" spectrum $sweep -o "$tmp/serial.h5" > "$tmp/serial.json"
    t0=$(now)
    mpirun -np "$np" $asroot --oversubscribe "$mpi" spectrum $sweep -o "$tmp/mpi.h5" \
        > "$tmp/mpi.json"
    t1=$(now)
    best_serial=$(awk -v a="$best_serial" -v b="$(field "$tmp/serial.json" wall_s)" 'BEGIN{print (b<a)?b:a}')
    best_mpi=$(awk -v a="$best_mpi" -v b="$(field "$tmp/mpi.json" wall_s)" 'BEGIN{print (b<a)?b:a}')
    best_outer=$(awk -v a="$best_outer" -v b="$t1" -v c="$t0" 'BEGIN{d=b-c; print (d<a)?d:a}')
done
cmp -s "$tmp/serial.h5" "$tmp/mpi.h5" && same=yes || same=NO
steps=$(field "$tmp/serial.json" steps)
awk -v s="$best_serial" -v m="$best_mpi" -v o="$best_outer" -v n="$np" -v st="$steps" -v same="$same" 'BEGIN{
    printf "spectrum sweep, %d runs of the paper-scale benchmark, %.4g oscillator steps\n", 4000, st
    printf "  serial (1 thread)     %7.3f s  %10.4g steps/s\n", s, st / s
    printf "  MPI %d ranks x 1 thr   %7.3f s  %10.4g steps/s  speedup %.2f, efficiency %.0f %%\n", n, m, st / m, s / m, 100 * s / (n * m)
    printf "  (mpirun from launch to exit: %.3f s)\n", o
    printf "  serial and MPI files byte-identical: %s\n", same
}'
[ "$same" = yes ]
