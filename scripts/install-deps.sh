#!/usr/bin/env bash
# Installs the Debian packages drapegen needs to build and test. Run as root (or with sudo available).
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libsuitesparse-dev libopenblas0-serial
  libspdlog-dev libfmt-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libosmesa6-dev libopenexr-dev openexr libpng-dev libdeflate-dev
  python3-torch python3-numpy python3-scipy
  cppzmq-dev libzmq3-dev libprotobuf-dev protobuf-compiler libsqlite3-dev libtomlplusplus-dev
  slurm-wlm munge sqlite3
  python3 python3-openimageio
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
