#!/usr/bin/env bash
# Short hydrostatic tank (H/dx = 50 as in validation.md, to t sqrt(g/H) = 5) through the CLI and its check.
set -euo pipefail
RHOD=$1; SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
"$RHOD" run "$SRC/cases/hydrostatic/scene.yaml" -o "$OUT" \
  --set time.end=1.5965 --set time.output_every=0.3193 >/dev/null 2>&1
/usr/bin/python3 "$SRC/cases/hydrostatic/check" "$OUT"
