# What the terminal tests share (a detached tmux session, keys sent with send-keys, the screen
# read with capture-pane). Name the session, then source it after `set -eu`:
#   session=NAME; . "$(dirname "$0")/tmux_lib.sh"
# It gives a work folder ($work) holding the tmux server's socket ($sock), removed with the
# server at exit after the caller's on_exit (define it to stop processes of its own), and
#   pane                 the screen without its blank lines
#   keys KEYS...         tmux send-keys to the session
#   fail MESSAGE         say it with the pane and exit 1
#   wait_for TEXT SECS   until the pane shows TEXT (a fixed string), else fail
#   wait_for_gone TEXT SECS  until the pane no longer shows TEXT, else fail
command -v tmux >/dev/null || { echo "tmux is not installed (tools/install-deps.sh)"; exit 1; }
work=$(mktemp -d)
sock="$work/tmux.sock"
on_exit() { :; }
cleanup() {
  on_exit
  tmux -S "$sock" kill-server 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

pane() { tmux -S "$sock" capture-pane -p -t "$session" | grep -v "^ *$"; }
keys() { tmux -S "$sock" send-keys -t "$session" "$@"; }
fail() { echo "FAIL: $*; the pane:"; pane; exit 1; }
wait_for() {
  i=0
  while ! pane | grep -q -F -- "$1"; do
    i=$((i + 1))
    [ $i -le $(($2 * 10)) ] || fail "timed out waiting for '$1'"
    sleep 0.1
  done
}
wait_for_gone() {
  i=0
  while pane | grep -q -F -- "$1"; do
    i=$((i + 1))
    [ $i -le $(($2 * 10)) ] || fail "timed out waiting for '$1' to leave the screen"
    sleep 0.1
  done
}
