# Shared by the command-line tests (sourced, not run): a scratch folder $T removed at
# exit, and the two checks. expect CODE WHAT -- command...: the exit code (stdout and
# stderr left in $T/stdout, $T/stderr); check WHAT -- command...: the command succeeds.
# Each counts into $pass / $fail; the test ends with `summary NAME`.
T=$(mktemp -d)
trap 'chmod -R u+w "$T"; rm -rf "$T"' EXIT
fail=0; pass=0
expect() {
  local code=$1 what=$2; shift 3
  "$@" >"$T/stdout" 2>"$T/stderr"; local got=$?
  if [ "$got" -ne "$code" ]; then
    echo "FAIL: $what: exit $got, expected $code"; tail -3 "$T/stderr"; fail=$((fail + 1))
  else pass=$((pass + 1)); fi
}
check() {
  local what=$1; shift 2
  if "$@"; then pass=$((pass + 1)); else echo "FAIL: $what"; fail=$((fail + 1)); fi
}
summary() {
  echo "$1: $pass passed, $fail failed"
  [ "$fail" -eq 0 ]
}
