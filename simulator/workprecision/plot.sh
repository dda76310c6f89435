#!/bin/sh
# A PNG of a clothsim_wp CSV with gnuplot (the tool writes its own SVG; this is for docs/).
# usage: plot.sh CSV PNG TITLE REFCHECK   (REFCHECK: the reference check the tool printed)
set -eu
if [ $# -ne 4 ]; then echo "usage: plot.sh CSV PNG TITLE REFCHECK" >&2; exit 2; fi
csv=$1; png=$2; title=$3; ref=$4
[ -r "$csv" ] || { echo "plot.sh: error: cannot read '$csv'" >&2; exit 1; }
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
methods="symplectic-euler explicit-euler verlet midpoint rk4 implicit-euler fast-mass-spring xpbd"
plot=""
for m in $methods; do
  awk -F, -v m=$m -v r=$ref 'NR>1 && $1==m && $6==1 && $3<=1 && $3>=10*r {print $3, $4}' "$csv" > $d/$m.dat
  if [ -s $d/$m.dat ]; then plot="$plot${plot:+, }'$d/$m.dat' using 1:2 with linespoints lw 2 pt 7 title '$m'"; fi
done
[ -n "$plot" ] || { echo "plot.sh: error: '$csv' has no finite points within 1 and 10 x $ref" >&2; exit 1; }
gnuplot <<GP || { rm -f "$png"; echo "plot.sh: error: gnuplot failed; no $png" >&2; exit 1; }
set terminal pngcairo size 900,600 font 'sans,11'
set output '$png'
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set grid
set xlabel 'error (RMS position error / cloth size)'
set ylabel 'CPU seconds'
set title '$title'
set key outside right
set arrow from 1e-2, graph 0 to 1e-2, graph 1 nohead dt 2 lc 'gray'
set arrow from 1e-3, graph 0 to 1e-3, graph 1 nohead dt 2 lc 'gray'
plot $plot
GP
