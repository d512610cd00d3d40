#!/bin/bash
# lead's first device call of the fifth session (issue 12): main 4ff22e6 (new: octree jobs shared out, per-voxel
# work cut, cpu-grid changes) against main 202dc47 (old: the fourth session's last bundle; 9e54710 differs only in
# refactors and docs) on fr079, alternating, idle and beside 4 busy loops (octree2's synthetic slow machine);
# then new alone on skt-corridor 0.2 and the real sets.
. docs/bench/gpu/lib.sh lead s4
timeout 60 $N/bin/octomap-rt bench $C --preset fr079 --scan-scale 0.1 > $O/throwaway.txt 2>&1
bench fr079-new-idle-a $N --preset fr079
bench fr079-old-idle-a $OLD --preset fr079
loaded fr079-new-load-a $N --preset fr079
loaded fr079-old-load-a $OLD --preset fr079
bench fr079-old-idle-b $OLD --preset fr079
bench fr079-new-idle-b $N --preset fr079
left 300 && loaded fr079-old-load-b $OLD --preset fr079
left 330 && loaded fr079-new-load-b $N --preset fr079
left 380 && bench skt $N --preset skt-corridor --scan-scale 0.2
left 420 && bench real $N --preset none --data .device-data
exit 0
