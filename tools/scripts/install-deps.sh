#!/usr/bin/env bash
# Install the Debian packages the project builds and tests with, if any is
# missing (idempotent; needs root, as on the project's machines).
set -euo pipefail
packages=(build-essential clang clang-format-14 libclang-rt-14-dev libopenblas-dev libsuitesparse-dev
	  libarpack2-dev libcmocka-dev tetgen python3-matplotlib rt-tests
	  petsc-dev slepc-dev libopenmpi-dev openmpi-bin
	  libwebsockets-dev libjs-three chromium libpng-dev)
missing=()
for p in "${packages[@]}"; do
	dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "install-deps: installing ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
	echo "install-deps: need root to apt-get install: ${missing[*]}" >&2
	exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
