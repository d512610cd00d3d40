#!/usr/bin/env bash
# Peak memory on a small machine (issue 25): `octomap-rt build` with the cpu-grid back end beside
# Debian's graph2tree (octomap-tools), each a child process under /usr/bin/time (%M: peak RSS),
# on the shared real sets and the skt-corridor preset (a 0.1 x 0.25 cut: 30 scans of ~67k
# points), all at 0.1 m; then `octomap-rt bench` for the speed against OctoMap in one process.
#   docs/bench/dev/issue25-rss/run.sh BUILD_DIR OUT_DIR
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
b=${1:-build}; o=${2:-$here/out}
data=${OCTOMAP_RT_DATA:-$here/../../../../../shared/data}
mkdir -p "$o"
{ date -u; nproc; uptime; } > "$o/machine.txt"
[ -f "$o/skt.graph" ] || "$b/tools/scenegen/octomap-rt-scenegen" skt-corridor --scan-scale 0.1 --point-scale 0.25 \
  -o "$o/skt.graph" > /dev/null
sets=("$data/3dtk_dat/3dtk_3scans.graph" "$data/octomap_share/scan_dat.graph" "$o/skt.graph")
echo "set,program,peak_rss_kib,seconds" > "$o/rss.csv"
for g in "${sets[@]}"; do
  n=$(basename "$g" .graph)
  /usr/bin/time -f "$n,graph2tree,%M,%e" -a -o "$o/rss.csv" graph2tree -i "$g" -o "$o/g2t.bt" -res 0.1 > /dev/null 2>&1
  /usr/bin/time -f "$n,octomap-rt build,%M,%e" -a -o "$o/rss.csv" "$b/client/octomap-rt" build "$g" -o "$o/ort.bt" \
    -r 0.1 --backend cpu-grid -q > "$o/build-$n.txt" 2>&1
done
# The octree stage both ways: `octomap-rt build` (above) runs the batched one by default.
"$b/client/octomap-rt" bench --preset none --graph "$(IFS=,; echo "${sets[*]}")" --resolutions 0.1 \
  --backends cpu-grid --traversals octomap --octree sequential,batched --csv "$o/bench.csv" > "$o/bench.txt" 2>&1
{ date -u; uptime; } >> "$o/machine.txt"
cat "$o/rss.csv"
