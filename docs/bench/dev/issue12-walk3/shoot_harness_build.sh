#!/bin/bash
# usage: shoot_harness_build.sh <srcroot> <out>   (the harness: ../issue12-walk2/cpu_harness.cpp; run: <out> skt01.graph 1 3)
S=$1
nice g++ -std=c++20 -O2 -g -I$S/server ${SB:-docs/bench/dev/issue12-walk2/cpu_harness.cpp} $S/server/core/cpu_grid_backend.cpp $S/server/core/window_walk_avx2.cpp $S/server/core/prepare_scan.cpp $S/server/core/ray_space.cpp $S/server/core/exact_traversal.cpp $S/server/core/log.cpp $(ls $S/server/core/map_frame.cpp 2>/dev/null) $(ls $S/server/core/grid_*.cpp 2>/dev/null) -o $2 -loctomap -loctomath -ljemalloc -lpthread
