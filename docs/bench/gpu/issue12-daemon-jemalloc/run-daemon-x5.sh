#!/bin/bash
# perf device run 4: daemon, 305 scans (the latency window of 512 holds every scan, first pass included).
cd "$(dirname "$0")/.."
. .device-bundle/env.sh .device-bundle
export PATH=$PWD/.device-bundle/bin:$PATH
OLD=$PWD/.device-bundle/bin; NEW=$PWD/.device-bundle/new
O=/tmp/perf-out; mkdir -p $O
log() { echo "== $(date -u +%T) $*" | tee -a $O/progress.txt; }
{ date -u; nproc; nvidia-smi -L; uptime; } > $O/machine.txt 2>&1
SB=.device-bundle/server-bench
$NEW/octomap-rt-scenegen skt-corridor --scan-scale 0.2 -o /tmp/skt02.graph > $O/scenegen.txt 2>&1
G="--graph /tmp/skt02.graph --repeat 5"
D="-r 0.1 --backend vulkan"
log d-new; OCTOMAP_RT_BUILD_DIR=$NEW timeout 40 $SB $G --rounds 2 --modes on --rate 100 -- $D > $O/daemon-new-rate100-x5.txt 2>&1
log d-new-nodelta; OCTOMAP_RT_BUILD_DIR=$NEW timeout 30 $SB $G --rounds 1 --modes on --rate 100 -- $D --delta-rate 0 > $O/daemon-new-rate100-nodelta-x5.txt 2>&1
log d-old; OCTOMAP_RT_BUILD_DIR=$OLD timeout 30 $SB $G --rounds 1 --modes on --rate 100 -- $D > $O/daemon-old-rate100-x5b.txt 2>&1
log done
