#!/usr/bin/env bash
# Hostile inputs (robustness round 2): a scene or checkpoint that is a device, a FIFO or a
# directory, a scene too large or whose aliases expand to gigabytes, a probes.csv shorter
# than its checkpoint recorded, an escaped NUL, long --set values and control characters
# in what a message quotes. Each must end quickly (timeout 10) with its exit code and one
# line on stderr, and a refused resume must leave the output folder as it was.
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
one_line() { [ "$(wc -l <"$T/stderr")" -eq 1 ] || { cat "$T/stderr" | head -5; return 1; }; }
says() { grep -qF -- "$1" "$T/stderr" || { echo "  wanted: $1"; cat "$T/stderr"; return 1; }; }
MIN="$SRC/tests/scenes/good/minimal.yaml"

# ---- A. reads are bounded -------------------------------------------------------------
expect 3 "scene /dev/zero" -- timeout 10 "$RHOD" run /dev/zero -o "$T/o"
check "/dev/zero: one line, not a regular file" -- says "/dev/zero: cannot read: not a regular file"
check "/dev/zero: one line" -- one_line
ln -s /dev/zero "$T/zero.yaml"
expect 3 "scene symlink to /dev/zero" -- timeout 10 "$RHOD" run "$T/zero.yaml" -o "$T/o"
check "symlink: not a regular file" -- says "zero.yaml: cannot read: not a regular file"
mkfifo "$T/fifo.yaml"
expect 3 "scene FIFO without a writer (must not block)" -- \
  timeout 10 "$RHOD" run "$T/fifo.yaml" -o "$T/o"
check "FIFO: not a regular file" -- says "fifo.yaml: cannot read: not a regular file"
exec 3<>"$T/fifo.yaml" # a writer that never closes
expect 3 "scene FIFO with a writer that never closes" -- \
  timeout 10 "$RHOD" run "$T/fifo.yaml" -o "$T/o"
check "FIFO with a writer: one line" -- one_line
exec 3>&-
expect 3 "scene is a directory" -- timeout 10 "$RHOD" run "$T" -o "$T/o"
check "directory: named as such" -- says "not a regular file"
# larger than 16 MiB (an invalid scene otherwise: exit 4 if it were read)
{ echo "time: {end: 1}"; head -c $((17 * 1024 * 1024)) /dev/zero | tr '\0' '#'; echo; } \
  >"$T/big.yaml"
expect 3 "scene larger than 16 MiB" -- timeout 10 "$RHOD" run "$T/big.yaml" -o "$T/o"
check "big scene: the limit named" -- \
  says "big.yaml: cannot read: larger than 16 MiB, the limit for a scene"
rm -f "$T/big.yaml"
# aliases: 2 nodes of text, ~100 nodes per level, but 10 KB x 100^3 = 10 GB expanded
{
  printf 'a: &a "%s"\n' "$(head -c 10000 /dev/zero | tr '\0' 'x')"
  printf 'b: &b [*a'; for _ in $(seq 99); do printf ', *a'; done; printf ']\n'
  printf 'c: &c [*b'; for _ in $(seq 99); do printf ', *b'; done; printf ']\n'
  printf 'd: &d [*c'; for _ in $(seq 99); do printf ', *c'; done; printf ']\n'
} >"$T/laughs.yaml"
# under a 2 GB address-space limit when the build allows one (an ASan build does not)
if (ulimit -v 2000000 && "$RHOD" --version) >/dev/null 2>&1; then LIM=2000000; else LIM=unlimited; fi
expect 4 "aliases expanding to gigabytes of text" -- \
  bash -c 'ulimit -v "$1" && exec timeout 10 "$2" run "$3" -o "$4"' _ "$LIM" "$RHOD" \
  "$T/laughs.yaml" "$T/o"
check "aliases: line:col and the cap" -- says "laughs.yaml:3:"
check "aliases: the cap named" -- says "aliases expand to more than 64 MiB of text"
check "aliases: one line" -- one_line

# ---- resume: checkpoint and probes.csv ------------------------------------------------
expect 0 "a short run with checkpoints" -- \
  "$RHOD" run "$SRC/tests/scenes/run/periodic_uniform.yaml" -o "$T/run" --checkpoint-every 0.05
snap() { (cd "$1" && find . -type f -exec sha256sum {} + | sort); }
fresh() { rm -rf "$T/r"; cp -r "$T/run" "$T/r"; }
fresh; rm "$T/r/checkpoint.rhod"; mkfifo "$T/r/checkpoint.rhod"
expect 10 "checkpoint.rhod a FIFO (must not block)" -- timeout 10 "$RHOD" resume "$T/r"
check "FIFO checkpoint: not a regular file" -- \
  says "checkpoint.rhod: cannot read the checkpoint: not a regular file"
check "FIFO checkpoint: one line" -- one_line
exec 3<>"$T/r/checkpoint.rhod"
expect 10 "checkpoint.rhod a FIFO with a writer" -- timeout 10 "$RHOD" resume "$T/r"
exec 3>&-
rm "$T/r/checkpoint.rhod"; ln -s /dev/zero "$T/r/checkpoint.rhod"
expect 10 "checkpoint.rhod a symlink to /dev/zero" -- timeout 10 "$RHOD" resume "$T/r"
check "/dev/zero checkpoint: not a regular file" -- says "not a regular file"
rm "$T/r/checkpoint.rhod"; mkdir "$T/r/checkpoint.rhod"
expect 10 "checkpoint.rhod a directory" -- timeout 10 "$RHOD" resume "$T/r"

# probes.csv shorter than the checkpoint recorded: refused, not padded with NULs, and
# nothing in the folder changed
fresh; truncate -s 100 "$T/r/probes.csv"; snap "$T/r" >"$T/before"
expect 10 "probes.csv shorter than recorded" -- timeout 10 "$RHOD" resume "$T/r"
check "short probes.csv: sizes named" -- says "probes.csv: 100 bytes, shorter than the"
check "short probes.csv: one line" -- one_line
check "short probes.csv: not padded" -- test "$(wc -c <"$T/r/probes.csv")" -eq 100
check "short probes.csv: no NUL in it" -- test "$(tr -d '\000' <"$T/r/probes.csv" | wc -c)" -eq 100
snap "$T/r" >"$T/after"
check "refused resume changed nothing (summary.json, run.log...)" -- cmp -s "$T/before" "$T/after"
fresh; rm "$T/r/probes.csv"
expect 10 "probes.csv missing" -- timeout 10 "$RHOD" resume "$T/r"
check "missing probes.csv named" -- says "probes.csv: missing"
fresh; rm "$T/r/probes.csv"; mkfifo "$T/r/probes.csv"
expect 10 "probes.csv a FIFO (must not block)" -- timeout 10 "$RHOD" resume "$T/r"
check "FIFO probes.csv: not a regular file" -- says "probes.csv: not a regular file"
fresh; sed -i '1s/^t,/time,/' "$T/r/probes.csv"
expect 10 "probes.csv with another header" -- timeout 10 "$RHOD" resume "$T/r"
fresh; sed -i '2s/^/0/' "$T/r/probes.csv" # one byte more in the first row: rows shift
expect 10 "probes.csv whose recorded length does not end a row" -- timeout 10 "$RHOD" resume "$T/r"
check "row end named" -- says "does not end a row"
fresh
expect 0 "the untouched folder still resumes" -- timeout 60 "$RHOD" resume "$T/r"
check "resumed probes.csv equals the uninterrupted one" -- cmp -s "$T/run/probes.csv" "$T/r/probes.csv"

# ---- C. the scene loader's messages ---------------------------------------------------
cp "$MIN" "$T/nul.yaml"; printf 'name: "a\\0b"\n' >>"$T/nul.yaml"
expect 4 "an escaped NUL in a string" -- "$RHOD" run "$T/nul.yaml" -o "$T/o"
check "NUL: line:col and the reason" -- says "nul.yaml:11:7: name: a NUL character"
cp "$MIN" "$T/nulkey.yaml"; printf '"x\\0y": 1\n' >>"$T/nulkey.yaml"
expect 4 "an escaped NUL in a key" -- "$RHOD" run "$T/nulkey.yaml" -o "$T/o"
check "NUL key: line:col" -- says "nulkey.yaml:11:1:"
expect 4 "an escaped NUL in a --set value" -- "$RHOD" run "$MIN" -o "$T/o" --set 'name="a\0b"'
check "NUL --set: the override named" -- says "--set name=\"a\\0b\": name: invalid YAML value: a NUL"
for n in 300 5000 100000; do
  long=$(head -c $n /dev/zero | tr '\0' 'a')
  for kv in "name=$long:longer than 64 characters" \
    "particles.kernel=$long:invalid value 'aaaa" "physics.rho0=$long:invalid number 'aaaa" \
    "fluid.0.rect.min=$long:expected a list of 2 numbers"; do
    key=${kv%%=*}; why=${kv##*:}; val=${kv#*=}; val=${val%:*}
    expect 4 "--set $key with $n characters" -- "$RHOD" run "$MIN" -o "$T/o" --set "$key=$val"
    check "--set $key ($n): names the override, not the scene file" -- says "rhod: --set $key=aaaa"
    check "--set $key ($n): the reason kept" -- says ": $key: $why"
    check "--set $key ($n): no scene line" -- bash -c "! grep -q 'minimal.yaml' '$T/stderr'"
    check "--set $key ($n): one short line" -- \
      test "$(wc -l <"$T/stderr")" -eq 1 -a "$(wc -c <"$T/stderr")" -lt 600
  done
done
long=$(head -c 5000 /dev/zero | tr '\0' '1')
expect 4 "--set a 5000-digit number" -- "$RHOD" run "$MIN" -o "$T/o" --set "physics.rho0=$long"
check "5000 digits: out of range, at the override" -- says "--set physics.rho0=1111"

# control characters in quoted user text come out escaped, on one line
cp "$MIN" "$T/ctl.yaml"; printf '"bad\\nkey\\tx\\x01": 1\n' >>"$T/ctl.yaml"
expect 4 "a key with a line break" -- "$RHOD" run "$T/ctl.yaml" -o "$T/o"
check "key with a line break: one line" -- one_line
check "key with a line break: escaped and located" -- says 'ctl.yaml:11:1: bad\nkey\tx\x01: unknown key'
expect 4 "--set value with a line break" -- "$RHOD" run "$MIN" -o "$T/o" --set $'name=a\nb\rc'
check "--set line break: one line" -- one_line
check "--set line break: escaped" -- says '--set name=a\nb\rc: name:'
expect 4 "--set key with a line break" -- "$RHOD" run "$MIN" -o "$T/o" --set $'na\nme=x'
check "--set key line break: escaped" -- says '--set na\nme=x: na\nme: unknown key'
expect 3 "a scene path with a line break" -- "$RHOD" run "$T/no"$'\n'"such.yaml" -o "$T/o"
check "path with a line break: one line" -- one_line
check "path with a line break: escaped" -- says 'no\nsuch.yaml: cannot read'

summary inputs
