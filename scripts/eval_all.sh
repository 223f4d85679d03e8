#!/usr/bin/env bash
# Scores every detector on every built-in scenario and prints a markdown table (docs/detectors.md).
# Usage: [DETECTORS="stereo stereo-flow ..."] scripts/eval_all.sh [path/to/stereoguard]
# DETECTORS defaults to all seven (about 25 min on 2 cores; relative-size is the slowest).
set -euo pipefail
bin="${1:-$(dirname "$0")/../build/release/stereoguard}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
detectors="${DETECTORS:-stereo stereo-flow motion-parallax relative-size elevation-map sceneflow-seg longseq}"
echo "| scenario | detector | GT alarm frames | alarm frames (true) | recall_settled | false_alarm_rate | lead time | TTC rel. error median / p90 / max after 5 | severity changes |"
echo "|---|---|---:|---:|---:|---:|---|---|---:|"
for scenario in $("$bin" scenarios | awk '{print $1}'); do
  for mode in $detectors; do
    "$bin" eval --quiet --scenario "$scenario" --detector "$mode" --json "$tmp/e.json" >/dev/null
    python3 - "$tmp/e.json" "$scenario" "$mode" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
leads = [l["lead_time_s"] for l in r["lead_times_s"]]
lead = ", ".join("never" if t is None else f"{t:.2f} s" for t in leads) or "-"
print(f"| {sys.argv[2]} | {sys.argv[3]} | {r['gt_alarm_frames']} | {r['alarm_frames']} "
      f"({r['true_alarm_frames']}) | {r['recall_settled']:.3f} | {r['false_alarm_rate']:.3f} | {lead} | "
      + (f"{r['ttc_rel_error_median']:.3f} / {r['ttc_rel_error_p90']:.3f} / "
         + ("-" if r.get('ttc_rel_error_max_settled') is None else f"{r['ttc_rel_error_max_settled']:.3f}")
         if r.get('ttc_rel_error_median') is not None else "-")
      + f" | {r['severity_changes']} |")
PY
  done
done
