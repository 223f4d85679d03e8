#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (unit, slow, data; data tests skip when
# ../shared is absent), then the skeleton and pipeline tests again under ThreadSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"

scripts/bootstrap.sh release
ctest --preset release -j "$jobs"

# ThreadSanitizer build of the parallel layers only (par and pipeline tests, label "tsan").
cmake --preset tsan >/dev/null
cmake --build --preset tsan -j "$jobs" --target test_par test_pipeline
ctest --preset tsan -L tsan -j "$jobs"
