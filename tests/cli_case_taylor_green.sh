#!/usr/bin/env bash
# Coarse Taylor-Green vortex (L/dx = 50, to t = 1) and its kinetic-energy check.
set -euo pipefail
RHOD=$1; SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
"$RHOD" run "$SRC/cases/taylor_green/scene.yaml" -o "$OUT" --set particles.dx=0.02 \
  --set time.output_every=0.5 >/dev/null 2>&1
/usr/bin/python3 "$SRC/cases/taylor_green/check" "$OUT"
