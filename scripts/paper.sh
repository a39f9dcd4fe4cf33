#!/bin/sh
# paper.sh — the source paper's figures (Dimitrakopoulos, Makris & Kappos
# 2010), regenerated with pound into OUT/paper-*.png, plus the numbers
# docs/paper.md quotes (OUT/paper-*.txt).  OUT: build/figures by default;
# `make paper DOCS=1` passes docs/figures, the tracked copies the docs show.
# Usage: scripts/paper.sh [path/to/pound [OUT]]   (run from the project root)
set -eu
pound=${1:-build/pound}
out=${2:-build/figures}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out"
term="set terminal pngcairo size 1100,800 enhanced font 'sans,10'
load 'scripts/plot_style.gp'"

# A history as "t u v impulse" rows (CSV of pound simulate, comments dropped):
# the impulse is nonzero at the samples that end an impact (the charts mark them).
hist() { # file args...
    f=$1; shift
    "$pound" simulate "$@" -o "$tmp/h.csv" > /dev/null
    grep -v '^#' "$tmp/h.csv" | awk -F, 'NR > 1 {print $1, $2, $3, $4}' > "$f"
}

# Rows of a spectrum CSV matching pulse, dir and a numeric column test.
rows() { # csv pulse dir awk-condition columns...
    csv=$1 p=$2 d=$3 cond=$4
    grep -v '^#' "$csv" | awk -F, -v p="$p" -v d="$d" "NR > 1 && \$1 == p && \$2 == d && ($cond) {print \$10, \$12, \$15, \$16, \$11, \$13}"
}

# ---- Fig. 3: two oscillators, one dimensionless history ----------------
# T0 = 0.5 s and 1.5 s, xi = 5 %, one-cosine pulses with Pi2 = 0.6, Pi3 = 0.2.
hist "$tmp/f3a" --pulse cosine --ap 3 --Tp 0.3 --T0 0.5 --Pi3 0.2 --eps 0.7 --dt 0.00015
hist "$tmp/f3b" --pulse cosine --ap 5 --Tp 0.9 --T0 1.5 --Pi3 0.2 --eps 0.7 --dt 0.00045
gnuplot <<GP
$term
set output '$out/paper-fig3.png'
set multiplot layout 2,2 title 'Fig. 3: T_0 = 0.5 s (a_p = 3 m/s^2, T_p = 0.3 s) and T_0 = 1.5 s (a_p = 5 m/s^2, T_p = 0.9 s), {/Symbol P}_2 = 0.6, {/Symbol P}_3 = 0.2, {/Symbol e} = 0.7'
set grid
set xlabel 't [s]'; set ylabel 'u [cm]'
plot '$tmp/f3a' u 1:(100*\$2) w l lw 2 t 'T_0 = 0.5 s', '$tmp/f3b' u 1:(100*\$2) w l lw 2 t 'T_0 = 1.5 s', \
     '$tmp/f3a' u 1:(\$4 != 0 ? 100*\$2 : 1/0) w p pt 7 ps 0.6 lc rgb 'black' t 'impacts', \
     '$tmp/f3b' u 1:(\$4 != 0 ? 100*\$2 : 1/0) w p pt 7 ps 0.6 lc rgb 'black' t ''
set ylabel 'du/dt [m/s]'
plot '$tmp/f3a' u 1:3 w l lw 2 t 'T_0 = 0.5 s', '$tmp/f3b' u 1:3 w l lw 2 t 'T_0 = 1.5 s'
set xlabel 't / T_p'; set ylabel 'u {/Symbol w}_p^2 / a_p'
wa = 2*pi/0.3; wb = 2*pi/0.9
plot '$tmp/f3a' u (\$1/0.3):(\$2*wa*wa/3) w l lw 4 t 'T_0 = 0.5 s', '$tmp/f3b' u (\$1/0.9):(\$2*wb*wb/5) w l lw 2 dt 2 t 'T_0 = 1.5 s'
set ylabel '(du/dt) {/Symbol w}_p / a_p'
plot '$tmp/f3a' u (\$1/0.3):(\$3*wa/3) w l lw 4 t 'T_0 = 0.5 s', '$tmp/f3b' u (\$1/0.9):(\$3*wb/5) w l lw 2 dt 2 t 'T_0 = 1.5 s'
unset multiplot
GP

# ---- Fig. 4: dimensional spectra collapse in Pi terms -------------------
"$pound" spectrum --method moreau --pulse cosine --dir normal --Tp 0.5 --ap 1,3,9 --Pi3 0.05,0.5 \
    --Pi2 0.05:5:100 --eps 0.5 --method event -o "$tmp/f4.csv" --plot "$tmp/f4.png" > "$out/paper-fig4.txt"
cp "$tmp/f4-dim.png" "$out/paper-fig4-dimensional.png"
cp "$tmp/f4.png" "$out/paper-fig4-collapse.png"

# ---- Figs. 5, 6: sine and cosine spectra, normal and reverse, several Pi3,
#      with the traditional gamma-vs-chi view -------------------------------
for pulse in sine cosine; do
    n=5; [ $pulse = cosine ] && n=6
    "$pound" spectrum --method moreau --pulse $pulse --dir normal,reverse --Pi3 0.01,0.1,0.5,1,2 --eps 0.5 \
        --Pi2 0.05:5:120 --method event -o "$tmp/f$n.csv" > "$out/paper-fig$n.txt"
    for d in normal reverse; do for P in 0.01 0.1 0.5 1 2; do
        rows "$tmp/f$n.csv" $pulse $d "\$6 == $P" > "$tmp/f$n-$d-$P"
    done; done
    gnuplot <<GP
$term
set output '$out/paper-fig$n.png'
set multiplot layout 2,2 title 'Fig. $n: one-$pulse pulse, {/Symbol e} = 0.5, {/Symbol x} = 0.05 (event-driven reference)'
set grid; set logscale xy; set key bottom left
set xlabel '{/Symbol P}_2 = T_p / T_0'; set ylabel '{/Symbol P}_1 = u_{max} {/Symbol w}_p^2 / a_p'
do for [d in 'normal reverse'] {
  set title d
  plot for [P in '0.01 0.1 0.5 1 2'] '$tmp/f$n-'.d.'-'.P u 1:2 w l lw 2 t '{/Symbol P}_3 = '.P
}
unset logscale y; set key top right
# gamma from 0, a margin above its largest (the reverse pulse's is 1: on the frame before)
set yrange [0:*]; set offsets 0, 0, graph 0.08, 0
set xlabel '{/Symbol c} = gap / u_{max,free}'; set ylabel '{/Symbol g} = u_{max} / u_{max,free}'
do for [d in 'normal reverse'] {
  set title d.' (traditional view)'
  plot for [P in '0.01 0.1 0.5 1 2'] '$tmp/f$n-'.d.'-'.P u 4:3 w p pt 7 ps 0.5 t '{/Symbol P}_3 = '.P
}
unset multiplot
GP
done

# ---- Beyond the paper: Fig. 5 for a yielding oscillator (issue 30) -------
# Piy = uy wp^2 / ap = 0.5, alpha = 0.05: the Pi1 spectra and the ductility
# umax / uy (the exact reference: xi^2 < alpha, its sliding phase underdamped).
"$pound" spectrum --pulse sine --dir normal,reverse --Pi3 0.01,0.1,0.5,1,2 --eps 0.5 --Piy 0.5 \
    --alpha 0.05 --Pi2 0.05:5:120 -o "$tmp/fy.csv" > "$out/paper-fig5-yielding.txt"
for d in normal reverse; do for P in 0.01 0.1 0.5 1 2; do
    grep -v '^#' "$tmp/fy.csv" | awk -F, -v d=$d -v P=$P 'NR > 1 && $2 == d && $6 == P {print $10, $12, $25, $26, $27}' > "$tmp/fy-$d-$P"
done; done
gnuplot <<GP
$term
set output '$out/paper-fig5-yielding.png'
set multiplot layout 2,2 title 'Fig. 5, yielding: one-sine pulse, {/Symbol P}_y = u_y {/Symbol w}_p^2 / a_p = 0.5, {/Symbol a} = 0.05, {/Symbol e} = 0.5, {/Symbol x} = 0.05 (event-driven reference)'
set grid; set logscale xy; set key bottom left
set xlabel '{/Symbol P}_2 = T_p / T_0'
do for [d in 'normal reverse'] {
  set title d; set ylabel '{/Symbol P}_1 = u_{max} {/Symbol w}_p^2 / a_p'
  plot for [P in '0.01 0.1 0.5 1 2'] '$tmp/fy-'.d.'-'.P u 1:2 w l lw 2 t '{/Symbol P}_3 = '.P
}
set key top right
do for [d in 'normal reverse'] {
  set title d.': ductility'; set ylabel '{/Symbol m} = u_{max} / u_y'
  plot for [P in '0.01 0.1 0.5 1 2'] '$tmp/fy-'.d.'-'.P u 1:3 w l lw 2 t '{/Symbol P}_3 = '.P, \
       '$tmp/fy-'.d.'-2' u 1:4 w l lw 1 dt 2 lc rgb 'black' t 'no wall'
}
unset multiplot
GP

# ---- Fig. 8: time histories in the three spectral regions ---------------
for P2 in 0.2 1 3; do
    hist "$tmp/f8-$P2" --pulse sine --dir normal --Tp 1 --Pi2 $P2 --Pi3 0.05 --eps 0.5 --method event --dt 0.001
    hist "$tmp/f8f-$P2" --pulse sine --dir normal --Tp 1 --Pi2 $P2 --Pi3 0.05 --eps 0.5 --method event --dt 0.001 --no-wall
done
gnuplot <<GP
$term
set output '$out/paper-fig8.png'
set multiplot layout 3,1 title 'Fig. 8: normal sine pulse (a_p = 1 m/s^2, T_p = 1 s), {/Symbol P}_3 = 0.05, {/Symbol e} = 0.5'
set grid; set ylabel 'u / L_e'; set xlabel 't / T_p'
L = 1/(2*pi)**2
do for [P in '0.2 1 3'] {
  set title '{/Symbol P}_2 = '.P
  plot '$tmp/f8-'.P u 1:(\$2/L) w l lw 2 t 'with the wall', '$tmp/f8f-'.P u 1:(\$2/L) w l lw 1 dt 2 t 'without', 0.05 w l dt 2 lc rgb 'black' t 'wall', \
       '$tmp/f8-'.P u 1:(\$4 != 0 ? \$2/L : 1/0) w p pt 7 ps 0.6 lc rgb 'black' t 'impacts'
}
unset multiplot
GP

# ---- Fig. 9: T0 = 3 s, Tp = 0.3 s, gap 4 mm, normal vs reverse ----------
for d in normal reverse; do
    hist "$tmp/f9-$d" --pulse sine --dir $d --Tp 0.3 --T0 3 --ap 4 --gap 0.004 --eps 0.6 --method event --dt 0.001
    "$pound" simulate --pulse sine --dir $d --Tp 0.3 --T0 3 --ap 4 --gap 0.004 --eps 0.6 --method event > "$tmp/f9-$d.txt"
done
cat "$tmp/f9-normal.txt" "$tmp/f9-reverse.txt" > "$out/paper-fig9.txt"
gnuplot <<GP
$term
set output '$out/paper-fig9.png'
set multiplot layout 2,1 title 'Fig. 9: T_0 = 3 s, one-sine pulse T_p = 0.3 s, a_p = 4 m/s^2, gap 4 mm, {/Symbol e} = 0.6'
set grid; set xlabel 't [s]'; set ylabel 'u [cm]'
set title 'normal'; plot '$tmp/f9-normal' u 1:(100*\$2) w l lw 2 t '', 0.4 w l dt 2 lc rgb 'black' t 'wall', \
    '$tmp/f9-normal' u 1:(\$4 != 0 ? 100*\$2 : 1/0) w p pt 7 ps 0.6 lc rgb 'black' t 'impacts'
set title 'reverse'; plot '$tmp/f9-reverse' u 1:(100*\$2) w l lw 2 t '', 0.4 w l dt 2 lc rgb 'black' t 'wall', \
    '$tmp/f9-reverse' u 1:(\$4 != 0 ? 100*\$2 : 1/0) w p pt 7 ps 0.6 lc rgb 'black' t 'impacts'
unset multiplot
GP

# ---- Fig. 10: eps across [0, 1] ------------------------------------------
"$pound" spectrum --method moreau --pulse sine,cosine --dir normal,reverse --Pi3 0.05 --eps 0,0.25,0.5,0.75,1 \
    --Pi2 0.05:5:120 --method event -o "$tmp/f10.csv" > "$out/paper-fig10.txt"
for p in sine cosine; do for d in normal reverse; do for e in 0 0.25 0.5 0.75 1; do
    rows "$tmp/f10.csv" $p $d "\$8 == $e" > "$tmp/f10-$p-$d-$e"
done; done; done
gnuplot <<GP
$term
set output '$out/paper-fig10.png'
set multiplot layout 2,2 title 'Fig. 10: {/Symbol P}_3 = 0.05, {/Symbol x} = 0.05, eps from 0 to 1'
set grid; set logscale x; set key top right  # linear Pi1: on log axes the eps curves overlapped
set xlabel '{/Symbol P}_2'; set ylabel '{/Symbol P}_1'
do for [p in 'sine cosine'] { do for [d in 'normal reverse'] {
  set title p.', '.d
  plot for [e in '0 0.25 0.5 0.75 1'] '$tmp/f10-'.p.'-'.d.'-'.e u 1:2 w l lw 2 t '{/Symbol e} = '.e
} }
unset multiplot
GP

# ---- Fig. 11: Pi2 = 1.16, one-cosine reverse, eps = 0.2 vs 1.0 -----------
for P3 in 0.3 0.05; do for e in 0.2 1; do
    hist "$tmp/f11-$P3-$e" --pulse cosine --dir reverse --Tp 1 --Pi2 1.16 --Pi3 $P3 --eps $e --method event --dt 0.001
done; done
gnuplot <<GP
$term
set output '$out/paper-fig11.png'
set multiplot layout 2,2 title 'Fig. 11: {/Symbol P}_2 = 1.16, one-cosine reverse pulse (T_p = 1 s): {/Symbol e} = 0.2 against {/Symbol e} = 1'
set grid; set xlabel 't / T_p'; set key below
L = 1/(2*pi)**2; V = 1/(2*pi)
do for [P in '0.3 0.05'] {
  set title '{/Symbol P}_3 = '.P; set ylabel 'u / L_e'
  plot '$tmp/f11-'.P.'-0.2' u 1:(\$2/L) w l lw 2 t '{/Symbol e} = 0.2', '$tmp/f11-'.P.'-1' u 1:(\$2/L) w l lw 2 t '{/Symbol e} = 1', P+0 w l dt 2 lc rgb 'black' t 'wall', \
       '$tmp/f11-'.P.'-0.2' u 1:(\$4 != 0 ? \$2/L : 1/0) w p pt 7 ps 0.6 lc rgb 'black' t 'impacts', \
       '$tmp/f11-'.P.'-1' u 1:(\$4 != 0 ? \$2/L : 1/0) w p pt 7 ps 0.6 lc rgb 'black' t ''
}
do for [P in '0.3 0.05'] {
  set title '{/Symbol P}_3 = '.P; set ylabel '(du/dt) / (a_p / {/Symbol w}_p)'
  plot '$tmp/f11-'.P.'-0.2' u 1:(\$3/V) w l lw 2 t '{/Symbol e} = 0.2', '$tmp/f11-'.P.'-1' u 1:(\$3/V) w l lw 2 t '{/Symbol e} = 1'
}
unset multiplot
GP

# ---- Fig. 12: harmonic steady state, Pi3 = 0.001, subharmonic peaks -------
"$pound" spectrum --method moreau --pulse harmonic --dir normal --Pi3 0.001 --eps 0.3,0.6,0.9 \
    --Pi2 0.1:1.25:200 --method event -o "$tmp/f12.csv" > "$out/paper-fig12.txt"
for e in 0.3 0.6 0.9; do rows "$tmp/f12.csv" harmonic normal "\$8 == $e" > "$tmp/f12-$e"; done
gnuplot <<GP
$term
set output '$out/paper-fig12.png'
set title 'Fig. 12: harmonic excitation, steady state, {/Symbol P}_3 = 0.001, {/Symbol x} = 0.05'
set grid; set logscale y; set key top left
set xlabel '1/{/Symbol P}_2 = T_0 / T_p'; set ylabel '{/Symbol P}_1 (steady state)'
set xtics 1
plot for [e in '0.3 0.6 0.9'] '$tmp/f12-'.e u (1/\$1):2 w l lw 2 t '{/Symbol e} = '.e
GP
# the largest Pi1 within 0.7 of 1/Pi2 = 2, 4, 6, 8 (the subharmonic peaks)
for e in 0.3 0.6 0.9; do
    awk -v e=$e '{x[NR] = 1/$1; y[NR] = $2} END {printf "eps %s: peaks of Pi1 near 1/Pi2 = 2,4,6,8 at", e;
        for (k = 2; k <= 8; k += 2) {b = 0; for (i = 1; i <= NR; i++) if (x[i] > k - 0.7 && x[i] < k + 0.7 && y[i] > b) {b = y[i]; bx = x[i]}
            printf " %.2f (Pi1 %.3g)", bx, b} print ""}' "$tmp/f12-$e"
done >> "$out/paper-fig12.txt"

# ---- Records (issue 10): Fig. 2, Fig. 7 and the collapse of record spectra --
# The shared records when present (the paper's pulse-like set); else the
# records the repository ships: Rinaldi, the CDMG record and the seven
# stochastic near-fault records of examples/records/suite (said on stderr).
recs=../shared/data/records
if [ -d "$recs" ]; then
    pulse_like="NGA_no_1063_RRS228.AT2 RSN181_IMPVALL.H_H-E06230.AT2 RSN77_SFERN_PUL164.AT2 RSN1120_KOBE_TAK090.AT2"
    set --
    for r in $pulse_like; do set -- "$@" "$recs/$r"; done
    all=$(ls "$recs"/*.AT2 "$recs"/*.at2 "$recs"/*.V2 2>/dev/null | sort)
    rec_label='shared records (fitted 1/L_e)'
else
    echo "paper: no $recs: Figs. 2 and 7 and the record spectra from the records in" \
         "examples/records (Rinaldi, CE36456, the seven stochastic near-fault records)" >&2
    pulse_like="NGA_no_1063_RRS228.AT2 nf2.txt nf3.txt nf4.txt"
    set -- examples/records/NGA_no_1063_RRS228.AT2 examples/records/suite/nf2.txt \
        examples/records/suite/nf3.txt examples/records/suite/nf4.txt
    all=$(ls examples/records/*.AT2 examples/records/*.V2 examples/records/suite/nf*.txt | sort)
    rec_label='shipped records (fitted 1/L_e)'
fi
if [ -n "$all" ]; then
    # Fig. 2: records with their fitted pulses
    "$pound" record "$@" --plot "$out/paper-fig2.png" > "$out/paper-fig2.txt"
    # every record's fitted 1/Le, for Fig. 7
    "$pound" record $all > "$out/paper-records.txt"
    "$pound" record $all --json | tr '{' '\n' | awk -F'"name":"' 'NF > 1 {split($2, a, "\""); n = a[1]}
        /"Le":/ {sub(/.*"Le":/, ""); sub(/,.*/, ""); printf "%s %.6g\n", n, 1 / $0}' |
        sort -g -k2,2 > "$tmp/le0"
    # a log axis from 1 (or below the first record) to past the last, every
    # record inside; each label at the lowest of four heights whose last
    # label is at least 2.2 % of the axis' width to its left (a 7-point
    # rotated label's height), else at the height whose last label is farthest
    xmin=$(awk 'NR == 1 {printf "%.3g", $2 < 1.2 ? 0.8 * $2 : 1}' "$tmp/le0")
    xmax=$(awk '{x = $2 > x ? $2 : x} END {printf "%.3g", 1.25 * (x > 12 ? x : 12)}' "$tmp/le0")
    awk -v xmin="$xmin" -v xmax="$xmax" 'BEGIN {for (l = 0; l < 4; l++) last[l] = -1e9}
        {x = log($2); best = -1
         for (l = 0; l < 4 && best < 0; l++) if (x - last[l] >= 0.022 * log(xmax / xmin)) best = l
         if (best < 0) {best = 0; for (l = 1; l < 4; l++) if (last[l] < last[best]) best = l}
         last[best] = x; name = $1; sub(/\.[^.]*$/, "", name)
         print name, $2, 0.002 + 0.022 * best}' "$tmp/le0" > "$tmp/le"
    # Fig. 7: contours of Pi3 = gap / Le on the (1/Le, gap) plane, the records placed
    gnuplot <<GP
$term
set output '$out/paper-fig7.png'
set title 'Fig. 7: {/Symbol P}_3 = gap / L_e on the (1/L_e, gap) plane; records at their fitted 1/L_e'
set xlabel '1/L_e = {/Symbol w}_p^2 / a_p [m^{-1}]'; set ylabel 'gap [m]'
set logscale x; set xrange [$xmin:$xmax]; set xtics add (2, 5, 20, 50); set yrange [0:0.1]; set grid; set key top right
set samples 400
set arrow from 1.2, graph 0 to 1.2, graph 1 nohead dt 2 lc rgb 'black'
set label 'Tabas (paper)' at 1.25, 0.095 font ',9'
set arrow from 5.3, graph 0 to 5.3, graph 1 nohead dt 2 lc rgb 'black'
set label 'Parkfield C02 (paper)' at 5.35, 0.095 font ',9'
plot for [p in '0.01 0.02 0.05 0.1 0.2 0.5'] p/x w l lw 2 t '{/Symbol P}_3 = '.p, \
     '$tmp/le' u 2:(0.0015):(0):(\$3 - 0.0015) w vectors nohead dt 3 lc rgb 'gray60' t '', \
     '$tmp/le' u 2:3:(strcol(1)) w labels rotate by 90 left font ',7' noenhanced \
        offset 0,0.5 t '', '$tmp/le' u 2:(0.0015) w points pt 7 ps 0.8 lc rgb 'black' \
        t '$rec_label'
GP
    # the spectra of every record and of the one-cycle pulses at Pi3 = 0.01, 0.05, 0.1
    grid="--Pi2 0.1:5:60 --Pi3 0.01,0.05,0.1 --eps 0.5 --xi 0.05 --method event"
    k=0
    for r in $all; do
        k=$((k + 1))
        "$pound" spectrum --method moreau --record "$r" $grid -o "$tmp/r$k.csv" > /dev/null
        grep -v '^#' "$tmp/r$k.csv" | awk -F, 'NR > 1 {print $1, $6, $10, $12}' >> "$tmp/rall"
    done
    "$pound" spectrum --method moreau --pulse sine,cosine $grid -o "$tmp/p.csv" > /dev/null
    grep -v '^#' "$tmp/p.csv" | awk -F, 'NR > 1 {print $1, $6, $10, $12}' >> "$tmp/rall"
    # collapse: across the pulse-like records, per Pi3 and band of Pi2, the spread
    # (max - min) / median of Pi1, and where the one-cycle pulses lie in it
    awk -v like="$pulse_like" 'BEGIN {n = split(like, L, " "); for (i = 1; i <= n; i++) pl[L[i]] = 1}
        ($1 in pl) {k = $2 " " $3; v[k] = v[k] " " $4; pi3[$2] = 1}
        $1 == "sine" || $1 == "cosine" {pul[$1 " " $2 " " $3] = $4}
        END {
            printf "collapse of Pi1(Pi2) across the pulse-like records (%s)\n", like
            printf "%6s %12s %8s %14s %14s %18s\n", "Pi3", "Pi2 band", "points", "median spread", "worst spread", "sine/cosine inside"
            for (p3 in pi3) for (b = 0; b < 3; b++) {
                lo = b == 0 ? 0 : b == 1 ? 0.5 : 2; hi = b == 0 ? 0.5 : b == 1 ? 2 : 99
                m = 0; inside = 0; tot = 0
                for (k in v) { split(k, kk, " "); if (kk[1] != p3 || kk[2] + 0 < lo || kk[2] + 0 >= hi) continue
                    c = split(substr(v[k], 2), x, " "); for (i = 1; i <= c; i++) for (j = i + 1; j <= c; j++) if (x[j] < x[i]) {t = x[i]; x[i] = x[j]; x[j] = t}
                    med = c % 2 ? x[(c + 1) / 2] : 0.5 * (x[c / 2] + x[c / 2 + 1])
                    s[++m] = (x[c] - x[1]) / med
                    for (q = 0; q < 2; q++) {pp = pul[(q ? "cosine " : "sine ") k]; tot++; if (pp >= x[1] && pp <= x[c]) inside++}
                }
                for (i = 1; i <= m; i++) for (j = i + 1; j <= m; j++) if (s[j] < s[i]) {t = s[i]; s[i] = s[j]; s[j] = t}
                if (m) printf "%6g %12s %8d %14.3f %14.3f %13d/%d\n", p3 + 0, lo "-" (hi == 99 ? "5" : hi), m, s[int((m + 1) / 2)], s[m], inside, tot
            }
        }' "$tmp/rall" > "$out/paper-records-collapse.txt"
    for r in $pulse_like sine cosine; do awk -v r="$r" '$1 == r && $2 == 0.05 {print $3, $4}' "$tmp/rall" > "$tmp/c-$r"; done
    gnuplot <<GP
$term
set output '$out/paper-records-collapse.png'
set title '{/Symbol P}_1({/Symbol P}_2) at {/Symbol P}_3 = 0.05, {/Symbol e} = 0.5, {/Symbol x} = 0.05: pulse-like records and the one-cycle pulses'
set xlabel '{/Symbol P}_2 = T_p / T_0'; set ylabel '{/Symbol P}_1 = u_{max} / L_e'
set logscale x; set grid; set key top right
plot for [r in '$pulse_like'] '$tmp/c-'.r w l lw 2 t r noenhanced, \
     '$tmp/c-sine' w l lw 3 dt 2 lc rgb 'black' t 'one-sine pulse', \
     '$tmp/c-cosine' w l lw 3 dt 3 lc rgb 'gray30' t 'one-cosine pulse'
GP
fi

echo "paper figures written to $out/paper-*.png"
