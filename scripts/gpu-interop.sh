#!/usr/bin/env bash
# The GPU half of the interop routes, for a machine with a GPU whose OpenCL
# reports cl_khr_external_memory_opaque_fd (NVIDIA: also its Vulkan ICD and
# EGL). Fails rather than skips when no shared route is found:
#   - tests/interop.rs with SHAPECUE_REQUIRE_INTEROP=1: `edges` pictures on
#     external memory equal the host path's, for every cap variant;
#   - `shapecue edges MESH --interop on` against `--interop off`, byte for
#     byte, with both routes' --stats (route, reason, frame phases) kept.
# Usage: scripts/gpu-interop.sh [MESH] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
mesh=${1:-${SHAPECUE_SHARED_DATA:-../shared/data}/meshes/bunny.off}
[ -f "$mesh" ] || mesh=
out=${2:-${OUT:-/tmp/gpu-interop}}
mkdir -p "$out"
# NVIDIA's Vulkan ICD where the container keeps it apart.
nv=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$nv" ] && export VK_DRIVER_FILES="$nv"
cargo build --release --bin shapecue
SHAPECUE_REQUIRE_INTEROP=1 cargo test --release --test interop -- --nocapture
if [ -z "$mesh" ]; then
    echo "gpu-interop: no MESH given; the CLI comparison is skipped"
    exit 0
fi
for mode in on off; do
    ./target/release/shapecue edges "$mesh" --interop "$mode" --msaa 0 --runs 10 --force \
        -o "$out/edges-$mode.png" --stats "$out/edges-$mode.json"
done
cmp "$out/edges-on.png" "$out/edges-off.png" && echo "gpu-interop: shared and host images are identical"
