#!/bin/bash
# Fills the bundle run-daemon.sh carries: the programs of two build trees (OLD: main before the
# change measured, NEW: after), stripped, Debian's ip/bc/zstd, server-bench, and the libraries.
#   docs/bench/gpu/issue12-stage1/make-bundle.sh OLD_BUILD_DIR NEW_BUILD_DIR [BUNDLE (.device-bundle/stage1)]
set -euo pipefail
old=$1 new=$2 B=${3:-.device-bundle/stage1}
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../../.." && pwd)
rm -rf "$B"; mkdir -p "$B/old" "$B/new" "$B/bin"
for d in old new; do
  src=$old; [ $d = new ] && src=$new
  cp "$src/server/octomap-rt-server" "$src/client/octomap-rt" "$src/tools/scenegen/octomap-rt-scenegen" "$B/$d/"
done
cp "$new/tools/intake_bench/octomap-rt-intake-bench" "$B/new/"
strip "$B"/old/* "$B"/new/*
cp /usr/bin/ip /usr/bin/bc "$(command -v zstd)" "$B/bin/"
cp "$repo/tools/server-bench/server-bench" "$B/"
"$repo/../shared/device/bundle-libs" "$B" "$B"/old/* "$B"/new/* "$B"/bin/*
du -sh "$B"
