#!/usr/bin/env bash
# Runs a validation case coarsely and its check: run_case.sh RHOD SRC CASE [--set k=v]...
# (the coarse settings of each case are listed in tests/CMakeLists.txt).
set -euo pipefail
RHOD=$1; SRC=$2; CASE=$3; shift 3
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
if ! "$RHOD" run "$SRC/cases/$CASE/scene.yaml" -o "$OUT" "$@" >"$OUT/.stdout" 2>&1; then
  tail -5 "$OUT/.stdout"
  exit 1
fi
"${PYTHON:-/usr/bin/python3}" "$SRC/cases/$CASE/check" "$OUT"
