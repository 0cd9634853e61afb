#!/usr/bin/env bash
# Builds the fuzz targets (if needed) and runs one of them with libFuzzer.
#
#   fuzz/run.sh TARGET SECONDS [libFuzzer options...]
#   fuzz/run.sh build            # only build every target
#   fuzz/run.sh list             # the target names
#   fuzz/run.sh ci SECONDS       # CI: replay every committed corpus, then SECONDS per target
#                                # from seed 1 (deterministic: a slower machine runs a prefix)
#
# New inputs go to a scratch corpus, $FUZZ_TARGET_DIR/corpus/TARGET, read together with the
# committed seeds in fuzz/corpus/TARGET (FUZZ_GROW_CORPUS=1 grows the committed directory
# instead; commit only small, interesting additions); crashes are written to
# fuzz/artifacts/TARGET/. Each run uses one process (-jobs/-workers may be passed for more).
# Environment: FUZZ_TARGET_DIR (default fuzz/target), FUZZ_RSS_LIMIT_MB (default 2048),
# FUZZ_MAX_LEN (default 65536 bytes), FUZZ_MAX_MAGNITUDE (default: the whole double range).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
targets=(stl obj matrix_market scene urdf abi_kinematics abi_mass abi_impulse abi_modal abi_mechanism abi_urdf abi_dynamics abi_motion)
export CARGO_TARGET_DIR="${FUZZ_TARGET_DIR:-$here/target}"
export CARGO_INCREMENTAL=0
# Instrumentation is added by the wrapper, crate by crate; RUSTFLAGS would also reach build
# scripts and proc macros, which cannot link libFuzzer's hooks.
export RUSTC_WRAPPER="$here/sancov-rustc"
unset RUSTFLAGS

# Whether a panic message matches a line of known-findings.txt.
known_finding() {
    local message="$1" pattern
    [ -n "$message" ] || return 1
    while IFS= read -r pattern; do
        [[ -z "$pattern" || "$pattern" == \#* ]] && continue
        [[ "$message" =~ $pattern ]] && return 0
    done < "$here/known-findings.txt"
    return 1
}

build() {
    cargo build --manifest-path "$here/Cargo.toml" --release --locked --bins
}

case "${1:-}" in
    list)
        printf '%s\n' "${targets[@]}"
        exit 0
        ;;
    build)
        build
        exit 0
        ;;
    ci)
        seconds="${2:?usage: fuzz/run.sh ci SECONDS}"
        build
        failed=()
        for target in "${targets[@]}"; do
            binary="$CARGO_TARGET_DIR/release/$target"
            artifacts="$here/artifacts/$target"
            scratch="$CARGO_TARGET_DIR/ci-corpus/$target"
            found="$CARGO_TARGET_DIR/ci-crashes/$target"
            log="$CARGO_TARGET_DIR/ci-$target.log"
            rm -rf "$scratch" "$found"
            mkdir -p "$artifacts" "$scratch" "$found"
            # 1. Every committed input once (-runs=0 stops after reading the corpus): the seeds
            #    and the regressions must pass, known findings or not.
            if ! "$binary" -runs=0 -rss_limit_mb=2048 -timeout=20 -artifact_prefix="$artifacts/" \
                "$here/corpus/$target" > "$log" 2>&1; then
                tail -n 40 "$log"
                failed+=("$target (committed corpus)")
                continue
            fi
            # 2. Exploration from seed 1, collecting crashes instead of stopping at the first.
            explored=0
            "$binary" -fork=1 -ignore_crashes=1 -ignore_ooms=0 -ignore_timeouts=0 -seed=1 \
                -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=20 -max_len="${FUZZ_MAX_LEN:-65536}" \
                -artifact_prefix="$found/" "$scratch" "$here/corpus/$target" >> "$log" 2>&1 || explored=$?
            new=0
            known=0
            for crash in "$found"/*; do
                [ -e "$crash" ] || continue
                message=$(timeout 60 "$binary" "$crash" 2>&1 | grep -A1 'panicked at' | sed -n 2p || true)
                if known_finding "$message"; then
                    known=$((known + 1))
                    echo "$target: known finding: ${message:0:160}"
                else
                    new=$((new + 1))
                    cp "$crash" "$artifacts/"
                    echo "$target: NEW crash $(basename "$crash"): ${message:-$(basename "$crash")}"
                fi
            done
            if [ "$new" -gt 0 ] || { [ "$explored" -ne 0 ] && [ "$known" -eq 0 ]; }; then
                tail -n 20 "$log"
                failed+=("$target")
            else
                echo "$target: corpus replayed, then ${seconds} s from seed 1: $known known finding(s), no new crash"
            fi
        done
        if [ ${#failed[@]} -gt 0 ]; then
            echo "fuzzing found crashes in: ${failed[*]} (inputs in fuzz/artifacts/)"
            exit 1
        fi
        echo "fuzzing: ${#targets[@]} targets, corpus replayed and ${seconds} s each, no crash"
        exit 0
        ;;
    "" | -h | --help)
        sed -n '2,16p' "$0"
        exit 2
        ;;
esac

target="$1"
seconds="${2:?usage: fuzz/run.sh TARGET SECONDS [libFuzzer options...]}"
shift 2
if [[ ! " ${targets[*]} " =~ " $target " ]]; then
    echo "unknown target '$target'; targets: ${targets[*]}" >&2
    exit 2
fi
build
corpus="$here/corpus/$target"
artifacts="$here/artifacts/$target"
mkdir -p "$corpus" "$artifacts"
# A scratch corpus directory first: new inputs land there, not in the committed seeds, unless
# FUZZ_GROW_CORPUS=1 asks for the committed directory to grow.
if [ "${FUZZ_GROW_CORPUS:-0}" = 1 ]; then
    dirs=("$corpus")
else
    scratch="$CARGO_TARGET_DIR/corpus/$target"
    mkdir -p "$scratch"
    dirs=("$scratch" "$corpus")
fi
exec "$CARGO_TARGET_DIR/release/$target" \
    -max_total_time="$seconds" \
    -rss_limit_mb="${FUZZ_RSS_LIMIT_MB:-2048}" \
    -max_len="${FUZZ_MAX_LEN:-65536}" \
    -timeout=20 \
    -print_final_stats=1 \
    -artifact_prefix="$artifacts/" \
    "$@" "${dirs[@]}"
