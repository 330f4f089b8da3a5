#!/bin/sh
# Install the Debian 12 packages Metriplex builds, tests and plots with (clang, libclang-rt-dev and
# libomp-dev: the sanitizer and libFuzzer build of .ci/run; pybind11, numpy, pytest and
# matplotlib: the Python module, its tests and example). Idempotent; run as root.
set -eu
packages="build-essential cmake pkg-config libeigen3-dev libsundials-dev libsuitesparse-dev
  libopenblas0-pthread libtinyxml2-dev liburdfdom-dev libgtest-dev libbenchmark-dev libcli11-dev
  libfmt-dev gnuplot-nox clang-format clang libclang-rt-dev libomp-dev pybind11-dev python3-dev python3-numpy
  python3-pytest python3-matplotlib"
missing=""
for p in $packages; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends $missing
fi
