#!/usr/bin/env bash
# Installs what craneassist needs from Debian 12's packages, only if something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config clang-format
  libeigen3-dev libode-dev libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-matplotlib python3-scipy  # figures; scipy: the polytope's plot and Qhull check
  qemu-system-x86 busybox-static can-utils cpio  # the SocketCAN test VM (tools/can-vm/)
  libevdev-dev libsdl2-dev tmux  # joysticks; tmux drives the keyboard joystick in tests
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools openssl  # DDS telemetry and security
  cyclonedds-dev cyclonedds-tools  # Eclipse Cyclone DDS: the interop tests (tests/interop/)
  clang libclang-rt-14-dev llvm  # the clang sanitizer build and libFuzzer (docs/fuzzing.md)
  libboost-dev nlohmann-json3-dev chromium  # the web view (docs/web.md) and its browser test
  liburdfdom-dev liburdfdom-tools  # reads back the URDF of craneassist urdf (docs/ros.md)
  python3-can python3-canmatrix  # decode craneassist's CAN logs through its DBC (docs/can.md)
  libnlopt-dev  # the MHSB planner's optimal posture table (SLSQP; docs/mhsb.md)
  libzstd-dev  # the MCAP recordings' chunk compression (docs/foxglove.md)
)
# npm bundles the web page at build time (Debian's npm, unless node and npm are already there).
command -v npm >/dev/null || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "craneassist: installing ${missing[*]}" >&2
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "craneassist: run as root or install sudo" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
