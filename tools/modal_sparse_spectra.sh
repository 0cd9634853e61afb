#!/usr/bin/env bash
# The sparse peer comparison in one run: Spectra (C++, Eigen) and mechanica's `solve_sparse` on
# the same N x N grid Laplacian, 10 lowest modes, in interleaved rounds (medians and their
# ratio reported), with the machine load recorded.
# Needs Debian's libspectra-dev and libeigen3-dev (apt-get install -y libspectra-dev
# libeigen3-dev); they are a peer's, used only here, never by the build or the tests.
# Rerun:  bash tools/modal_sparse_spectra.sh [N]      (default 300: n = 90 000)
# SEQ=1 in the environment runs mechanica sequentially (faer's global parallelism Seq).
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
ours=${CARGO_TARGET_DIR:-target}/release/examples/sparse_grid
rounds=7
{
    echo "# tools/modal_sparse_spectra.sh: Spectra $(dpkg-query -W -f='${Version}' libspectra-dev), Eigen $(dpkg-query -W -f='${Version}' libeigen3-dev), g++ -O3 -march=native"
    echo "# load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
    echo "# method N n best_of_3_s converged max_rel_eig_error"
    "$bin" "$n"
    echo "# $rounds interleaved rounds: Spectra on SimplicialLDLT (one solve), then mechanica"
    echo "# solve_sparse (default block size 2, tolerance 1e-12, inertia-certified), so that load"
    echo "# drift on a shared machine slows both alike; times in seconds"
    rows=$(mktemp)
    for rep in $(seq "$rounds"); do
        spectra=$("$bin" "$n" 1 ldlt | awk '{print $4}')
        mechanica=$("$ours" "$n" 10 | sed -n 1p | sed -E 's/.*solve ([0-9.]+)(m?s).*/\1 \2/' |
            awk '{print ($2 == "ms") ? $1 / 1000 : $1}')
        echo "round $rep spectra_ldlt $spectra mechanica $mechanica" | tee -a "$rows"
    done
    median() { awk -v c="$1" '{print $c}' "$rows" | sort -g | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'; }
    s=$(median 4)
    m=$(median 6)
    echo "median of $rounds: spectra_ldlt $s s, mechanica $m s, ratio mechanica/spectra $(awk -v m="$m" -v s="$s" 'BEGIN {printf "%.2f", m / s}')"
    echo "# mechanica's accuracy (last run):"
    "$ours" "$n" 10 | sed -n 1p
    echo "# load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
} | tee "$out"
