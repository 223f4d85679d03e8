#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (unit, slow, data; data tests skip when
# ../shared is absent), then the skeleton and pipeline tests under ThreadSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/bootstrap.sh release
ctest --preset release -j "$(nproc)"
