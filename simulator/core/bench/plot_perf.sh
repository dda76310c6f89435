#!/bin/sh
# Log-log plots of perf_sweep's CSV files (gnuplot, PNG):
#   simulator/core/bench/plot_perf.sh CSV_DIR OUT_DIR [N]   -> OUT_DIR/perf_springs.png, perf_collision.png
# (the collision plot shows the N x N cloth, default 256)
set -eu
in=${1:?usage: plot_perf.sh CSV_DIR OUT_DIR}
out=${2:?usage: plot_perf.sh CSV_DIR OUT_DIR [N]}
n=${3:-256}
for f in springs.csv collision.csv; do
  [ -r "$in/$f" ] || { echo "plot_perf.sh: error: cannot read '$in/$f'" >&2; exit 1; }
done
if ! awk -F, -v n="$n" 'NR>1 && $1==n {found=1} END {exit !found}' "$in/collision.csv"; then
  echo "plot_perf.sh: error: no rows for a $n x $n cloth in '$in/collision.csv' (it has N =" \
    "$(awk -F, 'NR>1 {print $1}' "$in/collision.csv" | sort -nu | tr '\n' ' ')); give one as the third argument" >&2
  exit 2
fi
mkdir -p "$out"
gnuplot <<GP || { rm -f "$out/perf_springs.png" "$out/perf_collision.png"; echo "plot_perf.sh: error: gnuplot failed" >&2; exit 1; }
set datafile separator ","
set terminal pngcairo size 900,560 font "sans,11"
set logscale xy
set grid
set key top left
# room above and below the data, so that a target line at its edge (100 ns under collision
# times that are all above it) is drawn inside the frame
set offsets 0, 0, graph 0.08, graph 0.08
set output "$out/perf_springs.png"
set title "Spring forces per step (one core unless said), triangulated N x N cloth"
set xlabel "masses (N^2)"
set ylabel "ns per spring per step"
plot "$in/springs.csv" using 2:4 skip 1 with linespoints title "scalar scatter loop (reference)", \
     "" using 2:5 skip 1 with linespoints title "gathered, 1 thread", \
     "" using 2:6 skip 1 with linespoints title "gathered, 2 threads", \
     3 with lines dashtype 2 title "target 3 ns"
set output "$out/perf_collision.png"
set title "Collision query per mass (cloth over an icosphere of T triangles, $n x $n cloth)"
set xlabel "collider triangles T"
set ylabel "ns per mass"
plot "< awk -F, 'NR==1 || \$1==$n' $in/collision.csv" using 3:5 skip 1 with linespoints title "BVH search + hints", \
     "" using 3:6 skip 1 with linespoints title "ContactCache (as in step), cloth moving 1 mm per step", \
     "" using 3:8 skip 1 with linespoints title "brute force (reference)", \
     100 with lines dashtype 2 title "target 100 ns"
GP
