#!/usr/bin/env bash
# Installs, from Debian 12's package archive, every package the project needs to build,
# run and test. Idempotent: it asks apt only for what is missing, and does nothing when
# everything is there. Run as root (or with sudo available).
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git ca-certificates
  # libraries the project links
  libeigen3-dev libassimp-dev libglfw3-dev libglew-dev libgl-dev
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  libstb-dev nlohmann-json3-dev libcli11-dev
  # headless OpenGL (Mesa's llvmpipe under Xvfb)
  xvfb xauth x11-utils libgl1-mesa-dri mesa-utils
  # fuzzing and sanitizers (clang + libFuzzer), plots, OBJ test models
  clang libclang-rt-14-dev libomp-dev gnuplot-nox assimp-testmodels
  # time -v for the build-speed benchmark
  time
  # strace: fault injection (SIGKILL at the K-th write/rename) in the reliability tests
  strace
  # xdotool: keys and mouse sent to the viewer's window under Xvfb (tests/viewer)
  xdotool
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "installed" ]] || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
