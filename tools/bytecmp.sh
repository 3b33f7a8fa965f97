#!/usr/bin/env bash
# tools/bytecmp.sh OLD_RHOD NEW_RHOD SRC: the short runs of tests/cli_reference.sh made with two
# binaries (e.g. before and after a refactor), probes.csv compared byte for byte and every
# snapshot dataset exactly (the files themselves differ in their GitCommit). Prints one line
# per run: "same"/"identical" or what differs.
OLD=$1; NEW=$2; SRC=$3; T=$(mktemp -d)
export OMP_NUM_THREADS=2
run() { local name=$1 scene=$2; shift 2
  "$OLD" run "$SRC/cases/$scene" -o "$T/o_$name" "$@" >/dev/null 2>&1 || echo "old fail $name"
  "$NEW" run "$SRC/cases/$scene" -o "$T/n_$name" "$@" >/dev/null 2>&1 || echo "new fail $name"
  cmp -s "$T/o_$name/probes.csv" "$T/n_$name/probes.csv" && p=same || p=DIFF
  /usr/bin/python3 - "$T/o_$name" "$T/n_$name" "$name" "$p" <<'PY'
import sys,glob,os,h5py,numpy as np
a,b,name,p=sys.argv[1:]
bad=[]
fa=sorted(glob.glob(a+'/snapshot_*.h5')); fb=sorted(glob.glob(b+'/snapshot_*.h5'))
if [os.path.basename(x) for x in fa]!=[os.path.basename(x) for x in fb]: bad.append('files')
for x,y in zip(fa,fb):
  A=h5py.File(x); B=h5py.File(y)
  for k in A['PartType0']:
    if not np.array_equal(A['PartType0'][k][()],B['PartType0'][k][()]): bad.append(os.path.basename(x)+':'+k)
print(f"{name}: probes {p}, snapshots {len(fa)} {'identical' if not bad else 'DIFF '+','.join(bad)}")
PY
}
run hydrostatic hydrostatic/scene.yaml --set particles.dx=0.05 --set time.end=0.2 --set time.output_every=0.1
run taylor_green taylor_green/scene.yaml --set particles.dx=0.05 --set time.end=0.2 --set time.output_every=0.1
run rotating_square rotating_square/scene.yaml --set particles.dx=0.05 --set time.end=0.3 --set time.output_every=0.15
run dam_break dam_break/scene.yaml --set particles.dx=0.00584 --set time.end=0.05 --set time.output_every=0.025
run dam_break_lobovsky dam_break_lobovsky/scene.yaml --set particles.dx=0.012 --set time.end=0.1 --set time.output_every=0.05
run hydrostatic_apr hydrostatic_apr/scene.yaml --set time.end=0.05 --set time.output_every=0.025
run rotating_square_apr rotating_square/scene_apr.yaml --set time.end=0.1 --set time.output_every=0.05
run dam_break_lobovsky_apr dam_break_lobovsky/scene_apr.yaml --set time.end=0.05 --set time.output_every=0.025
rm -rf "$T"
