#!/usr/bin/env bash
# Checks that two stereoguard binaries write byte-identical events (`run --no-timing --events`)
# on every built-in scenario in every detector, and on the recordings of the shared data folder
# with the default detector: the check of a change that must not change behaviour (a refactor).
# Prints one line per run that differs and a count; exits 1 when any differs, 2 on bad arguments.
# Usage: scripts/compare_events.sh BINARY_BEFORE BINARY_AFTER [SHARED_DATA_DIR]
# SHARED_DATA_DIR defaults to ../shared/data beside the repository; without it the recordings are
# skipped. Two runs at a time; about 23 min on 2 idle cores.
set -euo pipefail
if [ $# -lt 2 ] || [ ! -x "$1" ] || [ ! -x "$2" ]; then
  echo "usage: scripts/compare_events.sh BINARY_BEFORE BINARY_AFTER [SHARED_DATA_DIR]" >&2
  exit 2
fi
before="$(realpath "$1")"
after="$(realpath "$2")"
repo="$(cd "$(dirname "$0")/.." && pwd)"
data="${3:-$repo/../shared/data}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

scenarios="car-cut-in car-stopped cold-start crossing ego-pass ego-wall head-on head-on-fast
  overhang pedestrian receding static thin-pole turning two-obstacles"
detectors="stereo-flow stereo motion-parallax relative-size elevation-map sceneflow-seg longseq"

# One job per line: a name, then the run arguments.
jobs="$tmp/jobs"
for s in $scenarios; do
  for d in $detectors; do echo "$s.$d --scenario $s --detector $d"; done
done > "$jobs"
if [ -d "$data" ]; then
  u="$data/unibo_robot_approach"
  [ -d "$u" ] && echo "unibo --left $u/robotL.mp4 --right $u/robotR.mp4 --calib $u/camera.yaml" >> "$jobs"
  for take in "$data"/tudelft_stereoboard_approach/take*; do
    [ -d "$take" ] || continue
    echo "tudelft-$(basename "$take") --left $take/left.avi --right $take/right.avi" \
      "--calib $take/camera.yaml" >> "$jobs"
  done
  for e in "$data"/euroc*; do
    [ -d "$e" ] && echo "$(basename "$e") --euroc $e" >> "$jobs"
  done
fi

# compare NAME ARGS...: both binaries' events of one run, and a line when they differ.
compare() {
  local name="$1"
  shift
  "$before" run "$@" --no-timing --quiet --workers 1 --events "$tmp/$name.before" >/dev/null 2>&1 ||
    echo "before failed: $name" > "$tmp/$name.before"
  "$after" run "$@" --no-timing --quiet --workers 1 --events "$tmp/$name.after" >/dev/null 2>&1 ||
    echo "after failed: $name" > "$tmp/$name.after"
  if cmp -s "$tmp/$name.before" "$tmp/$name.after"; then
    echo same > "$tmp/$name.result"
  else
    echo differ > "$tmp/$name.result"
    echo "differ: $name"
  fi
}
export -f compare
export before after tmp
xargs -P 2 -L 1 bash -c 'compare "$@"' _ < "$jobs"

total=$(wc -l < "$jobs")
differ=$(grep -l differ "$tmp"/*.result 2>/dev/null | wc -l || true)
echo "compare_events: $((total - differ)) of $total runs byte-identical"
[ "$differ" -eq 0 ]
