#!/usr/bin/env bash
# Configures, builds and runs examples/cpp/panda_modes with CMake against the mechanica
# installed under the prefix $1 (find_package(mechanica CONFIG REQUIRED), target
# mechanica::mechanica). Used by .ci/run after `cargo cinstall` into a staging prefix.
set -euo pipefail
cd "$(dirname "$0")/.."
prefix=${1:?usage: tools/cmake-install-check.sh <install prefix>}
build=$(mktemp -d)
cmake -S examples/cpp/panda_modes -B "$build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build"
LD_LIBRARY_PATH="$prefix/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$build/panda_modes" examples/cpp/panda_modes/panda.urdf
rm -rf "$build"
