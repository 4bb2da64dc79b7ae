#!/usr/bin/env bash
# The README's main job, on bundled data (data/) and generated meshes: sets up,
# builds, lists the OpenCL devices, builds the curvature kernels into the
# kernel cache, computes curvature of Spot, a torus and an ellipsoid to PLY + JSON
# stats in out/, prints the accuracy/time table of every variant, then extracts
# isosurfaces of procedural fields (with curvature) and prints their report,
# renders the bundled scenes (Spot, torus, gyroid, strokes, the skinned Fox
# with feature edges, the iron protein isosurface), draws feature edges and
# curvature-directed strokes, and writes plots of the accuracy/time tables.
# The front page's three pictures are out/scenes/spot_f0000_v00.png,
# out/spot-edges.png and out/torus-strokes.png (copied to docs/images/).
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
$bin curvature torus --vertices 40000 -o out/torus.ply --stats out/torus.json --force
$bin curvature ellipsoid --vertices 40000 -o out/ellipsoid.ply --stats out/ellipsoid.json --force
$bin report curvature --vertices 40000 --plot out/curvature-report.svg --force
# Isosurfaces: marching cubes + vertex fusion on the device, then curvature
# of the fused mesh without a host round trip, on procedural fields.
$bin isosurface data/bucky.nhdr --iso 51 --curvature -o out/bucky-iso.ply --stats out/bucky-iso.json --force
$bin isosurface --sdf torus --resolution 128 --curvature --normals -o out/torus-iso.ply --stats out/torus-iso.json --force
$bin isosurface --sdf gyroid --resolution 128 --fusion hash -o out/gyroid-iso.ply --stats out/gyroid-iso.json --force
$bin report isosurface --max-resolution 256 --runs 3 --plot out/isosurface-report.svg --force
# Scenes: only the passes each scene's cues need run; images, SVG line
# drawings and a JSON report of the passes that ran go to out/scenes/.
$bin render scenes/spot.toml scenes/torus.toml scenes/gyroid.toml scenes/strokes.toml \
  scenes/fox-edges.toml scenes/ironprot.toml --out out/scenes --force
# Feature edges with House & Li's adjacency caps (PNG and SVG polylines).
$bin edges data/spot.obj --caps adjacency --width 2.5 --crease 40 --size 480x480 --eye=-2.0,0.8,-2.4 \
  -o out/spot-edges.png --svg out/spot-edges.svg --force
# Curvature-directed strokes on a signed distance field (every step on the
# device): PNG over the shaded surface, SVG outlines, PLY strips, stats.
$bin strokes --sdf torus --resolution 128 --size 480x480 -o out/torus-strokes.png --svg out/torus-strokes.svg \
  --geometry out/torus-strokes.ply --stats out/torus-strokes.json --force
