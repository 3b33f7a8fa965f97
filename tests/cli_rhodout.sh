#!/usr/bin/env bash
# tools/rhodout.py as a command: after a tiny run, `python3 tools/rhodout.py OUT` prints
# the summary and writes OUT/probes.png (one panel per probe); a missing folder is an
# error; the module still serves the cases' scripts (import rhodout).
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
PY=/usr/bin/python3
TOOL=$SRC/tools/rhodout.py
expect 0 "a tiny run" -- "$RHOD" run "$SRC/tests/scenes/run/periodic_uniform.yaml" \
  --set time.end=0.04 --set time.output_every=0.02 -o "$T/out"
expect 0 "rhodout.py OUT" -- "$PY" "$TOOL" "$T/out"
check "the summary: status" -- grep -q "^$T/out: ok$" "$T/stdout"
check "the summary: time, steps, particles" -- grep -qE "time 0.04 s, [0-9]+ steps, 400 particles" "$T/stdout"
check "the summary: wall time" -- grep -q "wall time" "$T/stdout"
check "probes.png written" -- test -s "$T/out/probes.png"
check "probes.png is a PNG" -- bash -c "head -c 8 '$T/out/probes.png' | od -An -c | grep -q 'P   N   G'"
check "momentum's two columns share a panel" -- "$PY" -c "
import sys; sys.path.insert(0, '$SRC/tools'); import rhodout
g = rhodout.probe_groups(['t', 'P_x', 'P_y', 'mass', 'ke'])
assert g == [('P', ['P_x', 'P_y']), ('mass', ['mass']), ('ke', ['ke'])], g
assert rhodout.probes('$T/out')['mass'].shape[0] >= 2"
expect 2 "a missing folder" -- "$PY" "$TOOL" "$T/nothing"
check "names the folder" -- grep -q "nothing: not a folder" "$T/stderr"
summary "rhodout.py"
