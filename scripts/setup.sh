#!/usr/bin/env bash
# Installs the Debian packages rhod needs when they are missing (run as root on a
# fresh Debian 12 machine; a no-op when everything is there).
set -euo pipefail
PKGS=(build-essential cmake clang-format valgrind python3 pkg-config libhdf5-dev libcunit1-dev libcyaml-dev libmatheval-dev libpng-dev
      gcc-12-offload-nvptx libjansson-dev python3-meshio python3-numpy python3-h5py python3-matplotlib python3-scipy hdf5-tools)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
