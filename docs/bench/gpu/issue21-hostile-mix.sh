#!/bin/bash
# Issue 21 on the GPU machine (16 cores: less noise than the shared dev machine): the far400
# hostile-mix bench (tools/hostile-mix-bench, docs/RELIABILITY.md "Hostile-mix load"): one robot
# replays fr079 at scale 0.5 at 5 Hz, quiet and then while the attacker who knows the mean-ray bound
# sends 100-point scans 400 m out from fresh robot ids; the robot's scans applied, the daemon's end-to-end
# p50/p99 and how long each stop took, the same binary for both. Two calls, ~35 s each:
#   now       the defaults (session 9: the shared class's budget of stage time per second and its
#             per-scan bound while a robot with history streams, intake/shared_class_budget.h);
#   nobudget  the same binary with --shared-budget false (session 7's share and round robin only).
# Every step is skipped, never cut, once its time is past (lib.sh's `left`); ~70 s in all.
#   Here, after building octomap-rt-server octomap-rt octomap-rt-scenegen (and build/python, the
#   generated Python types the hostile peers send with) in BUILD_DIR:
#       docs/bench/gpu/issue21-hostile-mix.sh bundle BUILD_DIR      -> .device-bundle/bounds-s9
#   There (carry [".device-bundle/bounds-s9"]), from the repository root:
#       docs/bench/gpu/issue21-hostile-mix.sh run
#   The result, $OUT/bounds-s9.tar.gz: now.txt, nobudget.txt (the bench's report), progress.txt,
#   machine.txt. The peers are Python (standard library only: octomap_rt's udpm transport).
set -uo pipefail
name=bounds-s9
case "${1:-}" in
  bundle)
    set -e
    build=$2
    repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)
    "$repo/docs/bench/gpu/make-bundle.sh" "$build" "$name"
    rm -f "$repo/.device-bundle/$name/server-bench" "$repo/.device-bundle/$name/bin/zstd"
    mkdir -p "$repo/.device-bundle/$name/python"
    cp -r "$build/python/." "$repo/.device-bundle/$name/python/"
    find "$repo/.device-bundle/$name/python" -name __pycache__ -prune -exec rm -rf {} +
    du -sh "$repo/.device-bundle/$name"
    ;;
  run)
    . docs/bench/gpu/lib.sh "$name"
    # The layout tools/hostile-mix-bench expects of a build folder, made of the bundle's programs.
    L=$T/build
    mkdir -p "$L/server" "$L/client" "$L/tools/scenegen"
    ln -sf "$N/bin/octomap-rt-server" "$L/server/octomap-rt-server"
    ln -sf "$N/bin/octomap-rt" "$L/client/octomap-rt"
    ln -sf "$N/bin/octomap-rt-scenegen" "$L/tools/scenegen/octomap-rt-scenegen"
    ln -sfn "$N/python" "$L/python"
    { command -v python3 && python3 --version; command -v unshare; id -u; } > "$O/tools.txt" 2>&1
    bench() { local tag=$1; shift; log "$tag"
      OCTOMAP_RT_BUILD_DIR=$L timeout 75 tools/hostile-mix-bench/hostile-mix-bench --preset fr079 --scale 0.5 \
        --rate 5 --hostile far400 -- "$@" > "$O/$tag.txt" 2>&1
      echo "rc=$?" >> "$O/$tag.txt"; }
    left 60 && bench now
    left 60 && bench nobudget --shared-budget false
    ;;
  *) echo "usage: $0 bundle BUILD_DIR | run" >&2; exit 2 ;;
esac
