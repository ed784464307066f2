# Helpers of the command-line test scripts (sourced): pass/fail counters and `expect`.
failures=0
passes=0
pass() { passes=$((passes + 1)); }
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# expect CODE PATTERN -- command...: exit code CODE and stderr+stdout matching PATTERN
expect() {
  local code=$1 pattern=$2
  shift 3
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  if [ "$rc" -ne "$code" ]; then fail "'$*' exited $rc, expected $code: $out"; return; fi
  if ! grep -qE -- "$pattern" <<<"$out"; then fail "'$*' output does not match '$pattern': $out"; return; fi
  pass
}

# enter_workdir DIR: a fresh, empty DIR as the working directory.
enter_workdir() {
  rm -rf "$1" && mkdir -p "$1" && cd "$1" || exit 1
}
