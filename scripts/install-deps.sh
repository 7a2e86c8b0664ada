#!/usr/bin/env bash
# Installs every build and test dependency of ofv from Debian 12's packages.
# The single list of what ofv needs: README, .ci/run and scripts call this.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev
  libvisp-dev
  libpcl-dev
  libopencv-dev
  libopencv-contrib-dev  # ofv::odometry (OpenCV's rgbd module); optional: without it the rest builds
  libopenni2-dev
  libembree-dev libtbb-dev libassimp-dev
  nlohmann-json3-dev libcli11-dev libyaml-cpp-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  gnuplot-nox
  xvfb xdotool  # the live display's tests (ctest -L display): windows under xvfb-run, clicks
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib  # python/: the module ofv, its tests and tutorial
  clang libclang-rt-14-dev  # scripts/fuzz.sh: clang++ -fsanitize=fuzzer (libFuzzer)
  doxygen  # the API reference: cmake --build build --target doc (cmake/Doxyfile.in)
  visp-images-data  # ViSP's castel recording: odometry against ViSP's model-based tracker (Castel.*), 75 MB
)
# --cluster: also what the sweep tests of ctest label `cluster` need (a
# single-node Slurm cluster, GNU parallel). Not by default: on a machine with
# systemd, Debian's slurm-wlm starts its daemons.
if [ "${1:-}" = "--cluster" ]; then
  packages+=(slurm-wlm munge parallel python3)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -q
$sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
