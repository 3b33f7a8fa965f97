#!/usr/bin/env bash
# The GPU measurement in two halves, because a GPU machine of the `device` tool has no
# Debian packages (no gcc 12 offload libgomp, no HDF5):
#   perf/gpu_kit.sh pack       here: builds the offload binaries in double and single and
#                              gathers them with every shared library they need (Debian's
#                              libgomp and its nvptx plugin included) into gpu-kit/
#   perf/gpu_kit.sh run OUT    on the GPU machine, gpu-kit/ carried there: unit tests,
#                              benchmarks and the coarse validation cases; the log goes
#                              to OUT/gpu.log as it runs
# The figures are in perf/RESULTS.md.
set -euo pipefail
cd "$(dirname "$0")/.."
KIT=gpu-kit

pack() {
  local b
  for b in double single; do
    local dir=build-offload-$b opt=OFF
    [ $b = single ] && opt=ON
    cmake -S . -B $dir -DRHOD_OFFLOAD=ON -DRHOD_SINGLE=$opt -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build $dir -j"$(nproc)" >/dev/null
  done
  rm -rf $KIT
  mkdir -p $KIT/lib $KIT/single
  cp build-offload-double/rhod build-offload-double/perf/bench_step \
    build-offload-double/perf/bench_passes build-offload-double/tests/test_kernels $KIT/
  cp build-offload-single/perf/bench_step build-offload-single/perf/bench_passes \
    build-offload-single/tests/test_kernels $KIT/single/
  # every library the binaries need except the C library itself (the GPU image's glibc
  # is newer than Debian 12's), plus the nvptx plugin libgomp opens at run time
  ldd $KIT/rhod $KIT/bench_step $KIT/test_kernels | awk '/=> \//{print $3}' | sort -u |
    grep -Ev '/(libc|libm|libpthread|libdl|librt|libresolv)\.so' | xargs -I{} cp -L {} $KIT/lib/
  cp -L "$(dirname "$(ldd $KIT/bench_step | awk '/libgomp/{print $3}')")/libgomp-plugin-nvptx.so.1" \
    $KIT/lib/
  du -sh $KIT
}

run() {
  local out=$1 log=$1/gpu.log
  mkdir -p "$out"
  export LD_LIBRARY_PATH=$PWD/$KIT/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}
  {
    date -u
    nvidia-smi -L || true
    echo "== unit tests on the device (double, single)"
    $KIT/test_kernels | tail -4 || echo "test_kernels FAILED"
    $KIT/single/test_kernels | tail -4 || echo "single test_kernels FAILED"
    echo "== whole RK4 step"
    for n in 1e5 1e6 4e6 1.6e7; do $KIT/bench_step $n 20; done
    for n in 1e6 4e6 1.6e7; do $KIT/single/bench_step $n 20; done
    echo "== passes"
    $KIT/bench_passes 1e6 20
    $KIT/single/bench_passes 1e6 20
    echo "== coarse validation cases (the list and settings of tests/CMakeLists.txt)"
    sed -n 's/^rhod_case_test(\(.*\))$/\1/p' tests/CMakeLists.txt | while read -r c args; do
      # shellcheck disable=SC2086
      if PYTHON=python3 bash tests/run_case.sh $KIT/rhod . $c $args >"$out/case.txt" 2>&1; then
        echo "case_$c passed: $(tail -1 "$out/case.txt")"
      else
        echo "case_$c FAILED:"
        cat "$out/case.txt"
      fi
    done
  } 2>&1 | tee -a "$log"
}

case "${1:-}" in
pack) pack ;;
run) run "${2:?usage: perf/gpu_kit.sh run OUT}" ;;
*)
  echo "usage: perf/gpu_kit.sh pack | run OUT" >&2
  exit 2
  ;;
esac
