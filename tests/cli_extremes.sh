#!/usr/bin/env bash
# The extremes of tests/EXTREMES.md that single resolution can run: each scene of
# tests/scenes/extremes either runs to its end (exit 0) or stops with its cause named
# (exit 6, "unstable at t = ...: particle ... <cause>"), and no snapshot holds a value
# that is not finite. Prints one line per scene: the outcome for the table.
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
for scene in "$SRC"/tests/scenes/extremes/*.yaml; do
  name=$(basename "$scene" .yaml)
  "$RHOD" run "$scene" -o "$T/$name" >"$T/$name.out" 2>"$T/$name.err"
  code=$?
  if [ $code -eq 0 ]; then
    echo "$name: ran to its end ($(grep -o 'done: .*' "$T/$name.out"))"
    pass=$((pass + 1))
  elif [ $code -eq 6 ] && grep -q "unstable at t = .*particle id" "$T/$name.err"; then
    echo "$name: stopped: $(grep -o 'unstable at .*' "$T/$name.err" | head -1)"
    pass=$((pass + 1))
  else
    echo "FAIL: $name: exit $code"; tail -3 "$T/$name.err"; fail=$((fail + 1))
  fi
  check "$name: every snapshot finite" -- /usr/bin/python3 - "$T/$name" "$SRC" <<'PY'
import sys
sys.path.insert(0, sys.argv[2] + "/tools")
import numpy as np
import rhodout
snaps = rhodout.snapshots(sys.argv[1])
for s in snaps:
    d = rhodout.read_snapshot(s)
    for k in ("pos", "vel", "rho", "p"):
        if not np.all(np.isfinite(d[k])):
            sys.exit(f"{s}: {k} not finite")
sys.exit(0 if snaps else "no snapshot")
PY
done
summary extremes
