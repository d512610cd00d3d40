#!/bin/bash
# lead's fourth device call of the fifth session (issue 12): fr079 beside 4 busy loops (octree2's synthetic slow
# machine), main ce16284 (new) and 202dc47 (old) alternating, three pairs, after one idle pair; every run records
# the steal time across it (lib.sh). Calls 1 and 2 gave one and two loaded pairs with opposite outcomes.
. docs/bench/gpu/lib.sh lead s4
timeout 60 $N/bin/octomap-rt bench $C --preset fr079 --scan-scale 0.1 > $O/throwaway.txt 2>&1
bench fr079-new-idle $N --preset fr079
bench fr079-old-idle $OLD --preset fr079
loaded fr079-old-load-a $OLD --preset fr079
loaded fr079-new-load-a $N --preset fr079
loaded fr079-new-load-b $N --preset fr079
loaded fr079-old-load-b $OLD --preset fr079
left 250 && loaded fr079-old-load-c $OLD --preset fr079
left 280 && loaded fr079-new-load-c $N --preset fr079
exit 0
