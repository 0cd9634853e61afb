#!/usr/bin/env bash
# Compares a built libmechanica.so with the committed ABI baseline (tools/abi/libmechanica.abi,
# written by abidw from a library built with full debug information; see docs/c-abi.md).
#
#   tools/abi-check.sh LIBRARY          check LIBRARY against the baseline
#   tools/abi-check.sh --bless LIBRARY  write LIBRARY's ABI as the new baseline
#
# Passes when abidiff finds no change other than added functions. Any other change — a
# function changed or removed, a struct's size or layout changed — fails, unless both the
# SONAME and MECH_ABI_VERSION (include/mechanica.h) differ from the baseline's, i.e. the change
# opens a new ABI version, whose baseline is then blessed and committed.
set -uo pipefail
cd "$(dirname "$0")/.."
baseline=tools/abi/libmechanica.abi
baseline_version_file=tools/abi/libmechanica.abi-version
suppressions=tools/abi/libmechanica.suppr

header_abi_version() {
    sed -n 's/^#define MECH_ABI_VERSION \([0-9][0-9]*\)$/\1/p' include/mechanica.h
}
soname_of() {
    readelf -d "$1" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p'
}

if [ "${1:-}" = "--bless" ]; then
    library="${2:?usage: tools/abi-check.sh --bless LIBRARY}"
    abidw --no-show-locs --no-corpus-path --type-id-style hash "$library" > "$baseline" || exit 1
    header_abi_version > "$baseline_version_file"
    echo "wrote $baseline (SONAME $(soname_of "$library"), MECH_ABI_VERSION $(cat "$baseline_version_file"))"
    exit 0
fi

library="${1:?usage: tools/abi-check.sh LIBRARY}"
report=$(mktemp)
abidiff --no-added-syms --suppressions "$suppressions" "$baseline" "$library" > "$report" 2>&1
status=$?
# abidiff's exit status is a bit set: 1 error, 2 usage error, 4 ABI change, 8 incompatible change.
if (( status & 3 )); then
    cat "$report"
    echo "abidiff could not compare $library with $baseline (status $status)"
    exit 1
fi
if (( status == 0 )); then
    echo "ABI check: $library keeps every function and type of the baseline (added functions are allowed)"
    exit 0
fi
cat "$report"
old_soname=$(sed -n "s/.*<abi-corpus [^>]*soname='\([^']*\)'.*/\1/p" "$baseline" | head -n 1)
new_soname=$(soname_of "$library")
old_version=$(cat "$baseline_version_file")
new_version=$(header_abi_version)
if [ "$old_soname" != "$new_soname" ] && [ "$old_version" != "$new_version" ]; then
    echo "ABI check: incompatible changes with a new SONAME ($old_soname → $new_soname) and MECH_ABI_VERSION ($old_version → $new_version): bless the new baseline (tools/abi-check.sh --bless)"
    exit 0
fi
echo "ABI check FAILED: the changes above break the C ABI of MECH_ABI_VERSION $old_version ($old_soname)."
echo "Only additions are allowed; an incompatible change must raise MECH_ABI_VERSION and the SONAME together."
exit 1
