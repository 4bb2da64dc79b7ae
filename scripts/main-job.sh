#!/usr/bin/env bash
# The README's main job, on bundled (generated) data: sets up, builds, lists the
# OpenCL devices, computes curvature of a torus and an ellipsoid to PLY + JSON
# stats in out/, and prints the accuracy/time table of every variant.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo build --release
bin=target/release/shapecue
mkdir -p out
$bin devices
$bin curvature --generate torus --resolution 40000 -o out/torus.ply --stats out/torus.json --force
$bin curvature --generate ellipsoid --resolution 40000 -o out/ellipsoid.ply --stats out/ellipsoid.json --force
$bin curvature --report --resolution 40000
