#!/usr/bin/env bash
# Every performance figure of issue 8 in one go, on a quiet machine (docs/performance.md):
#   1. collector busy time, Stereo-Flow, 640x480 head-on folder, W 1 and 2 (summary JSON);
#   2. bench at 640x480 against opencv-mt in the same run, with the paced rows (80 %, 150 %),
#      StereoBM and --matcher fast;
#   3. whole process on a 752x480 folder (scripts/bench_process.sh).
#
#   scripts/bench_realtime.sh [WORK_DIR]     (default /tmp/sg-realtime; folders are made once)
#   RUNS=7 FRAMES=300 scripts/bench_realtime.sh
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
sg="${BUILD:-$here/build/release}/stereoguard"
work="${1:-/tmp/sg-realtime}"
frames="${FRAMES:-300}"
mkdir -p "$work"
[[ -x "$sg" ]] || { echo "missing $sg: build first" >&2; exit 2; }
echo "== $(date -u)  $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"

[[ -d "$work/head-on" ]] || "$sg" simulate --scenario head-on --out "$work/head-on"
[[ -d "$work/head-on-752" ]] || "$here/scripts/bench_process.sh" --make-folder "$work/head-on-752"

echo "== 1. collector busy time, Stereo-Flow, 640x480 head-on folder"
for w in 1 2; do
  "$sg" run --input "$work/head-on" --mode stereo-flow --workers "$w" --quiet \
    --summary "$work/summary-w$w.json" | grep -E "throughput|busy"
done

echo "== 2. bench 640x480 (StereoBM, then --matcher fast; baselines stay StereoBM)"
for matcher in bm fast; do
  "$sg" bench --resolutions 640x480 --workers 1,2,3 --tiles 1,2 --frames "$frames" \
    --pace 0.8,1.5 --matcher "$matcher" --csv "$work/bench-$matcher.csv"
done

echo "== 3. whole process, 752x480 folder"
"$here/scripts/bench_process.sh" "$work/head-on-752" "${RUNS:-7}"
