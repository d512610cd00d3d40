#!/bin/bash
# Makes the bundle docs/bench/gpu/lib.sh expects from a build tree (stripped programs, Debian's ip/bc/zstd,
# server-bench, the libraries they need), here on the dev machine:
#     docs/bench/gpu/make-bundle.sh BUILD_DIR NAME      -> .device-bundle/NAME
set -euo pipefail
build=$1 name=$2
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)
B=$repo/.device-bundle/$name
rm -rf "$B"; mkdir -p "$B/bin"
cp "$build/server/octomap-rt-server" "$build/client/octomap-rt" "$build/tools/scenegen/octomap-rt-scenegen" "$B/bin/"
strip "$B"/bin/octomap-rt*
cp /usr/bin/ip /usr/bin/bc "$(command -v zstd)" "$B/bin/"
cp "$repo/tools/server-bench/server-bench" "$B/"
"$repo/../shared/device/bundle-libs" "$B" "$B"/bin/*
du -sh "$B"
