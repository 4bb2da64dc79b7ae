#!/usr/bin/env bash
# Installs Intel's OpenCL runtime for CPUs (the `intel-opencl-rt` and
# `intel-cmplr-lib-rt` packages of PyPI, with their dependencies) into a
# folder of the project's or the user's, and makes it visible to the ICD
# loader beside the devices already installed, without touching
# /etc/OpenCL/vendors. It runs on any x86-64 CPU with AVX2 (AMD's too).
#
#   scripts/setup-intel-opencl.sh [DIR]     (default: target/intel-opencl)
#   . DIR/env.sh                            (sets OCL_ICD_VENDORS)
#   shapecue devices                        (lists PoCL and Intel's device)
#   SHAPECUE_DEVICE=intel cargo test --release --test curvature
#
# What it takes care of:
# - The wheels put their libraries under the environment's lib/, so they go
#   into a virtual environment of their own (DIR/venv), not the user's Python.
# - The wheel's own .icd names a path that does not exist after a pip
#   install: DIR/vendors/intel-cpu.icd names libintelocl.so by its absolute
#   path instead, and DIR/vendors also links the system's .icd files, so
#   that OCL_ICD_VENDORS=DIR/vendors adds Intel's device to PoCL instead of
#   replacing it.
# - The runtime needs the libraries of intel-cmplr-lib-rt and tbb; where
#   its run path does not find them, env.sh adds DIR/venv/lib to
#   LD_LIBRARY_PATH. The bundled libOpenCL.so (an ICD loader) is moved
#   aside so that it can never shadow the system's loader that way.
# Idempotent: a second run reuses the environment and rewrites the files.
set -euo pipefail
cd "$(dirname "$0")/.."

dir="${1:-target/intel-opencl}"
mkdir -p "$dir"
dir="$(cd "$dir" && pwd)"
venv="$dir/venv"

if ! command -v python3 >/dev/null 2>&1; then
    echo "setup-intel-opencl: python3 not found (it installs the runtime from PyPI)" >&2
    exit 1
fi
if [ ! -x "$venv/bin/pip" ]; then
    echo "setup-intel-opencl: creating $venv"
    python3 -m venv "$venv"
fi
echo "setup-intel-opencl: installing intel-opencl-rt and intel-cmplr-lib-rt into $venv"
"$venv/bin/pip" install --disable-pip-version-check -q intel-opencl-rt intel-cmplr-lib-rt

lib="$(find "$venv" -name 'libintelocl.so' -not -path '*/bundled-icd-loader/*' | head -n 1)"
if [ -z "$lib" ]; then
    echo "setup-intel-opencl: libintelocl.so not found under $venv after the install" >&2
    exit 1
fi
libdir="$(dirname "$lib")"

# The bundled ICD loader must not be the one the process loads.
aside="$libdir/bundled-icd-loader"
for f in "$libdir"/libOpenCL.so*; do
    [ -e "$f" ] || continue
    mkdir -p "$aside"
    mv -f "$f" "$aside/"
done

vendors="$dir/vendors"
rm -rf "$vendors"
mkdir -p "$vendors"
for icd in /etc/OpenCL/vendors/*.icd; do
    [ -e "$icd" ] || continue
    case "$(basename "$icd")" in
    intel-cpu.icd | intel-fpga_emu.icd) ;;
    *) ln -s "$icd" "$vendors/" ;;
    esac
done
echo "$lib" >"$vendors/intel-cpu.icd"

# Libraries the runtime does not find by its run path alone.
need_path=0
if command -v ldd >/dev/null 2>&1 && ldd "$lib" | grep -q 'not found'; then
    need_path=1
    missing="$(LD_LIBRARY_PATH="$libdir" ldd "$lib" | grep 'not found' || true)"
    if [ -n "$missing" ]; then
        echo "setup-intel-opencl: libraries still missing with $libdir on the path:" >&2
        echo "$missing" >&2
        exit 1
    fi
fi

{
    echo "# Makes Intel's CPU OpenCL runtime ($lib) visible beside the system's devices."
    echo "# Source it: . $dir/env.sh"
    echo "export OCL_ICD_VENDORS=\"$vendors\""
    if [ "$need_path" -eq 1 ]; then
        echo "export LD_LIBRARY_PATH=\"$libdir\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}\""
    fi
} >"$dir/env.sh"

echo "setup-intel-opencl: wrote $dir/env.sh; OpenCL devices with it:"
(
    # shellcheck disable=SC1091
    . "$dir/env.sh"
    clinfo -l 2>/dev/null || echo "  (clinfo not installed; try: shapecue devices)"
)
echo "setup-intel-opencl: use it with: . $dir/env.sh; SHAPECUE_DEVICE=intel shapecue devices"
