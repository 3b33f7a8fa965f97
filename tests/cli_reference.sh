#!/usr/bin/env bash
# RHOD-SPH's results held while the engine changes (issue 50, "RHOD-SPH unchanged"):
# short runs of every RHOD case and APR scene against the figures stored in
# tests/reference/ (refcompare.py: per snapshot and field sums, extremes and sampled
# particles within 1e-12 of their scale; the last probes to their 9 printed digits).
# Double precision only (the references are double runs). When a change of results is
# intended, RHOD_REF_UPDATE=1 rewrites the references; say why in the commit.
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
REF=$SRC/tests/reference
if "$RHOD" --version | grep -q "single precision"; then
  echo "reference: single precision build: the references are double runs, not compared"
  summary reference
  exit $?
fi
run_ref() { # run_ref NAME SCENE ARGS...
  local name=$1 scene=$2; shift 2
  expect 0 "$name: run" -- "$RHOD" run "$SRC/cases/$scene" -o "$T/$name" "$@"
  if [ "${RHOD_REF_UPDATE:-0}" = 1 ]; then
    /usr/bin/python3 "$REF/refcompare.py" "$T/$name" "$REF/$name.txt" --update
  else
    check "$name: as the reference" -- /usr/bin/python3 "$REF/refcompare.py" "$T/$name" "$REF/$name.txt"
  fi
}
run_ref hydrostatic hydrostatic/scene.yaml --set particles.dx=0.05 --set time.end=0.2 \
  --set time.output_every=0.1
run_ref taylor_green taylor_green/scene.yaml --set particles.dx=0.05 --set time.end=0.2 \
  --set time.output_every=0.1
run_ref rotating_square rotating_square/scene.yaml --set particles.dx=0.05 --set time.end=0.3 \
  --set time.output_every=0.15
run_ref dam_break dam_break/scene.yaml --set particles.dx=0.00584 --set time.end=0.05 \
  --set time.output_every=0.025
run_ref dam_break_lobovsky dam_break_lobovsky/scene.yaml --set particles.dx=0.012 \
  --set time.end=0.1 --set time.output_every=0.05
run_ref hydrostatic_apr hydrostatic_apr/scene.yaml --set time.end=0.05 --set time.output_every=0.025
run_ref rotating_square_apr rotating_square/scene_apr.yaml --set time.end=0.1 \
  --set time.output_every=0.05
run_ref dam_break_lobovsky_apr dam_break_lobovsky/scene_apr.yaml --set time.end=0.05 \
  --set time.output_every=0.025
summary reference
