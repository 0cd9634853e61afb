#!/usr/bin/env bash
# The sparse peer comparison in one run: Spectra (C++, Eigen) and mechanica's `solve_sparse` on
# the same N x N grid Laplacian, 10 lowest modes, back to back, with the machine load recorded.
# Needs Debian's libspectra-dev and libeigen3-dev (apt-get install -y libspectra-dev
# libeigen3-dev); they are a peer's, used only here, never by the build or the tests.
# Rerun:  bash tools/modal_sparse_spectra.sh [N]      (default 300: n = 90 000)
# Writes tools/modal_sparse_spectra.out.
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-300}
out=tools/modal_sparse_spectra.out
bin=$(mktemp -d)/spectra_grid
if [ ! -d /usr/include/Spectra ] || [ ! -d /usr/include/eigen3 ]; then
    echo "needs libspectra-dev and libeigen3-dev (apt-get install -y libspectra-dev libeigen3-dev)" >&2
    exit 1
fi
g++ -O3 -march=native -DNDEBUG -std=c++17 -I/usr/include/eigen3 tools/modal_sparse_spectra.cpp -o "$bin"
cargo build -q --release -p mechanica-modal --example sparse_grid
{
    echo "# tools/modal_sparse_spectra.sh: Spectra $(dpkg-query -W -f='${Version}' libspectra-dev), Eigen $(dpkg-query -W -f='${Version}' libeigen3-dev), g++ -O3 -march=native"
    echo "# load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
    echo "# method N n best_of_3_s converged max_rel_eig_error"
    "$bin" "$n"
    for rep in 1 2 3; do
        echo "# mechanica solve_sparse (default block size 2, tolerance 1e-12, inertia-certified), run $rep:"
        ${CARGO_TARGET_DIR:-target}/release/examples/sparse_grid "$n" 10 | sed -n 1p
    done
    echo "# load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
} | tee "$out"
