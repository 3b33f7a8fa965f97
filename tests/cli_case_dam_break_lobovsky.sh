#!/usr/bin/env bash
# Coarse Lobovsky dam break (H/dx = 25, to t sqrt(g/H) = 4): P1 reached, energy not
# growing; prints the impact time and first peak.
set -euo pipefail
RHOD=$1; SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
"$RHOD" run "$SRC/cases/dam_break_lobovsky/scene.yaml" -o "$OUT" --set particles.dx=0.012 \
  --set time.end=0.7 --set time.output_every=0.35 >/dev/null 2>&1
/usr/bin/python3 "$SRC/cases/dam_break_lobovsky/check" "$OUT"
