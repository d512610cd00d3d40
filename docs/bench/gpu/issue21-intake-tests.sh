#!/bin/bash
# Issue 21 item 1 and issue 24 item 1 on the GPU machine: the tests of degenerate scan fields, of
# coordinates near 0 (the scan contract's rules against NVIDIA's flushing of fp32 subnormals:
# core/prepare_scan.h), of GPU preparation against the CPU's bit for bit, and of organised
# clouds with NaN no-returns, on every back end, where vulkan runs on the H200 and rt (ray
# tracing, exact traversal) has its device; on the dev machine rt is skipped (no RT device)
# and vulkan runs on lavapipe.
#   Here, after building the test targets (engine_degenerate_rays_test server_scan_fields_test
#   server_organised_cloud_test gpu_prepare_test) in BUILD_DIR:
#       docs/bench/gpu/issue21-intake-tests.sh bundle BUILD_DIR     -> .device-bundle/issue21-intake
#   There (the run tool, carry [".device-bundle"]):
#       docs/bench/gpu/issue21-intake-tests.sh run
#   The result, $OUT/issue21-intake.tar.gz, holds each test's output, summary.txt (passed/failed/
#   skipped per test, "NO RT RUN" when the rt cases skipped there too), the device's float
#   controls (vulkaninfo, when there) and the machine's description.
set -uo pipefail
tests="engine_degenerate_rays_test server_scan_fields_test server_organised_cloud_test gpu_prepare_test"
case "${1:-}" in
  bundle)
    set -e
    build=$2
    repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)
    B=$repo/.device-bundle/issue21-intake
    rm -rf "$B"; mkdir -p "$B/bin" "$B/data"
    for t in $tests; do [ -x "$build/tests/$t" ] && cp "$build/tests/$t" "$B/bin/"; done
    strip "$B"/bin/*
    # The organised-cloud test and gpu_prepare_test read shared real scans, carried beside the tests.
    mkdir -p "$B/data/octomap_share" "$B/data/3dtk_dat"
    cp "$repo/../shared/data/octomap_share/scan_dat.graph" "$B/data/octomap_share/"
    cp "$repo/../shared/data/3dtk_dat/3dtk_3scans.graph" "$B/data/3dtk_dat/"
    "$repo/../shared/device/bundle-libs" "$B" "$B"/bin/*
    du -sh "$B";;
  run)
    . docs/bench/gpu/lib.sh issue21-intake
    export OCTOMAP_RT_DATA=$N/data
    command -v vulkaninfo > /dev/null && vulkaninfo 2> /dev/null | grep -iE 'deviceName|denorm|roundingMode' \
      > "$O/float-controls.txt"
    for t in $tests; do
      [ -x "$N/bin/$t" ] || continue
      log "$t"
      timeout 120 "$N/bin/$t" > "$O/$t.txt" 2>&1; rc=$?
      { echo "$t rc=$rc"; grep -E '^\[  (PASSED|FAILED|SKIPPED) ' "$O/$t.txt"; } >> "$O/summary.txt"
      grep -q 'SKIPPED.*/rt' "$O/$t.txt" && echo "$t: NO RT RUN (rt cases skipped)" >> "$O/summary.txt"
    done;;
  *) echo "usage: $0 bundle BUILD_DIR | run" >&2; exit 2;;
esac
