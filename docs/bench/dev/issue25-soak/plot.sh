#!/usr/bin/env bash
# The soak's plot: memory (server RSS, peak RSS, map memory) and end-to-end p99 over time.
#   plot.sh SERIES.csv OUT.png TITLE
set -euo pipefail
gnuplot <<G
set terminal png size 1000,700
set output "$2"
set datafile separator ","
set multiplot layout 2,1 title "soak: $3"
set xlabel "minutes"
set ylabel "MiB"
set key below
plot "$1" every ::1 using (\$1/60):2 with lines title "server RSS", \
     "" every ::1 using (\$1/60):3 with lines title "server peak RSS", \
     "" every ::1 using (\$1/60):4 with lines title "map memory (OcTree::memoryUsage)"
set ylabel "ms"
plot "$1" every ::1 using (\$1/60):6 with lines title "end-to-end p99 (status)"
unset multiplot
G
