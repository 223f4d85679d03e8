#!/usr/bin/env bash
# Builds the libFuzzer targets (preset fuzz, clang-14) and runs each for RUNS executions
# (default 1000000), niced, printing libFuzzer's final stats per target.
# Usage: scripts/fuzz.sh [RUNS] [TARGET...]   (targets: names of tests/fuzz/fuzz_*.cpp without
# the fuzz_ prefix; default all). New inputs go to build/fuzz/corpus/<target>, crashes to
# build/fuzz/artifacts/. Reproduce a crash: build/fuzz/tests/fuzz/fuzz_<target> <crash file>.
set -euo pipefail
cd "$(dirname "$0")/.."
runs="${1:-1000000}"
shift || true
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j "$(nproc)"
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for f in tests/fuzz/fuzz_*.cpp; do
    name="$(basename "$f" .cpp)"
    [ "$name" = fuzz_input ] || targets+=("${name#fuzz_}")
  done
fi
status=0
for t in "${targets[@]}"; do
  mkdir -p "build/fuzz/corpus/$t" build/fuzz/artifacts
  echo "== fuzz_$t: $runs runs"
  start=$(date +%s)
  if ! nice -n 19 "build/fuzz/tests/fuzz/fuzz_$t" -runs="$runs" -timeout=60 -rss_limit_mb=2048 \
      -print_final_stats=1 -artifact_prefix="build/fuzz/artifacts/$t-" \
      "build/fuzz/corpus/$t" "tests/fuzz/corpus/$t" 2>"build/fuzz/$t.log"; then
    status=1
    echo "fuzz_$t: FAILED, see build/fuzz/$t.log"
  fi
  grep -E "^Done|stat::number_of_executed_units|stat::peak_rss_mb|cov: .*(DONE|INITED)" \
    "build/fuzz/$t.log" | tail -4 || true
  echo "fuzz_$t: $(( $(date +%s) - start )) s"
done
exit $status
