#!/usr/bin/env bash
# Whole-process benchmark on a stereo folder (docs/performance.md): the plain loop a user would
# write (build/release/plain_loop: imread, StereoBM, DIS ultrafast, a one-gap labelling, OpenCV's
# default threads) against `stereoguard run --input DIR` with its default W and T (auto), in
# both modes, and with `--matcher fast`. Every command runs as its own process, RUNS rounds, the
# commands in a rotated order each round so that a change in machine load hits all of them alike.
# Prints each command's median wall and CPU time and, per mode, the median over rounds of the
# ratio plain-loop wall / run wall (the speedup; pairs from the same round).
#
#   scripts/bench_process.sh DIR [RUNS]       (RUNS default 7)
#   BUILD=build/release WORKERS=auto MODES="stereo stereo-flow" MATCHERS="bm fast" PLAIN_LABELLING=naive
#   PLAIN_TUNED=1: run the plain loop with the malloc settings stereoguard sets for itself
#   (freed maps stay on the heap, see src/apps/main.cpp), to separate that gain from the pipeline's
#
# A 752x480 folder like the one of issue 8 (135 frames of head-on):
#   scripts/bench_process.sh --make-folder DIR
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${BUILD:-$here/build/release}"
sg="$build/stereoguard"
plain="$build/plain_loop"
workers="${WORKERS:-auto}"  # auto: run's default
modes="${MODES:-stereo stereo-flow}"
matchers="${MATCHERS:-bm fast}"
plain_labelling="${PLAIN_LABELLING:-naive}"
plain_env=""
if [[ -n "${PLAIN_TUNED:-}" ]]; then
  plain_env="env GLIBC_TUNABLES=glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=536870912"
fi

for exe in "$sg" "$plain"; do
  [[ -x "$exe" ]] || { echo "missing $exe: build first (cmake --build build/release)" >&2; exit 2; }
done

if [[ "${1:-}" == "--make-folder" ]]; then
  out="${2:?usage: $0 --make-folder DIR}"
  yaml="$(mktemp --suffix=.yaml)"
  cat >"$yaml" <<'EOF'
name: head-on-752x480
frames: 135
camera: {width: 752, height: 480, focal_px: 500, baseline_m: 0.12, cx: 375.5, cy: 239.5, fps: 30}
obstacles:
  - {id: 1, size_m: [1.0, 1.5, 0.5], position_m: [0.0, 0.45, 15.0], velocity_mps: [0, 0, -3.0], texture_seed: 101}
EOF
  "$sg" simulate --scenario "$yaml" --out "$out"
  rm -f "$yaml"
  exit 0
fi

dir="${1:?usage: $0 DIR [RUNS]  (or $0 --make-folder DIR)}"
runs="${2:-7}"
[[ -f "$dir/camera.yaml" && -d "$dir/left" && -d "$dir/right" ]] ||
  { echo "$dir: not a stereo folder (camera.yaml, left/, right/)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "needs python3" >&2; exit 2; }

# Commands: name|command line. The first of each mode is its baseline.
cmds=()
for mode in $modes; do
  cmds+=("$mode plain-loop|$plain_env $plain --input $dir --mode $mode --labelling $plain_labelling")
  for matcher in $matchers; do
    cmds+=("$mode run-W$workers-$matcher|$sg run --input $dir --mode $mode --workers $workers --matcher $matcher --quiet")
  done
done

log="$(mktemp)"
trap 'rm -f "$log"' EXIT
echo "whole process on $dir ($(ls "$dir/left" | wc -l) frames), $runs rounds; $(nproc) cores," \
  "load average $(cut -d' ' -f1-3 /proc/loadavg)"
n=${#cmds[@]}
for ((r = 0; r < runs; ++r)); do
  for ((k = 0; k < n; ++k)); do
    entry="${cmds[$(((k + r) % n))]}"
    name="${entry%%|*}"
    line="${entry#*|}"
    # %e wall s, %U user s, %S system s
    if ! /usr/bin/time -f "$r|$name|%e|%U|%S" -o "$log.one" $line >"$log.out" 2>&1; then
      cat "$log.out" >&2
      echo "failed: $line" >&2
      exit 1
    fi
    cat "$log.one" >>"$log"
    if [[ $r == 0 ]]; then echo "  $name: $(grep -E "alarm|frames processed" "$log.out" | head -3 | tr '\n' ' ')"; fi
  done
done
rm -f "$log.one" "$log.out"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"

python3 - "$log" <<'EOF'
import sys, statistics as st
rows = [l.strip().split("|") for l in open(sys.argv[1]) if l.strip()]
by = {}
for r, name, wall, user, sys_ in rows:
    by.setdefault(name, {})[int(r)] = (float(wall), float(user) + float(sys_))
print(f"{'command':34} {'wall s (median)':>16} {'CPU s (median)':>15} {'speedup (median of rounds)':>27}")
base = None
for name, runs in by.items():
    mode = name.split()[0]
    walls = [w for w, _ in runs.values()]
    cpus = [c for _, c in runs.values()]
    if name.endswith("plain-loop"):
        base = runs
        ratio = ""
    else:
        ratios = [base[r][0] / runs[r][0] for r in runs if r in base]
        ratio = f"{st.median(ratios):.2f}x (min {min(ratios):.2f}, max {max(ratios):.2f})"
    print(f"{name:34} {st.median(walls):16.2f} {st.median(cpus):15.2f} {ratio:>27}")
EOF
