# What the shell tests of the DDS tools and the interop tests share; source it after `set -eu`:
#   . "$(dirname "$0")/../cli/test_lib.sh"
# A work folder ($work), a background process ($bg_pid) stopped and the folder removed at exit,
# fail MESSAGE, has FILE TEXT (FILE in $work must contain TEXT), wait_ready FILE OTHER (until
# FILE in $work says "ready", 5 s at most; on failure FILE and OTHER are shown).
#
# Under AddressSanitizer (CRANEASSIST_SANITIZE): Debian's Fast DDS 2.9 (not instrumented) deletes
# the statistics part of each DataReader with a mismatched size (new-delete-type-mismatch when a
# subscriber exits). Not our code; the caller's other options stay. Without the sanitizers this
# does nothing.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}new_delete_type_mismatch=0"
work=$(mktemp -d)
bg_pid=
cleanup() {
  [ -n "$bg_pid" ] && kill -TERM "$bg_pid" 2>/dev/null && wait "$bg_pid" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; exit 1; }
has() { grep -q -F -- "$2" "$work/$1" || { cat "$work/$1"; fail "no '$2' in $1"; }; }
wait_ready() {
  i=0
  until grep -q "ready" "$work/$1" 2>/dev/null; do
    i=$((i + 1))
    [ $i -lt 100 ] || { cat "$work/$1" "$work/$2"; fail "not ready: $1"; }
    sleep 0.05
  done
}
