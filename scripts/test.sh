#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (unit, slow, data; data tests skip when
# ../shared is absent), then the skeleton and pipeline tests again under ThreadSanitizer, then the
# whole suite under AddressSanitizer + UndefinedBehaviorSanitizer (LeakSanitizer reports fail).
# The soak (label soak) and the fuzz targets (preset fuzz) are not part of it; the ASan stage
# leaves out the live-window tests (label gui, docs/live-and-stop.md): see docs/reliability.md.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"

scripts/bootstrap.sh release
# Every project file a comment names exists (docs/, src/, vision/... paths).
python3 scripts/check_comment_paths.py
ctest --preset release -j "$jobs"

# ThreadSanitizer build of the parallel layers only (par and pipeline tests, label "tsan").
cmake --preset tsan >/dev/null
cmake --build --preset tsan -j "$jobs" --target test_par test_pipeline
ctest --preset tsan -L tsan -j "$jobs"

# ASan + UBSan build of everything; every test (the preset leaves out the soak, the live-view
# test on Xvfb, label gui: GTK's one-time allocations may be reported by LeakSanitizer, and the
# tests that repeat under ASan what others there run already, on more data: the CLI tests that
# check detection figures on full-size scenarios, the 10-scene smoke suite (CliRandom's eval of a
# generated scene stays), the matchers' accuracy on the Middlebury pairs (FastVsReference stays);
# the release stage runs them all). Under TSan the configuration tests run a subset of their
# configurations (tests/pipeline/test_pipeline.cpp).
cmake --preset asan >/dev/null
cmake --build --preset asan -j "$jobs"
ctest --preset asan -j "$jobs"
