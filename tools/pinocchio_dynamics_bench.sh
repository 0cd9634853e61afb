#!/usr/bin/env bash
# Builds the Pinocchio (C++) dynamics peer, tools/pinocchio_dynamics_bench.cpp, into a C-ABI
# shared library from the pip package's headers (pip install pin; they live under cmeel.prefix/
# in site-packages; no library of the package is linked) and Debian's Eigen
# (apt-get install -y libeigen3-dev), with g++ -O3 -march=native -DNDEBUG, then runs the
# criterion bench that times it against mechanica in the same run:
#   MECHANICA_PINOCCHIO_SHIM=$OUT/libpin_bench.so cargo bench -p mechanica-benches --bench dynamics
# OUT defaults to ${CARGO_TARGET_DIR:-target}/pinocchio-shim. Pinocchio is a peer used only here
# and by that bench, never by the build or the tests.
# Run:  bash tools/pinocchio_dynamics_bench.sh            (build, then bench)
#       bash tools/pinocchio_dynamics_bench.sh build      (build only)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${OUT:-${CARGO_TARGET_DIR:-target}/pinocchio-shim}
prefix=$(python3 -c 'import os, pinocchio; print(os.path.normpath(os.path.join(os.path.dirname(pinocchio.__file__), "..", "..", "..", "..")))') || {
    echo "Pinocchio's Python package is missing: pip install pin" >&2
    exit 1
}
if [ ! -d /usr/include/eigen3 ]; then
    echo "needs Debian's Eigen: apt-get install -y libeigen3-dev" >&2
    exit 1
fi
mkdir -p "$out"
# Pinocchio's exported compile definitions (lib/cmake/pinocchio/pinocchioTargets.cmake), less
# the template instantiation one, so that the algorithms are compiled here with these flags.
# (-Wno-stringop-overread: GCC 12 warns spuriously on Eigen's AVX-512 stores in Pinocchio's
# composite joint, which these models do not use.)
g++ -O3 -march=native -DNDEBUG -std=c++17 -fPIC -shared \
    -I/usr/include/eigen3 -I"$prefix/include" \
    -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS \
    -DBOOST_FUSION_INVOKE_MAX_ARITY=12 -Wno-stringop-overread \
    tools/pinocchio_dynamics_bench.cpp -o "$out/libpin_bench.so"
echo "built $out/libpin_bench.so: pinocchio $(python3 -c 'import pinocchio; print(pinocchio.__version__)'), Eigen $(dpkg-query -W -f='${Version}' libeigen3-dev), $(g++ --version | head -1)" >&2
if [ "${1:-}" = build ]; then
    exit 0
fi
MECHANICA_PINOCCHIO_SHIM="$(realpath "$out/libpin_bench.so")" cargo bench -p mechanica-benches --bench dynamics
