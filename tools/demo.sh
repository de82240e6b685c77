#!/usr/bin/env bash
# Set up (Debian packages), build, and run the main job: the simulated reference crane driven by
# the bundled demo replay. Prints a summary and writes craneassist-log.csv. Extra arguments go to
# `craneassist replay`.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-deps.sh
# Ninja for a new build tree (an existing tree keeps the generator it was made with).
command -v ninja >/dev/null && export CMAKE_GENERATOR=Ninja
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target craneassist
exec build/app/craneassist replay "$@"
