#!/usr/bin/env bash
# The run command of the README: installs what is missing, builds, and runs the
# default scene (the 2D dam break) into out/dam_break (replacing an earlier demo run):
# snapshots, probes, pictures.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target rhod
# --overwrite: running the demo again replaces its earlier run
./build/rhod run cases/dam_break/scene.yaml -o out/dam_break --overwrite "$@"
echo "output in out/dam_break: snapshots (open snapshots.xdmf in ParaView), probes.csv, pictures snapshot_*.png"
