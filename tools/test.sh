#!/usr/bin/env bash
# Set up (Debian packages, the SocketCAN test VM's kernel), build, and run the whole test suite
# twice: a release build (with the SocketCAN tests in a qemu VM, label can_vm), then a clang build
# with AddressSanitizer and UndefinedBehaviorSanitizer (with float-cast-overflow and implicit
# integer conversion checks) that also runs each libFuzzer harness briefly (label fuzz_smoke;
# docs/fuzzing.md). Also checks the formatting and that the executable builds without DDS and
# without the web view.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-deps.sh
tools/can-vm/prepare.sh  # Debian's stock kernel with CAN for the VM tests (cached in build/)
jobs="$(nproc)"
export CRANEASSIST_CAN_VM_REQUIRED=1  # here the VM tests must run, never be skipped
export CRANEASSIST_WEB_REQUIRED=1     # and the browser test of the web view

echo "== formatting (clang-format)"
find app bench config dynamics input research scaling sim_backend tests valves \( -name '*.cpp' -o -name '*.hpp' \) \
  -print0 | xargs -0 clang-format --dry-run --Werror

echo "== release build and tests"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"

echo "== build without DDS and the web view: the executable alone, unoptimised, and its CLI checks"
cmake -S . -B build-nodds -DCMAKE_BUILD_TYPE=Debug -DCRANEASSIST_DDS=OFF -DCRANEASSIST_BUILD_BENCH=OFF \
  -DCRANEASSIST_CAN_VM_TESTS=OFF -DCRANEASSIST_WEB=OFF >/dev/null
cmake --build build-nodds -j"$jobs" --target craneassist
ctest --test-dir build-nodds --output-on-failure -R 'cli_sim_without_dds|cli_sim_without_web|cli_replay_initial|cli_sim_bad_input'

echo "== clang AddressSanitizer + UndefinedBehaviorSanitizer build, tests and fuzz smoke runs"
cmake -S . -B build-clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCRANEASSIST_FUZZ=ON -DCRANEASSIST_BUILD_BENCH=OFF >/dev/null
cmake --build build-clang -j"$jobs"
# Debian's Fast DDS 2.9 (not instrumented) frees some of its objects through a base pointer of
# another size when a participant is deleted (ASan: new-delete-type-mismatch), and leaks OpenSSL
# objects after a failed DDS Security handshake: both are inside the library, so that one check
# is off and libcrypto's leaks are suppressed (tests/lsan-fastdds.supp). Everything else stays on.
# The fuzz soak runs (label fuzz_soak, minutes each) are left to `ctest -L fuzz_soak`; the papers'
# offline studies (label research: planners, MHSB arm, mobile base; minutes under ASan) ran in
# the release suite above.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:new_delete_type_mismatch=0 \
  LSAN_OPTIONS="suppressions=$PWD/tests/lsan-fastdds.supp" \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-clang --output-on-failure -j"$jobs" -LE 'fuzz_soak|research|sway'
