#!/usr/bin/env bash
# GCC 12 nvptx pitfall guard: an addressable local (an array, or a struct whose address
# is passed on) inside an offloaded `simd` loop body is placed in the per-warp soft-stack
# frame, which the 32 lanes of the warp share, so the lanes overwrite each other's
# copies (this broke every wall ghost on a GPU while the host-fallback tests passed).
# This compiles each source with kernels for nvptx, reads the PTX, and fails when a
# simd body (an outlined `$_omp_fn$N` that is not a team-level `$impl`) has such a frame.
# Objects are compiled -fPIC: a shared object may then refer to data defined elsewhere.
# usage: offload_frames.sh SRC_DIR OFFLOAD_FLAGS... (the build's own, from CMake)
set -euo pipefail
SRC=$(cd "$1" && pwd)
shift
FLAGS=("$@" -foffload-options=nvptx-none=-save-temps)
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
bad=0
checked=0
for f in $(grep -l -E "RHOD_KERNEL_LOOP|omp target" "$SRC"/kernels/*.c "$SRC"/kernels/*/*.c "$SRC"/src/*.c \
  "$SRC"/src/*/*.c); do
  b=$(basename "$f" .c)
  (cd "$TMP" && gcc -O2 -fPIC "${FLAGS[@]}" -I"$SRC/include" -I"$SRC/kernels" -I"$SRC/src" \
    -DRHOD_OFFLOAD=1 -c "$f" -o "$b.o" &&
    gcc "${FLAGS[@]}" -no-pie -shared -o "$b.so" "$b.o" 2>/dev/null)
  # the offload image holds our module first, then libgomp's and libm's
  tr '\0' '\n' <"$TMP/$b.so.xnvptx-none.mkoffload" | awk '/^\/\/ BEGIN PREAMBLE/{n++} n==1' >"$TMP/$b.ptx"
  out=$(awk '/BEGIN FUNCTION DEF/{f=$NF}
             /sub.u64 %frame,%sspprev,/{split($2,a,","); if (a[3]+0 > 0 && f ~ /_omp_fn/ && f !~ /\$impl$/) print "  " f ": " a[3]+0 " bytes"}' "$TMP/$b.ptx")
  checked=$((checked + $(grep -c "BEGIN FUNCTION DEF" "$TMP/$b.ptx")))
  if [ -n "$out" ]; then
    echo "$f: simd bodies with a lane-shared frame:"
    echo "$out"
    bad=1
  fi
done
echo "offload_frames: $checked device functions checked"
exit $bad
