#!/usr/bin/env bash
# Prints the real-recording table (docs/real-recordings.md, DESIGN 4.1) as markdown: stereoguard
# with its defaults and the central-median baseline on each recording of the shared data folder,
# scored by `stereoguard eval --truth` against the recording's truth log (EuRoC has none: its
# alarm frames are counted).
# Usage: [SG_BIN=path/to/stereoguard] scripts/eval_real.sh [SHARED_DATA_DIR]
# SHARED_DATA_DIR defaults to ../shared/data beside the repository; SG_BIN to build/release/stereoguard.
# About 40 s on 2 idle cores.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
data="${1:-$repo/../shared/data}"
bin="${SG_BIN:-$repo/build/release/stereoguard}"
if [ ! -d "$data" ]; then
  echo "eval_real.sh: no shared data folder at $data: nothing to evaluate (skipped)"
  exit 0
fi
if [ ! -x "$bin" ]; then
  echo "eval_real.sh: no stereoguard binary at $bin (build it, or set SG_BIN)" >&2
  exit 2
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# row RECORDING METHOD JSON: one table row from the JSON of `eval --json` or `run --summary`.
row() {
  python3 - "$1" "$2" "$3" <<'PY'
import json, sys
name, method, path = sys.argv[1:4]
r = json.load(open(path))
def ratio(num, den, scale=1.0, digits=3):
    if den == 0:
        return "-"
    return f"{scale * num / den:.{digits}f} ({num}/{den})"
alarms = f"{r['alarm_frames']} / {r['frames']}"
if "scored_frames" not in r:  # no truth log
    print(f"| {name} | {method} | {alarms} | - | - | - | - | - |")
    sys.exit()
recall = ratio(r["due_alarm_frames"], r["due_frames"])
false_alarm = ratio(r["quiet_alarm_frames"], r["quiet_frames"], 100.0, 1)
still = f"{r['still_alarm_frames']} / {r['still_frames']}"
contacts = "; ".join(
    ("never" if c["lead_s"] is None else f"{c['lead_s']:.2f} s")
    + " / " + ("-" if c["recall_last"] is None else f"{c['recall_last']:.2f}")
    for c in r["contacts"]) or "no contact"
error = r["distance_rel_error_median"]
error = "-" if error is None else f"{100 * error:.1f} ({r['distance_frames']})"
unscored = f" ({r['unscored_frames']} unscored)" if r["unscored_frames"] else ""
print(f"| {name} | {method} | {alarms}{unscored} | {recall} | {false_alarm} | {still} | "
      f"{contacts} | {error} |")
PY
}

# score NAME TRUTH_ARGS... -- INPUT_ARGS...: both rows of a recording with a truth log.
score() {
  local name="$1"
  shift
  local truth=()
  while [ "$1" != "--" ]; do truth+=("$1"); shift; done
  shift
  echo "eval_real.sh: $name" >&2
  "$bin" eval --quiet "$@" "${truth[@]}" --json "$tmp/sg.json" >/dev/null
  row "$name" "stereoguard" "$tmp/sg.json"
  "$bin" eval --quiet "$@" "${truth[@]}" --baseline-method central-median \
    --json "$tmp/base.json" >/dev/null
  row "$name" "baseline central-median" "$tmp/base.json"
}

echo "| recording | method | alarm frames / frames | recall (due) | false alarm % (quiet) |" \
     "still-camera alarms / still frames | lead / recall last 2.5 s, per contact |" \
     "median distance error % (frames) |"
echo "|---|---|---:|---:|---:|---:|---|---:|"

unibo="$data/unibo_robot_approach"
if [ -f "$unibo/truth.csv" ]; then
  score unibo_robot_approach --truth "$unibo/truth.csv" --due-within 0.85 -- \
    --left "$unibo/robotL.mp4" --right "$unibo/robotR.mp4" --calib "$unibo/camera.yaml"
else
  echo "eval_real.sh: $unibo missing, skipped" >&2
fi

for take in take1 take2 take3; do
  dir="$data/tudelft_stereoboard_approach/$take"
  if [ -f "$dir/truth.csv" ]; then
    score "tudelft $take" --truth "$dir/truth.csv" --distance-column distance_m -- \
      --left "$dir/left.avi" --right "$dir/right.avi" --calib "$dir/camera.yaml"
  else
    echo "eval_real.sh: $dir missing, skipped" >&2
  fi
done

euroc="$data/euroc_v1_01_micro"
if [ -d "$euroc" ]; then
  echo "eval_real.sh: euroc_v1_01_micro (no truth log)" >&2
  "$bin" run --quiet --euroc "$euroc" --summary "$tmp/sg.json" >/dev/null
  row "euroc_v1_01_micro (no truth)" "stereoguard" "$tmp/sg.json"
  "$bin" eval --quiet --euroc "$euroc" --baseline-method central-median \
    --json "$tmp/base.json" >/dev/null
  row "euroc_v1_01_micro (no truth)" "baseline central-median" "$tmp/base.json"
else
  echo "eval_real.sh: $euroc missing, skipped" >&2
fi
