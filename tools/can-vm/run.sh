#!/usr/bin/env bash
# Runs a guest script inside Debian's stock kernel under qemu, with vcan0 and vcan1 up: the
# project's real SocketCAN tests (docs/can-vm.md). Run tools/can-vm/prepare.sh once first.
#
#   tools/can-vm/run.sh [--timeout S] [--memory MB] [--keep DIR] [--python] [--]
#                       GUEST_SCRIPT [FILE...]
#
# The FILEs (test binaries, data) are copied to /tests in the guest, each executable with the
# shared libraries ldd finds for it; GUEST_SCRIPT runs there as `sh GUEST_SCRIPT` (busybox sh)
# from /tests, with candump, cansend and cangen on the PATH. Its exit status goes back to the host
# through qemu's isa-debug-exit device. The guest's console is printed as it runs.
#
# Exit status: 0 when the guest script exited 0; 1 when it failed, 2 for a usage error, 3 when the
# guest never reported (kernel panic, crash), 124 on timeout; 77 when the VM's prerequisites are
# missing (CTest reports the test skipped), or 2 then if CRANEASSIST_CAN_VM_REQUIRED=1 (CI).
#
#   --timeout S   give up after S seconds of wall time (default 240)
#   --memory MB   guest memory (default 256; 512 with --python, whose files take about 40 MB of
#                 the initramfs, unpacked in guest memory next to it)
#   --keep DIR    keep the initramfs tree and the console log in DIR (for debugging)
#   --python      put Debian's /usr/bin/python3 in the guest with python-can and canmatrix
#                 (python3-can, python3-canmatrix); implied when a FILE ends in .py
set -euo pipefail

say() { echo "can-vm: $*" >&2; }
usage_error() { say "error: $*"; exit 2; }

root="$(cd "$(dirname "$0")/../.." && pwd)"
cache="${CRANEASSIST_CAN_VM_CACHE:-$root/build/can-vm-cache}"
timeout_s=240
memory=""
keep=""
python=0
while [ $# -gt 0 ]; do
  case "$1" in
    --timeout) timeout_s="${2:?--timeout needs seconds}"; shift 2 ;;
    --memory) memory="${2:?--memory needs MB}"; shift 2 ;;
    --keep) keep="${2:?--keep needs a folder}"; shift 2 ;;
    --python) python=1; shift ;;
    -h | --help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --) shift; break ;;
    -*) usage_error "unknown option '$1' (see --help)" ;;
    *) break ;;
  esac
done
[ $# -ge 1 ] || usage_error "no guest script given (see --help)"
guest_script="$1"
shift
[ -f "$guest_script" ] || usage_error "guest script '$guest_script' not found"
for f in "$@"; do
  [ -f "$f" ] || usage_error "file '$f' not found"
  case "$f" in *.py) python=1 ;; esac
done
if [ -z "$memory" ]; then memory=$((python ? 512 : 256)); fi

# Prerequisites: without them the test cannot run here; it is skipped with the fix (exit 77), or
# fails where it is required (CRANEASSIST_CAN_VM_REQUIRED=1: CI, tools/test.sh).
prepare_hint="run tools/can-vm/prepare.sh (installs qemu, busybox-static, can-utils, cpio, python3-can, python3-canmatrix and caches Debian's stock kernel)"
cannot_run() {
  if [ "${CRANEASSIST_CAN_VM_REQUIRED:-0}" = 1 ]; then usage_error "$*"; fi
  say "skipped: $*"
  exit 77
}
missing=()
for tool in qemu-system-x86_64 cpio candump cansend cangen; do
  command -v "$tool" >/dev/null || missing+=("$tool")
done
is_static() {
  local out
  out="$(LC_ALL=C ldd "$1" 2>&1 || true)"
  [ -x "$1" ] && [[ "$out" == *"not a dynamic executable"* ]]
}
busybox=/bin/busybox
is_static "$busybox" || missing+=("a static busybox (package busybox-static)")
# Python in the guest: Debian's own interpreter and packages (never a pyenv or venv one earlier in
# the PATH), python-can and canmatrix importable.
host_python=/usr/bin/python3
if [ "$python" = 1 ]; then
  if [ ! -x "$host_python" ]; then
    missing+=("$host_python (package python3)")
  elif ! "$host_python" -c 'import can.interfaces.socketcan, canmatrix.formats' >/dev/null 2>&1; then
    missing+=("python-can or canmatrix for $host_python (packages python3-can, python3-canmatrix)")
  fi
fi
[ ${#missing[@]} -eq 0 ] || cannot_run "missing ${missing[*]}: $prepare_hint"
release="$(cat "$cache/current" 2>/dev/null || true)"
kdir="$cache/$release"
[ -n "$release" ] && [ -s "$kdir/vmlinuz" ] || cannot_run "no kernel in $cache: $prepare_hint"
for m in can can-raw can-dev vcan; do
  [ -s "$kdir/modules/$m.ko" ] || cannot_run "no $m.ko in $kdir: $prepare_hint"
done

# The kernel: the uncompressed ELF when prepare.sh could extract it (qemu boots it through its PVH
# entry, saving the emulated decompression), else the bzImage.
kernel="$kdir/vmlinuz"
[ -s "$kdir/vmlinux" ] && kernel="$kdir/vmlinux"

# The initramfs: busybox, can-utils, the modules, the files and their libraries, and /init.
if [ -n "$keep" ]; then
  rm -rf "$keep" && mkdir -p "$keep"
  work="$(cd "$keep" && pwd)"
else
  work="$(mktemp -d "${TMPDIR:-/tmp}/can-vm.XXXXXX")"
  trap 'rm -rf "$work"' EXIT
fi
rootfs="$work/rootfs"
mkdir -p "$rootfs"/{bin,sbin,usr/bin,usr/sbin,proc,sys,dev,tmp,lib/modules,tests}
cp "$busybox" "$rootfs/bin/busybox"
cp "$kdir"/modules/*.ko "$rootfs/lib/modules/"
for tool in candump cansend cangen; do cp "$(command -v "$tool")" "$rootfs/usr/bin/"; done
script_name="$(basename "$guest_script")"
cp "$guest_script" "$rootfs/tests/$script_name"
for f in "$@"; do cp "$f" "$rootfs/tests/"; done
copy_libraries() {  # copy_libraries BINARY: its shared libraries (and the loader) at their paths
  local lib
  { ldd "$1" 2>/dev/null || true; } | { grep -o '/[^ ]*' || true; } | sort -u | while read -r lib; do
    [ -e "$rootfs$lib" ] && continue
    mkdir -p "$rootfs$(dirname "$lib")"
    cp -L "$lib" "$rootfs$lib"
  done
}
for b in "$rootfs"/usr/bin/* "$rootfs"/tests/*; do
  if [ -x "$b" ]; then copy_libraries "$b"; fi  # ldd lists nothing for scripts, static binaries
done
# Python (--python): the interpreter, its standard library without what a test never imports
# (the test suite, IDLE, tkinter, the static libpython of config-*, installers, optimised .pyc),
# the C extension modules with their libraries, and from Debian's dist-packages only python-can,
# canmatrix and what their imports need (found by importing can, can.interfaces.socketcan,
# can.io and canmatrix.formats with nothing else on the path). The .pyc files come along with
# their sources' times (tar keeps them), so the guest does not compile at every start.
if [ "$python" = 1 ]; then
  py_bin="$(readlink -f "$host_python")"             # /usr/bin/python3.11
  py_ver="$("$host_python" -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
  py_lib="/usr/lib/python$py_ver"
  py_packages=(can canmatrix attr future past six.py typing_extensions.py pkg_resources)
  mkdir -p "$rootfs/usr/lib/python3/dist-packages"
  cp "$py_bin" "$rootfs$py_bin"
  ln -sf "$(basename "$py_bin")" "$rootfs/usr/bin/python3"
  copy_libraries "$py_bin"
  tar -C /usr/lib -cf - --exclude-vcs --exclude='*.opt-[12].pyc' \
    --exclude="python$py_ver/"{test,idlelib,tkinter,turtledemo,ensurepip,lib2to3,pydoc_data,distutils,venv,curses,dbm} \
    --exclude="python$py_ver/"{config-*,dist-packages,site-packages,sitecustomize.py,turtle.py} \
    --exclude="python$py_ver/"{unittest,wsgiref,xmlrpc} \
    --exclude="python$py_ver/lib-dynload/"{_test*,_ctypes_test*,_xxtest*,xxlimited*,_tkinter*,_curses*,_dbm*,nis*,ossaudiodev*,readline*} \
    --exclude="python$py_ver/lib-dynload/"{_ssl*,_hashlib*,_crypt*,_codecs_*,_multibytecodec*,audioop*,_lsprof*,_xxsub*} \
    "python$py_ver" | tar -C "$rootfs/usr/lib" -xf -
  for so in "$rootfs$py_lib"/lib-dynload/*.so; do copy_libraries "${so#"$rootfs"}"; done
  dist=/usr/lib/python3/dist-packages
  present=()
  for p in "${py_packages[@]}"; do [ -e "$dist/$p" ] && present+=("$p"); done
  tar -C "$dist" -cf - --exclude='*.opt-[12].pyc' --exclude='tests' "${present[@]}" |
    tar -C "$rootfs$dist" -xf -
  # What the guest has must be enough: import it here with nothing else on the path, so that a
  # package a newer python-can or canmatrix needs fails now, by name, not in the guest.
  if ! why="$("$host_python" -I -S -c "import sys, warnings
warnings.simplefilter('ignore')
sys.path[:] = ['$rootfs$py_lib', '$rootfs$py_lib/lib-dynload', '$rootfs$dist']
import can, can.interfaces.socketcan, can.io, canmatrix.formats" 2>&1)"; then
    usage_error "python-can or canmatrix do not import from what run.sh copies for the guest (py_packages in $0): ${why##*$'\n'}"
  fi
fi
# /lib64/ld-linux-x86-64.so.2 is a symlink into /lib on Debian (cp -L copied the file itself).

cat >"$rootfs/init" <<INIT
#!/bin/busybox sh
# Generated by tools/can-vm/run.sh.
/bin/busybox --install -s
export PATH=/bin:/sbin:/usr/bin:/usr/sbin TERM=dumb GTEST_COLOR=no
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev
mount -t tmpfs tmp /tmp
report() {  # report STATUS: to the host through isa-debug-exit (qemu exits with STATUS*2+1)
  printf "\\\\\$(printf %03o "\$1")" | dd of=/dev/port bs=1 seek=244 count=1 2>/dev/null
  poweroff -f
}
setup_failed() { echo "CAN-VM: SETUP FAILED: \$*"; report 126; }
for m in can can-raw can-dev vcan; do
  insmod /lib/modules/\$m.ko || setup_failed "insmod \$m.ko"
done
for i in vcan0 vcan1; do
  ip link add dev \$i type vcan && ip link set up \$i || setup_failed "ip link \$i"
done
echo "CAN-VM: kernel \$(uname -r), vcan0 and vcan1 up at \$(cut -d' ' -f1 /proc/uptime) s after boot"
cd /tests
sh /tests/$script_name </dev/null
status=\$?
echo "CAN-VM: guest script exit status \$status at \$(cut -d' ' -f1 /proc/uptime) s after boot"
[ \$status -le 125 ] || status=125
report \$status
INIT
chmod 755 "$rootfs/init"
(cd "$rootfs" && find . | cpio -o -H newc --quiet) >"$work/initramfs.cpio"
say "kernel $release ($(basename "$kernel")), initramfs $(du -h "$work/initramfs.cpio" | cut -f1), guest script $script_name, files: $*"

# Boot. stdin from /dev/null (qemu would otherwise take the terminal); -no-reboot with panic=-1
# turns a kernel panic into qemu's exit 0, which is not a pass.
log="$work/console.log"
start="$(date +%s.%N)"
# Two emulated CPUs where the host has two cores (multi-threaded TCG: one host thread each), so
# the emulator and the control loop in the guest do not take turns on one CPU
# (CRANEASSIST_CAN_VM_CPUS overrides).
cpus="${CRANEASSIST_CAN_VM_CPUS:-$(($(nproc) >= 2 ? 2 : 1))}"
# The guest's control loop and emulator run in real time on the emulated CPUs, so the host must not
# starve them: where it may (as root, as CI runs), qemu runs at nice -15, a scheduler share about
# 28 times a normal process's, so a busy host (a build beside it, `stress-ng --cpu 2`) slows it
# little. Not SCHED_FIFO: the emulated CPUs may spin, and would then starve the host.
# A nice value weighs only against the processes of the same session where the kernel groups
# sessions (sched_autogroup_enabled, Debian's default): a build or stress-ng started in another
# session (a terminal, `setsid`) gets as much of the CPUs as all of this session together, so
# qemu runs in a session of its own whose group gets the same nice value (/proc/self/autogroup).
# CRANEASSIST_CAN_VM_NICE overrides (0: as the caller).
nice_level="${CRANEASSIST_CAN_VM_NICE:-$([ "$(id -u)" -eq 0 ] && echo -15 || echo 0)}"
set +e
setsid --wait sh -c 'echo "$1" >/proc/self/autogroup 2>/dev/null; shift; exec "$@"' _ "$nice_level" \
  timeout --kill-after=10 "$timeout_s" nice -n "$nice_level" qemu-system-x86_64 -accel tcg,thread=multi -m "$memory" -smp "$cpus" \
  -nodefaults -no-user-config -no-reboot -display none -serial stdio -nic none \
  -kernel "$kernel" -initrd "$work/initramfs.cpio" \
  -append "console=ttyS0 quiet loglevel=3 panic=-1 rdinit=/init ${CRANEASSIST_CAN_VM_APPEND:-}" \
  -device isa-debug-exit,iobase=0xf4,iosize=0x04 </dev/null 2>&1 | while IFS= read -r line; do
  # Echo the console as it comes (unbuffered); note the host time at which vcan was up.
  line="${line%$'\r'}"
  printf '%s\n' "$line"
  printf '%s\n' "$line" >>"$log"
  case "$line" in "CAN-VM: kernel "*) date +%s.%N >"$work/ready" ;; esac
done
rc="${PIPESTATUS[0]}"
set -e
end="$(date +%s.%N)"
elapsed="$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')"
if [ -s "$work/ready" ]; then
  say "timing: boot to vcan up $(awk -v a="$start" -v b="$(cat "$work/ready")" 'BEGIN { printf "%.1f", b - a }') s, then guest script and power-off $(awk -v a="$(cat "$work/ready")" -v b="$end" 'BEGIN { printf "%.1f", b - a }') s (wall time)"
fi

if [ "$rc" -eq 124 ] || [ "$rc" -eq 137 ]; then
  say "FAIL: timed out after $timeout_s s (qemu killed)"
  exit 124
elif [ "$rc" -eq 1 ]; then
  say "PASS: guest script $script_name exited 0 (qemu ran $elapsed s)"
  exit 0
elif [ $((rc % 2)) -eq 1 ] && [ "$rc" -gt 1 ]; then
  status=$(((rc - 1) / 2))
  if [ "$status" -eq 126 ]; then
    say "FAIL: the guest's set-up failed (modules or vcan; see above) (qemu ran $elapsed s)"
  else
    say "FAIL: guest script $script_name exited $status (qemu ran $elapsed s)"
  fi
  exit 1
else
  say "FAIL: the guest never reported a result (qemu exit $rc: kernel panic or crash?) (qemu ran $elapsed s)"
  if grep -q "Initramfs unpacking failed" "$log" 2>/dev/null; then
    say "the initramfs ($(du -h "$work/initramfs.cpio" | cut -f1)) did not fit in the guest's $memory MB: raise --memory"
  fi
  exit 3
fi
