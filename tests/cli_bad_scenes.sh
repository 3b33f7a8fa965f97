#!/usr/bin/env bash
# Every malformed or contradictory scene of tests/scenes/bad through the command line:
# exit 4 (invalid scene; 3 where the file itself cannot be read as a scene), one
# line on stderr naming the file and the key, and an output folder that already holds a
# run left exactly as it was (test_scene checks each message's line, key and reason).
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
# a previous run's folder, to be left alone by every failing run
"$RHOD" run "$SRC/tests/scenes/run/periodic_uniform.yaml" -o "$T/out" >/dev/null 2>&1 ||
  { echo "FAIL: setting up the previous run"; exit 1; }
(cd "$T/out" && find . -type f -exec sha256sum {} + | sort) >"$T/before"
n=0
for scene in "$SRC"/tests/scenes/bad/*.yaml; do
  name=$(basename "$scene")
  n=$((n + 1))
  "$RHOD" run "$scene" -o "$T/out" >"$T/stdout" 2>"$T/stderr"
  code=$?
  lines=$(wc -l <"$T/stderr")
  if [ $code -ne 4 ] && [ $code -ne 3 ]; then
    echo "FAIL: $name: exit $code, expected 4 (invalid scene) or 3 (unreadable)"; fail=$((fail + 1))
  elif [ "$lines" -ne 1 ] || ! grep -q "$name" "$T/stderr"; then
    echo "FAIL: $name: not one line naming the file:"; cat "$T/stderr"; fail=$((fail + 1))
  elif [ -s "$T/stdout" ]; then
    echo "FAIL: $name: wrote to stdout"; fail=$((fail + 1))
  else
    pass=$((pass + 1))
  fi
done
(cd "$T/out" && find . -type f -exec sha256sum {} + | sort) >"$T/after"
if cmp -s "$T/before" "$T/after"; then pass=$((pass + 1)); else
  echo "FAIL: a failing run changed the output folder"; diff "$T/before" "$T/after" | head; fail=$((fail + 1))
fi
[ $n -ge 30 ] || { echo "FAIL: only $n bad scenes (30 wanted)"; fail=$((fail + 1)); }
summary "$n bad scenes"
