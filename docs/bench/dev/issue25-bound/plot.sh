#!/usr/bin/env bash
# The memory bound's plot: tree memory, RSS and the bound over time (with and without the
# bound), and the end-to-end and octree p99s of both runs.
#   plot.sh OUT_DIR OUT.png TITLE [SUFFIX]   (OUT_DIR holds series-off$SUFFIX.csv and series-on$SUFFIX.csv)
set -euo pipefail
gnuplot <<G
set terminal png size 1000,800
set output "$2"
set datafile separator ","
set multiplot layout 2,1 title "memory bound: $3"
set xlabel "minutes"
set ylabel "MiB"
set key below
plot "$1/series-off${4:-}.csv" every ::1 using (\$1/60):4 with lines title "tree memory, no bound", \
     "$1/series-on${4:-}.csv" every ::1 using (\$1/60):4 with lines title "tree memory, bound", \
     "$1/series-on${4:-}.csv" every ::1 using (\$1/60):9 with lines dashtype 2 title "bound", \
     "$1/series-off${4:-}.csv" every ::1 using (\$1/60):2 with lines title "RSS, no bound", \
     "$1/series-on${4:-}.csv" every ::1 using (\$1/60):2 with lines title "RSS, bound", \
     "$1/series-on${4:-}.csv" every ::1 using (\$1/60):10 with lines title "evicted (in the store), bound"
set ylabel "ms"
plot "$1/series-off${4:-}.csv" every ::1 using (\$1/60):6 with lines title "end-to-end p99, no bound", \
     "$1/series-on${4:-}.csv" every ::1 using (\$1/60):6 with lines title "end-to-end p99, bound", \
     "$1/series-off${4:-}.csv" every ::1 using (\$1/60):8 with lines title "octree p99, no bound", \
     "$1/series-on${4:-}.csv" every ::1 using (\$1/60):8 with lines title "octree p99, bound"
unset multiplot
G
