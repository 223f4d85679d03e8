#!/usr/bin/env bash
# Installs the Debian packages stereoguard needs (when missing), then configures and builds it.
# Usage: scripts/bootstrap.sh [preset]   (preset: release (default), debug, asan, tsan, fuzz)
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"

packages=(build-essential cmake ninja-build pkg-config libopencv-dev libtbb-dev libgtest-dev
          libgmock-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev libyaml-cpp-dev
          libhwy-dev libboost-graph-dev libdeflate-dev ffmpeg gnuplot-nox opencv-doc clang-14 libclang-rt-14-dev
          pybind11-dev python3-pybind11 python3-pytest python3-numpy python3-matplotlib xvfb
          x11-apps xdotool)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" -j "$(nproc)"
