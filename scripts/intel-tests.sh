#!/usr/bin/env bash
# The whole device test suite on a second CPU runtime: Intel's OpenCL runtime
# for CPUs, installed from PyPI by scripts/setup-intel-opencl.sh into
# target/intel-opencl (beside PoCL, which `cargo test --release` uses).
# .ci/run runs it after the PoCL tests. The suite's device is chosen by
# SHAPECUE_DEVICE. Only a failed download (no network to PyPI) skips the
# run, saying so; once installed, a device that is not selected or a failing
# test fails it.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! bash scripts/setup-intel-opencl.sh target/intel-opencl; then
    echo "intel-tests: SKIPPED: Intel's OpenCL runtime could not be installed from PyPI" >&2
    exit 0
fi
# shellcheck disable=SC1091
. target/intel-opencl/env.sh
export SHAPECUE_DEVICE=intel
default="$(cargo run --release -q -- devices | grep -E '^ *[0-9]+\*' || true)"
echo "intel-tests: device: $default"
# The platform, not the device name: PoCL names its device after the processor.
case "$default" in
*"Intel(R) OpenCL /"*) ;;
*) echo "intel-tests: SHAPECUE_DEVICE=intel did not select Intel's runtime" >&2; exit 1 ;;
esac
# Every test binary (the library's unit tests and doctests need no device).
cargo test --release --tests
