# Shared by the command-line tests (source it after setting $work): failures are counted, not
# fatal, so that one run reports every broken promise; the sourcing script ends by exiting
# non-zero when $failures is not 0.
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
expect_exit() {  # expect_exit CODE DESCRIPTION -- COMMAND...: stdout to $work/out, stderr to $work/err
  local want=$1 what=$2; shift 3
  "$@" >"$work/out" 2>"$work/err"
  local got=$?
  [ "$got" -eq "$want" ] || fail "$what: exit $got, want $want; stderr: $(head -c 400 "$work/err")"
}
expect_stderr() {  # expect_stderr TEXT DESCRIPTION: the last command's stderr holds TEXT
  grep -qF -- "$1" "$work/err" || fail "$2: stderr lacks '$1': $(head -c 400 "$work/err")"
}
