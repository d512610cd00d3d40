#!/bin/bash
# Fills the bundle run-daemon.sh carries: OLD = the programs of a bundle already made for main
# (the lead's, a4c5234), NEW = this build tree's, stripped; Debian's ip/bc/zstd, server-bench,
# and the libraries.
#   docs/bench/gpu/issue12-session4-daemon/make-bundle.sh OLD_BIN_DIR NEW_BUILD_DIR [BUNDLE]
set -euo pipefail
old=$1 new=$2 B=${3:-.device-bundle/daemon}
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../../.." && pwd)
rm -rf "$B"; mkdir -p "$B/old" "$B/new" "$B/bin"
cp "$old/octomap-rt-server" "$old/octomap-rt" "$old/octomap-rt-scenegen" "$B/old/"
cp "$new/server/octomap-rt-server" "$new/client/octomap-rt" "$new/tools/scenegen/octomap-rt-scenegen" "$B/new/"
strip "$B"/new/*
cp /usr/bin/ip /usr/bin/bc "$(command -v zstd)" "$B/bin/"
cp "$repo/tools/server-bench/server-bench" "$B/"
"$repo/../shared/device/bundle-libs" "$B" "$B"/old/* "$B"/new/* "$B"/bin/*
du -sh "$B"
