# What the bad-input tests share; source it after setting $bin (the craneassist executable) and
# $work (a folder for the outputs):
#   expect NAME MESSAGE ARGS...   craneassist ARGS must exit 2 and print MESSAGE (a fixed
#                                 string); its output goes to $work/NAME.txt
# $failed is 1 once an expectation failed.
failed=0
expect() {
  name=$1 message=$2
  shift 2
  "$bin" "$@" > "$work/$name.txt" 2>&1 < /dev/null
  code=$?
  if [ "$code" -ne 2 ]; then
    echo "$name: exit code $code, expected 2"
    failed=1
  fi
  if ! grep -qF -e "$message" "$work/$name.txt"; then
    echo "$name: no '$message' in:"
    cat "$work/$name.txt"
    failed=1
  fi
}
