#!/usr/bin/env bash
# Installs the Debian packages the project needs, only those that are missing.
# Usage: scripts/install-deps.sh [--hardware | --cluster]   (--hardware adds the FPGA/HDL tools;
# --cluster adds Slurm and munge for the ctest label cluster)
set -euo pipefail

packages=(build-essential cmake g++ libgtest-dev libgmock-dev libbenchmark-dev libsystemc-dev
          nlohmann-json3-dev libyaml-cpp-dev libfftw3-dev libboost-dev pkg-config python3 python3-numpy python3-scipy
          libtbb-dev  # oneTBB: the persistent worker threads of parallel_items (model/base/parallel.hpp)
          python3-matplotlib
          parallel  # the GNU parallel sweep recipe and its test (docs/design-space.md)
          clang libclang-rt-14-dev)  # clang + libFuzzer: tests/fuzz (RANGING_FUZZ=ON)
if [[ "${1:-}" == "--hardware" ]]; then
  packages+=(verilator iverilog yosys nextpnr-ice40 fpga-icestorm gtkwave
             fpga-icestorm-chipdb  # icetime's chip database (a Recommends, not installed with --no-install-recommends)
             z3)  # solver of yosys-smtbmc: formal/ (ctest label formal)
fi
if [[ "${1:-}" == "--cluster" ]]; then
  packages+=(slurm-wlm munge)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  exit 0
fi

echo "install-deps: installing ${missing[*]}" >&2
sudo=""
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
