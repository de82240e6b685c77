#!/usr/bin/env bash
# Prepares the SocketCAN test VM (docs/can-vm.md): installs qemu, busybox, can-utils, cpio,
# python3-can and python3-canmatrix from Debian's packages when missing, downloads Debian's
# current stock kernel package (the one linux-image-amd64 depends on; never a fixed version) and
# extracts the kernel image and the four CAN modules (can, can-raw, can-dev, vcan) into the
# cache. A complete cache is reused as it is.
#
#   tools/can-vm/prepare.sh [--refresh]
#
#   --refresh   look up the current stock kernel again and fetch it if the cache holds another
#
# The cache is $CRANEASSIST_CAN_VM_CACHE, default build/can-vm-cache in the repository.
set -euo pipefail

say() { echo "can-vm prepare: $*" >&2; }
die() { say "error: $*"; exit 1; }

root="$(cd "$(dirname "$0")/../.." && pwd)"
cache="${CRANEASSIST_CAN_VM_CACHE:-$root/build/can-vm-cache}"
refresh=0
for arg in "$@"; do
  case "$arg" in
    --refresh) refresh=1 ;;
    -h | --help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown argument '$arg' (see --help)" ;;
  esac
done

sudo_cmd=()
need_root() {
  if [ "$(id -u)" -ne 0 ] && [ ${#sudo_cmd[@]} -eq 0 ]; then
    command -v sudo >/dev/null || die "apt-get needs root here: run as root or install sudo"
    sudo_cmd=(sudo)
  fi
}
apt_updated=0
apt_update() {
  if [ "$apt_updated" -eq 0 ]; then
    need_root
    say "apt-get update"
    "${sudo_cmd[@]}" apt-get update -qq
    apt_updated=1
  fi
}

# 1. Host tools: qemu (TCG emulation, no KVM needed), a static busybox for the guest, can-utils
#    (candump, cansend, cangen) as the independent peer on the bus, cpio for the initramfs;
#    python-can and canmatrix for the Python peer that run.sh --python copies into the guest with
#    Debian's python3 (tests/can_vm/valve_peer.py).
packages=(qemu-system-x86 busybox-static can-utils cpio python3-can python3-canmatrix)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  say "installing ${missing[*]}"
  need_root
  apt_update
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
fi

# 2. The kernel. cache/current names the kernel release in use; cache/<release>/ holds vmlinuz and
#    modules/{can,can-raw,can-dev,vcan}.ko.
modules=(can can-raw can-dev vcan)
complete() {  # complete RELEASE: is that kernel fully in the cache?
  local d="$cache/$1" m
  [ -s "$d/vmlinuz" ] || return 1
  for m in "${modules[@]}"; do [ -s "$d/modules/$m.ko" ] || return 1; done
}
if [ "$refresh" -eq 0 ] && [ -s "$cache/current" ] && complete "$(cat "$cache/current")"; then
  say "using the cached kernel $(cat "$cache/current") in $cache"
  exit 0
fi

kernel_package() {
  apt-cache depends linux-image-amd64 2>/dev/null |
    awk '/Depends: linux-image-[0-9]/ { sub(/-unsigned$/, "", $2); print $2; exit }'
}
kpkg="$(kernel_package)"
if [ -z "$kpkg" ] || [ "$refresh" -eq 1 ]; then
  apt_update
  kpkg="$(kernel_package)"
fi
[ -n "$kpkg" ] || die "apt-cache does not know linux-image-amd64 (is a Debian archive in apt's sources?)"
release="${kpkg#linux-image-}"
if complete "$release"; then
  echo "$release" >"$cache/current"
  say "using the cached kernel $release in $cache"
  exit 0
fi

say "downloading $kpkg (the stock kernel linux-image-amd64 depends on)"
mkdir -p "$cache"
work="$(mktemp -d "$cache/.download.XXXXXX")"
trap 'rm -rf "$work"' EXIT
# apt-get download as root warns that the download is unsandboxed; the file lands in $work.
(cd "$work" && chmod 755 . && apt-get download -qq "$kpkg" 2>&1 | grep -v -i 'unsandboxed' >&2 || true)
deb="$(ls "$work"/*.deb 2>/dev/null | head -n 1)"
[ -n "$deb" ] || die "apt-get download $kpkg fetched nothing"

# Extract only what the guest needs (the kernel image and four modules, some MB of a ~70 MB
# package). Newer Debian kernels ship compressed modules (.ko.xz, .ko.zst): decompress here,
# busybox's insmod takes plain .ko files.
mkdir -p "$work/x"
dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$work/x" --wildcards --no-anchored \
  "vmlinuz-$release" "net/can/can.ko*" "net/can/can-raw.ko*" "drivers/net/can/dev/can-dev.ko*" \
  "drivers/net/can/vcan.ko*"
dest="$work/$release"
mkdir -p "$dest/modules"
vmlinuz="$(find "$work/x" -name "vmlinuz-$release" | head -n 1)"
[ -n "$vmlinuz" ] || die "$kpkg holds no vmlinuz-$release"
cp "$vmlinuz" "$dest/vmlinuz"
for m in "${modules[@]}"; do
  f="$(find "$work/x" -name "$m.ko*" | head -n 1)"
  [ -n "$f" ] || die "$kpkg holds no $m.ko: its kernel has no CAN support?"
  case "$f" in
    *.ko) cp "$f" "$dest/modules/$m.ko" ;;
    *.ko.xz) xz -dc "$f" >"$dest/modules/$m.ko" ;;
    *.ko.zst) zstd -qdc "$f" >"$dest/modules/$m.ko" ;;
    *.ko.gz) gzip -dc "$f" >"$dest/modules/$m.ko" ;;
    *) die "unknown module compression: $f" ;;
  esac
done

# Boot time: under TCG, decompressing the ~8 MB bzImage takes the emulated CPU about 3.5 s of the
# boot. The kernel inside it is an ELF with a PVH entry note (Debian sets CONFIG_PVH), which qemu
# boots directly: keep it decompressed as vmlinux (~65 MB) and run.sh prefers it.
extract_vmlinux() {  # extract_vmlinux BZIMAGE OUT: find the compressed payload, decompress it
  local img="$1" out="$2" magic tool offset
  for pair in 'fd377a585a00:xz -dc' '28b52ffd:zstd -qdc' '1f8b0800:gzip -dc'; do
    magic="${pair%%:*}"
    tool="${pair#*:}"
    command -v "${tool%% *}" >/dev/null || continue
    for offset in $(LC_ALL=C grep -obUaP "$(echo "$magic" | sed 's/../\\x&/g')" "$img" | cut -d: -f1); do
      tail -c "+$((offset + 1))" "$img" | $tool >"$out" 2>/dev/null || true
      if [ "$(head -c 4 "$out" | od -An -tx1 | tr -d ' ')" = "7f454c46" ] &&
        readelf -n "$out" 2>/dev/null | grep -q 'Unknown note type: (0x00000012)'; then
        return 0
      fi
    done
  done
  rm -f "$out"
  return 1
}
if command -v readelf >/dev/null && extract_vmlinux "$dest/vmlinuz" "$dest/vmlinux"; then
  say "extracted the uncompressed kernel (PVH boot, about 3.5 s faster under emulation)"
else
  say "note: could not extract an uncompressed PVH kernel; booting the compressed one (slower)"
fi

rm -rf "${cache:?}/$release"
mv "$dest" "$cache/$release"
echo "$release" >"$cache/current"
say "kernel $release ready in $cache ($(du -sh "$cache/$release" | cut -f1))"
