#!/usr/bin/env bash
# Coarse dam break (L/dx = 25) to just after the wall impact, and its surge-front check.
set -euo pipefail
RHOD=$1; SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
"$RHOD" run "$SRC/cases/dam_break/scene.yaml" -o "$OUT" --set particles.dx=0.00584 \
  --set time.end=0.3 --set time.output_every=0.1 >/dev/null 2>&1
/usr/bin/python3 "$SRC/cases/dam_break/check" "$OUT"
