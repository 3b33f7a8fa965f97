#!/usr/bin/env bash
# Fuzzing campaigns (issue 5) with libFuzzer: builds the engine and one target with
# clang (-fsanitize=fuzzer,address,undefined) and runs it on its corpus, adding what it
# finds there. CI does not fuzz: it replays the kept corpus under ASan (tests/CMakeLists).
#   tests/fuzz/run.sh checkpoint|scene [RUNS=1000000] [JOBS=1]
# Needs clang-14 and libomp-14-dev (Debian packages) besides scripts/setup.sh's.
set -euo pipefail
cd "$(dirname "$0")/../.."
TARGET=${1:?usage: tests/fuzz/run.sh checkpoint|scene [RUNS] [JOBS]}
RUNS=${2:-1000000}
JOBS=${3:-1}
command -v clang >/dev/null || { echo "run.sh: needs clang (apt-get install clang libomp-14-dev)" >&2; exit 2; }
B=build-fuzz
mkdir -p "$B" "tests/fuzz/corpus/$TARGET"
# shellcheck disable=SC2046
clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined -fopenmp \
  -Iinclude -Ikernels -Isrc $(pkg-config --cflags hdf5 libcyaml libpng) \
  $(ls src/*.c kernels/*.c | grep -v src/main.c) "tests/fuzz/fuzz_$TARGET.c" \
  $(pkg-config --libs hdf5 libcyaml libpng) -lm -ldl -o "$B/fuzz_$TARGET"
CORPUS=tests/fuzz/corpus/$TARGET
SEEDS=()
[ "$TARGET" = scene ] && SEEDS=(tests/scenes/good tests/scenes/bad)
PAR=()
[ "$JOBS" -gt 1 ] && PAR=(-jobs="$JOBS" -workers="$JOBS") # then each job logs to fuzz-N.log
"$B/fuzz_$TARGET" -runs="$RUNS" "${PAR[@]}" -max_len=65536 -print_final_stats=1 \
  "$CORPUS" "${SEEDS[@]}" 2>&1 | tail -25
