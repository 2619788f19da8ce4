#!/usr/bin/env bash
# Installs every Debian package hexbite needs to build, test and run (see DESIGN.md section 5).
# Idempotent: when everything is installed it only asks dpkg and returns in well under a second.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git clang-format
  libdeal.ii-dev libopenblas0-pthread
  libeigen3-dev libcgal-dev libvtk9-dev libgdcm-dev zlib1g-dev
  liblemon-dev libboost-graph-dev
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libutfcpp-dev libx11-dev libglx-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  calculix-ccx gmsh openmpi-bin
  xvfb xauth
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [ "$status" = "installed" ] || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
  exit 0
fi

if [ "$(id -u)" -ne 0 ]; then
  echo "setup: missing packages: ${missing[*]}" >&2
  echo "setup: run this script as root (or with sudo) to install them" >&2
  exit 1
fi

echo "setup: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
