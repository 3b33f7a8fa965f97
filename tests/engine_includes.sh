#!/usr/bin/env bash
# The engine includes no scheme header, and the schemes do not include each other
# (issue 50; ../shared/design/architecture.md). Engine: include/rhod/*.h, kernels/*.c,
# src/*.c except the application layer: src/main.c, src/schemes.c (the registry that names
# every scheme) and src/scene.c (the loader's shared mechanism, which registers each
# module's sections; their schema and checks stay in the module's folder, e.g.
# src/multiphase/scene_mp.c). Schemes: include/rhod/<scheme>/, kernels/<scheme>/,
# src/<scheme>/.
# Prints each offending #include; exit 1 if any.
set -uo pipefail
SRC=${1:-.}
cd "$SRC" || exit 2
schemes=$(for d in include/rhod/*/ kernels/*/ src/*/; do [ -d "$d" ] && basename "$d"; done | sort -u)
[ -n "$schemes" ] || { echo "engine_includes: no scheme folder found"; exit 2; }
pat=$(echo "$schemes" | paste -sd'|')
bad=0
engine=$(ls include/rhod/*.h kernels/*.c kernels/*.h src/*.c src/*.h 2>/dev/null |
  grep -v -e '^src/main\.c$' -e '^src/schemes\.c$' -e '^src/scene\.c$')
for f in $engine; do
  if grep -nE "^[[:space:]]*#[[:space:]]*include[[:space:]]+\"(rhod/)?($pat)/" "$f"; then
    echo "engine_includes: $f (engine) includes a scheme header"
    bad=1
  fi
done
for s in $schemes; do
  others=$(echo "$schemes" | grep -vx "$s" | paste -sd'|')
  [ -n "$others" ] || continue
  for f in $(find "include/rhod/$s" "kernels/$s" "src/$s" -type f 2>/dev/null); do
    if grep -nE "^[[:space:]]*#[[:space:]]*include[[:space:]]+\"(rhod/)?($others)/" "$f"; then
      echo "engine_includes: $f (scheme $s) includes another scheme's header"
      bad=1
    fi
  done
done
[ $bad = 0 ] && echo "engine_includes: the engine includes no scheme header; schemes: $(echo $schemes)"
exit $bad
