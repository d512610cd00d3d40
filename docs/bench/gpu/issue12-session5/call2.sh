#!/bin/bash
# lead's final device call of the fifth session (issue 12): main ce16284 at the session's freeze (new) on every goal:
# fr079 (three runs; old = 202dc47 alternating twice; one run of each beside 4 busy loops), campus 0.1 twice,
# skt-corridor 0.2, the real sets (--repeat 3), and the daemon goal (skt-corridor 0.2, 3 producers x 100 Hz):
# two new-space runs (--repeat 5, each a fresh daemon) and one steady (--repeat 20).
. docs/bench/gpu/lib.sh lead s4
timeout 60 $N/bin/octomap-rt bench $C --preset fr079 --scan-scale 0.1 > $O/throwaway.txt 2>&1
bench fr079-new-a $N --preset fr079
bench fr079-old-a $OLD --preset fr079
bench fr079-new-b $N --preset fr079
bench fr079-old-b $OLD --preset fr079
bench fr079-new-c $N --preset fr079
loaded fr079-new-load $N --preset fr079
loaded fr079-old-load $OLD --preset fr079
bench skt $N --preset skt-corridor --scan-scale 0.2
bench real $N --preset none --data .device-data --repeat 3
left 200 && bench campus-a $N --preset campus --scan-scale 0.1
log scenegen; $N/bin/octomap-rt-scenegen skt-corridor --scan-scale 0.2 -o $T/skt02.graph > $O/scenegen.txt 2>&1
left 330 && daemon x5-a $N 5 $T/skt02.graph
left 360 && daemon x5-b $N 5 $T/skt02.graph
left 390 && daemon x20 $N 20 $T/skt02.graph
left 440 && bench campus-b $N --preset campus --scan-scale 0.1
exit 0
