#!/bin/bash
# usage: mk.sh <srcroot> <out>
S=$1
g++ -std=c++20 -O2 -g -I$S/server ${SB:-/tmp/walk2/shootbench.cpp} $S/server/core/cpu_grid_backend.cpp $S/server/core/window_walk_avx2.cpp $S/server/core/prepare_scan.cpp $S/server/core/ray_space.cpp $S/server/core/exact_traversal.cpp $S/server/core/log.cpp $(ls $S/server/core/grid_*.cpp 2>/dev/null) -o $2 -loctomap -loctomath -ljemalloc -lpthread
