#!/usr/bin/env bash
# Runs a validation case coarsely and its check:
#   run_case.sh RHOD SRC CASE [--scene FILE] [--check-arg ARG]... [--set k=v]...
# (scene.yaml of the case unless --scene; each --check-arg is passed on to the case's
# check after the output folder; the coarse settings are listed in tests/CMakeLists.txt).
set -euo pipefail
RHOD=$1; SRC=$2; CASE=$3; shift 3
SCENE=scene.yaml
CHECK_ARGS=()
while [ $# -gt 0 ]; do
  case $1 in
  --scene) SCENE=$2; shift 2 ;;
  --check-arg) CHECK_ARGS+=("$2"); shift 2 ;;
  *) break ;;
  esac
done
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
OUT=$TMP/out
if ! "$RHOD" run "$SRC/cases/$CASE/$SCENE" -o "$OUT" "$@" >"$TMP/stdout" 2>&1; then
  tail -5 "$TMP/stdout"
  exit 1
fi
"${PYTHON:-/usr/bin/python3}" "$SRC/cases/$CASE/check" "$OUT" "${CHECK_ARGS[@]}"
