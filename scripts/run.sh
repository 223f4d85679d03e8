#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs `stereoguard run` (arguments pass on;
# none = the built-in head-on scenario, with an overlay video).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/scripts/bootstrap.sh" release
exec "$here/build/release/stereoguard" run "$@"
