#!/usr/bin/env bash
# Builds and tests the Python package (python/): a virtual environment, the
# test dependencies from PyPI, the package installed by pip with maturin as
# its build backend, then its pytest suite (on the same OpenCL device as the
# Rust tests). Used by .ci/run after `cargo test --release`.
# The build shares target/ with cargo (CARGO_TARGET_DIR), so crates that
# the Rust build already compiled with the same features are reused.
set -euo pipefail
cd "$(dirname "$0")/.."
venv="$(realpath -m "${SHAPECUE_VENV:-target/python-venv}")"
py="${PYTHON:-python3}"
if ! "$py" -c 'import venv, ensurepip' 2>/dev/null; then
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    echo "python-tests: installing python3-venv"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends python3-venv >/dev/null
fi
[ -x "$venv/bin/python" ] || "$py" -m venv "$venv"
pip=("$venv/bin/python" -m pip --disable-pip-version-check -q)
"${pip[@]}" install maturin numpy pytest trimesh scikit-image "dask[distributed]"
export PATH="$venv/bin:$PATH"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
# The build backend from the venv (installed above) instead of a second
# download into an isolated build environment.
"${pip[@]}" install --no-build-isolation --force-reinstall --no-deps ./python
# From outside the source folder, so the installed package is what is tested.
tests="$PWD/python/tests"
(cd "$CARGO_TARGET_DIR" && "$venv/bin/python" -m pytest -q "$tests")
