#!/bin/sh
# figures.sh — the figures (convergence, work-precision, stability, energy)
# with the pound CLI and gnuplot, into OUT (default build/figures; `make
# figures DOCS=1` passes docs/figures, the tracked copies the docs show).
# Usage: scripts/figures.sh [path/to/pound [OUT]]   (run from the project root)
set -eu
pound=${1:-build/pound}
out=${2:-build/figures}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out"

# 1. Convergence and work-precision: Moreau-Jean (theta 1/2 and 1) and the
#    penalty baseline against the event-driven reference, two cases.
"$pound" converge --pulse sine --dir normal --Pi2 0.5 --Pi3 0.05 --eps 0.6 \
    --dt 0.004:0.0000625:7 --theta 0.5,1 --methods moreau,penalty \
    --kcs 1e2,1e3,1e4,1e5,1e6,1e7 --plot "$out/converge-sine-normal.png" \
    -o "$tmp/c1.csv" > "$out/converge-sine-normal.txt"
"$pound" converge --pulse cosine --dir reverse --Pi2 1.16 --Pi3 0.05 --eps 0.2 \
    --dt 0.004:0.0000625:7 --theta 0.5,1 --methods moreau,penalty \
    --kcs 1e2,1e3,1e4,1e5,1e6,1e7 --plot "$out/converge-cosine-reverse.png" \
    -o "$tmp/c2.csv" > "$out/converge-cosine-reverse.txt"

# 1b. Work-precision on rows of N = 2, 10, 100 SDOFs (--chain: periods 1 s
#     and 1.5 s alternating, walls at both ends) under a sine pulse against the
#     exact row reference (--method event): Moreau-Jean (theta 1/2 and 1),
#     both penalty methods (the adaptive GSL integration per stiffness --kcs,
#     and Newmark's fixed steps per dt with the elements at --kc 1e6), and the
#     GSL-based general reference (event-general) as one more point; the
#     reference's cost is the vertical line; the error of the peak response
#     (docs/methods.md).  N = 100: about two minutes (the general
#     reference's).
for N in 2 10 100; do
    "$pound" converge --chain "$N" --pulse sine --Tp 1 --T0 1 --Pi3 0.05 --eps 0.6 \
        --dt 0.004:0.00025:5 --theta 0.5,1 --methods moreau,penalty,newmark,event-general \
        --kcs 1e2,1e3,1e4,1e5,1e6 --kc 1e6 --error umax --plot "$out/rows-$N.png" \
        > "$out/rows-$N.txt"
done

# 1b'. Work-precision on a yielding row of 10 SDOFs (every SDOF elastic-
#     plastic with 5 % hardening, Piy 0.3, gaps 0.5 Le) against the exact row
#     reference with yield onsets and unloadings as events: Moreau-Jean and
#     Newmark with Newton (elements at --kc 1e6); docs/methods.md.
"$pound" converge --chain 10 --pulse sine --Tp 1 --T0 1 --Pi3 0.5 --Piy 0.3 --alpha 0.05 \
    --eps 0.6 --dt 0.004:0.0000625:4 --methods moreau,newmark --kc 1e6 --error umax \
    --plot "$out/rows-yield-10.png" > "$out/rows-yield-10.txt"

# 1c. Work-precision under a real record (Rinaldi RRS228, shipped in
#     examples/records): Moreau-Jean and penalty against the exact reference
#     on the record's linear pieces (docs/records.md).
rec=examples/records/NGA_no_1063_RRS228.AT2 # shipped with the repository
if [ -f "$rec" ]; then
    "$pound" converge --record "$rec" --T0 0.8 --gap 0.01 --eps 0.6 \
        --dt 0.004:0.0000625:7 --theta 0.5,1 --methods moreau,penalty \
        --kcs 1e2,1e3,1e4,1e5,1e6 --plot "$out/converge-record.png" > "$out/converge-record.txt"
fi

# 2. Where theta < 1/2 fails: amplitude after 200 s of a damped oscillator
#    (xi = 0.05, T0 = 1 s) against w0 h; a blown-up run is drawn at 1e30.
for th in 0.3 0.4 0.45 0.5; do
    for wh in 0.05 0.1 0.15 0.2 0.25 0.3 0.4 0.5 0.6 0.8 1.0 1.2 1.5 2.0 3.0; do
        dt=$(awk "BEGIN{printf \"%.12g\", $wh / 6.283185307179586}")
        u=$("$pound" simulate --no-wall --pulse sine --Tp 1 --T0 1 --xi 0.05 --theta "$th" \
              --allow-unstable --dt "$dt" --tend 200 --json 2>/dev/null |
            sed -n 's/.*"umax":\([^,]*\),.*/\1/p')
        [ -n "$u" ] || u=1e30
        awk "BEGIN{u=$u; if (u > 1e30) u = 1e30; print $wh, u}"
    done > "$tmp/stab-$th.dat"
done
gnuplot <<GP
set terminal pngcairo size 900,600 enhanced font 'sans,11'
load 'scripts/plot_style.gp'
set output '$out/stability-theta.png'
set logscale xy; set grid; set key top left; set format y '10^{%L}'
set title 'Moreau-Jean below {/Symbol q} = 1/2: max |u| over 200 s ({/Symbol x} = 0.05, no wall)'
set xlabel '{/Symbol w}_0 h'; set ylabel 'max |u| [m]'
set arrow from 0.25,graph 0 to 0.25,graph 1 nohead dt 3
set arrow from 0.5,graph 0 to 0.5,graph 1 nohead dt 3
set arrow from 1.0,graph 0 to 1.0,graph 1 nohead dt 3
set label 'predicted limits 2 {/Symbol x}/(1 - 2 {/Symbol q})' at 0.27,1e25
plot '$tmp/stab-0.3.dat' w lp lw 2 t '{/Symbol q} = 0.3', '$tmp/stab-0.4.dat' w lp lw 2 t '{/Symbol q} = 0.4', \
     '$tmp/stab-0.45.dat' w lp lw 2 t '{/Symbol q} = 0.45', '$tmp/stab-0.5.dat' w lp lw 2 t '{/Symbol q} = 0.5'
GP

# 3. eps = 1, theta = 1/2, no damping, 200 periods after a pulse: the energy
#    v^2/2 + w0^2 u^2/2 (w0 = 2 pi) stays put through hundreds of impacts.
"$pound" simulate --pulse sine --dir normal --Tp 1 --T0 1 --xi 0 --eps 1 --Pi3 0.05 \
    --dt 0.0005 --tend 200 --every 20 -o "$tmp/e1.csv" > /dev/null
"$pound" simulate --pulse sine --dir normal --Tp 1 --T0 1 --xi 0 --eps 0.8 --Pi3 0.05 \
    --dt 0.0005 --tend 200 --every 20 -o "$tmp/e08.csv" > /dev/null
for f in e1 e08; do
    grep -v '^#' "$tmp/$f.csv" | awk -F, 'NR > 1 && $1 > 1 {w = 6.283185307179586; print $1, 0.5*$3*$3 + 0.5*w*w*$2*$2}' > "$tmp/$f.dat"
done
gnuplot <<GP
set terminal pngcairo size 900,500 enhanced font 'sans,11'
load 'scripts/plot_style.gp'
set output '$out/energy-eps1.png'
set grid; set key center right; set logscale y; set format y '10^{%L}'
set title 'Energy after the pulse, {/Symbol q} = 1/2, {/Symbol x} = 0 (Moreau-Jean, dt = Tp/2000)'
set xlabel 't [s]'; set ylabel 'v^2/2 + {/Symbol w}_0^2 u^2/2 [m^2/s^2]'
plot '$tmp/e1.dat' w l lw 2 t '{/Symbol e} = 1 (kept)', '$tmp/e08.dat' w l lw 2 t '{/Symbol e} = 0.8 (falls at each impact)'
GP
echo "figures written to $out/"

# 4. Moreau-Jean (dt = min(Tp, T0)/2000) against the reference over the grid
#    of issue 4: error quantiles and the worst points (docs/methods.md).
for pulse in sine cosine; do for dir in normal reverse; do
  for Pi2 in 0.05 0.2 0.7 1.16 3 10; do for Pi3 in 0.001 0.05 1 10; do for eps in 0 0.5 0.9 1; do
    "$pound" compare --pulse $pulse --dir $dir --Tp 1 --Pi2 $Pi2 --Pi3 $Pi3 --eps $eps --json |
      sed -e 's/.*"err_umax_rel":\([^,]*\),"err_hist_linf":\([^,]*\),"impacts":\([^,]*\),"impacts_ref":\([^,]*\),"cpu_s":\([^,]*\),"cpu_s_ref":\([^,]*\),.*/\1 \2 \3 \4 \5 \6/' |
      awk -v c="$pulse $dir Pi2=$Pi2 Pi3=$Pi3 eps=$eps" '{print $0, c}'
  done; done; done
done; done > "$tmp/grid.dat"
{
  echo "Moreau-Jean (theta 1/2, dt = min(Tp,T0)/2000) vs the event-driven reference, $(wc -l < "$tmp/grid.dat") points"
  for col in 1 2 5 6; do
    name=$(echo "err_umax err_hist - - cpu_s_moreau cpu_s_ref" | cut -d' ' -f$col)
    sort -g -k$col,$col "$tmp/grid.dat" | awk -v c=$col -v n="$name" '{v[NR]=$c} END {printf "%-14s median %.3g  p90 %.3g  max %.3g\n", n, v[int((NR+1)/2)], v[int(0.9*NR)], v[NR]}'
  done
  echo "pounding points: $(awk '$4 > 0' "$tmp/grid.dat" | wc -l)"
  echo "worst umax:  $(sort -g -k1,1 "$tmp/grid.dat" | tail -1)"
  echo "worst hist:  $(sort -g -k2,2 "$tmp/grid.dat" | tail -1)"
} > "$out/grid-moreau.txt"
cat "$out/grid-moreau.txt"
