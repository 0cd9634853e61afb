#!/usr/bin/env bash
# Compiles and runs examples/c/hello.c with the exact command the README shows, against the
# mechanica found by pkg-config. Used by .ci/run after `cargo cinstall` into a staging prefix.
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(mktemp -d)
# The README line:
gcc -std=c11 -Wall -Wextra -Werror examples/c/hello.c $(pkg-config --cflags --libs mechanica) -o "$out/hello"
"$out/hello"
