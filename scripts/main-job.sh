#!/usr/bin/env bash
# The README's main job, on bundled data (data/) and generated meshes: sets up,
# builds, lists the OpenCL devices, builds the curvature kernels into the
# kernel cache, computes curvature of Spot, a torus and an ellipsoid to PLY + JSON
# stats in out/, prints the accuracy/time table of every variant, then extracts
# isosurfaces of procedural fields (with curvature) and prints their report,
# renders the bundled scenes (torus, gyroid, strokes), and draws curvature-
# directed strokes on a torus SDF.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo build --release
bin=target/release/shapecue
mkdir -p out
$bin devices
# Builds the curvature kernels for the device once, into shapecue's kernel
# cache, so that no later command compiles them.
$bin build-kernels
$bin curvature data/spot.obj -o out/spot.ply --stats out/spot.json --force
$bin curvature --generate torus --resolution 40000 -o out/torus.ply --stats out/torus.json --force
$bin curvature --generate ellipsoid --resolution 40000 -o out/ellipsoid.ply --stats out/ellipsoid.json --force
$bin report curvature --resolution 40000
# Isosurfaces: marching cubes + vertex fusion on the device, then curvature
# of the fused mesh without a host round trip, on procedural fields.
$bin isosurface data/bucky.nhdr --iso 51 --curvature -o out/bucky-iso.ply --stats out/bucky-iso.json --force
$bin isosurface --sdf torus --resolution 128 --curvature --normals -o out/torus-iso.ply --stats out/torus-iso.json --force
$bin isosurface --sdf gyroid --resolution 128 --fusion hash -o out/gyroid-iso.ply --stats out/gyroid-iso.json --force
$bin report isosurface --max-resolution 256 --runs 3
# Scenes: only the passes each scene's cues need run; images, SVG line
# drawings and a JSON report of the passes that ran go to out/scenes/.
$bin render scenes/spot.toml scenes/torus.toml scenes/gyroid.toml scenes/strokes.toml --out out/scenes --force
# Curvature-directed strokes on a signed distance field (every step on the
# device): PNG over the shaded surface, SVG outlines, PLY strips, stats.
$bin strokes --sdf torus --resolution 128 -o out/torus-strokes.png --svg out/torus-strokes.svg \
  --geometry out/torus-strokes.ply --stats out/torus-strokes.json --force
