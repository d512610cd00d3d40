#!/bin/bash
# lead's third device call of the fifth session (issue 12): main ce16284 (new) on another fresh H200: fr079
# alternating with 202dc47 (old), the real sets (--repeat 3), skt-corridor 0.2 and the daemon goal again
# (call 2's steady run missed 4 of 1220 scans in the kernel's UDP buffer during a stretch of steal time).
. docs/bench/gpu/lib.sh lead s4
timeout 60 $N/bin/octomap-rt bench $C --preset fr079 --scan-scale 0.1 > $O/throwaway.txt 2>&1
bench fr079-new-a $N --preset fr079
bench fr079-old-a $OLD --preset fr079
bench fr079-new-b $N --preset fr079
bench fr079-old-b $OLD --preset fr079
bench fr079-new-c $N --preset fr079
bench real $N --preset none --data .device-data --repeat 3
bench skt $N --preset skt-corridor --scan-scale 0.2
log scenegen; $N/bin/octomap-rt-scenegen skt-corridor --scan-scale 0.2 -o $T/skt02.graph > $O/scenegen.txt 2>&1
daemon() { local tag=$1 bin=$2 rep=$3 graph=$4; log "daemon-$tag"; echo "before $(head -1 /proc/stat)" > "$O/daemon-$tag.txt"
  OCTOMAP_RT_BUILD_DIR=$bin/bin timeout 60 "$bin/server-bench" --graph "$graph" --repeat "$rep" --rounds 1 \
    --modes on --rate 100 -- -r 0.1 --backend vulkan >> "$O/daemon-$tag.txt" 2>&1; echo "after $(head -1 /proc/stat)" >> "$O/daemon-$tag.txt"; }
left 300 && daemon x20-a $N 20 $T/skt02.graph
left 340 && daemon x5-a $N 5 $T/skt02.graph
left 360 && daemon x20-b $N 20 $T/skt02.graph
exit 0
