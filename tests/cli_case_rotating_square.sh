#!/usr/bin/env bash
# Coarse rotating square patch (L/dx = 40, to t sigma0 = 3) and its check.
set -euo pipefail
RHOD=$1; SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
"$RHOD" run "$SRC/cases/rotating_square/scene.yaml" -o "$OUT" --set particles.dx=0.025 \
  --set time.end=3 --set time.output_every=1 >/dev/null 2>&1
/usr/bin/python3 "$SRC/cases/rotating_square/check" "$OUT"
