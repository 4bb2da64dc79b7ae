#!/usr/bin/env bash
# Runs `cargo test --release` as on a fresh clone of the repository: the
# shared data sets (../shared beside the repository, or $SHAPECUE_SHARED_DATA)
# are made absent, so every test, README example and scene that needs them
# must skip with a message, and everything else must pass. Prints how many
# tests ran and how many skipped for absent data. Used by .ci/run.
#
# How the data are made absent: where the kernel allows a private mount
# namespace (root, or user namespaces), an empty tmpfs is mounted over
# ../shared for this command only, and the already built test binaries run
# from the repository as it is. Elsewhere the repository is cloned into a
# temporary folder with nothing beside it and built there (slower).
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$PWD"
empty="$(mktemp -d)"
log="$(mktemp)"
trap 'rm -rf "$empty" "$log"' EXIT
export SHAPECUE_SHARED_DATA="$empty"

run_tests() {
    # --nocapture so that the skip messages of passing tests reach the log.
    local rc=0
    cargo test --release -- --nocapture >"$log" 2>&1 || rc=$?
    grep -E '^(test result|error|failures:|---- |thread .* panicked|.*example failed)' "$log" || true
    return "$rc"
}

status=0
shared="$(realpath -m ../shared)"
# The probe mounts as the real run will, so a namespace that cannot mount
# takes the clone road instead of failing.
if [ -d ../shared ] && unshare -m sh -c "mount -t tmpfs -o ro tmpfs '$shared'" 2>/dev/null; then
    echo "clone-tests: ${shared} hidden under an empty tmpfs, SHAPECUE_SHARED_DATA=${empty}"
    export -f run_tests
    export log
    unshare -m bash -c "mount -t tmpfs -o ro tmpfs '$shared' && cd '$repo' && run_tests" || status=$?
elif [ -d ../shared ]; then
    clone="$(mktemp -d)/shapecue"
    echo "clone-tests: no private mount namespace here; cloning into ${clone} (nothing beside it)"
    git clone -q --no-hardlinks "$repo" "$clone"
    # Uncommitted changes travel too, so the clone tests this tree.
    (git diff HEAD | (cd "$clone" && git apply --allow-empty)) || true
    cd "$clone"
    CARGO_TARGET_DIR="$clone/target" run_tests || status=$?
    cd "$repo"
    rm -rf "$(dirname "$clone")"
else
    echo "clone-tests: no ../shared beside the repository; SHAPECUE_SHARED_DATA=${empty}"
    run_tests || status=$?
fi
skips=$(grep -c '^skipping' "$log" || true)
passed=$(awk '/^test result/ { for (i = 1; i < NF; i++) if ($(i + 1) ~ /^passed/) n += $i } END { print n + 0 }' "$log")
echo "clone-tests: ${passed:-0} tests passed; ${skips} skip message(s) for absent shared data:"
grep '^skipping' "$log" | sed -E 's/^/  /' | sort | uniq -c | sort -rn | head -60 || true
if [ "$status" -ne 0 ]; then
    echo "clone-tests: FAILED (exit ${status})" >&2
fi
exit "$status"
