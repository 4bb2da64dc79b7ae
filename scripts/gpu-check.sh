#!/usr/bin/env bash
# The GPU check: every device test and the GPU table, on a machine with an
# NVIDIA GPU and (probably) no Rust, from binaries built beforehand.
#
#   scripts/gpu-check.sh bundle [OUT.tar.xz]   here: build, strip and pack the test
#                                              binaries, the shapecue binary, data/,
#                                              scenes/, tests/ files and the shared data
#                                              (default: target/gpu-check/bundle.tar.xz)
#   scripts/gpu-check.sh run [BUNDLE] [OUTDIR]  there: set NVIDIA's OpenCL ICD and EGL
#                                              vendor file up where missing, run every
#                                              test binary, then print the GPU table
#                                              (Markdown and JSON) beside the paper's
#                                              GTX 480 figures
#   scripts/gpu-check.sh table [OUTDIR]         only the table (also runs on PoCL:
#                                              SHAPECUE_GPU_CHECK_SMALL=1 for small inputs)
#
# What the bundle holds and why (../shared/GPU.md): the machine has NVIDIA's
# libnvidia-opencl.so but no ICD file, no ICD loader and no glvnd EGL, and no
# package registry; so the Debian packages of the loader and of glvnd come
# along (downloaded here into target/gpu-check/debs) and are unpacked there.
# Test binaries read files through their compile-time CARGO_MANIFEST_DIR,
# which `run` recreates as a link to the unpacked tree where it is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
cmd="${1:-run}"

bundle() {
    local out="${1:-target/gpu-check/bundle.tar.xz}"
    local stage=target/gpu-check/stage
    rm -rf "$stage" && mkdir -p "$stage/bin" "$stage/tests" target/gpu-check/debs
    cargo build --release --bin shapecue
    cargo test --release --no-run --message-format=json 2>/dev/null |
        python3 -c '
import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["profile"]["test"]:
        print(m["target"]["name"], m["executable"])' |
        while read -r name exe; do
            cp "$exe" "$stage/tests/$name"
            strip "$stage/tests/$name"
        done
    cp target/release/shapecue "$stage/bin/" && strip "$stage/bin/shapecue"
    echo "$root" >"$stage/manifest_dir"
    if [ -d ../shared/data ]; then
        cp -a ../shared/data "$stage/shared-data"
    fi
    # NVIDIA's machine has no ICD loader and no glvnd EGL (../shared/GPU.md).
    local o=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/gpu-check-lists)
    mkdir -p /tmp/gpu-check-lists/partial
    if apt-get "${o[@]}" update -qq >/dev/null 2>&1; then
        (cd target/gpu-check/debs && apt-get "${o[@]}" download -qq \
            libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 ocl-icd-libopencl1 2>/dev/null) || true
    fi
    cp target/gpu-check/debs/*.deb "$stage/" 2>/dev/null || true
    tar -C target/gpu-check -cf - stage | xz -9e -T0 >"$out"
    echo "gpu-check: bundle $out ($(du -h "$out" | cut -f1)); run it there with:"
    echo "  bash scripts/gpu-check.sh run $out"
}

setup_nvidia() {
    local stage="$1"
    local lib=/usr/local/nvidia/lib64/libnvidia-opencl.so.1
    # Only where NVIDIA's driver is mounted and the loader is missing.
    if [ -f "$lib" ] && ! ldconfig -p | grep -q libOpenCL.so.1; then
        for f in "$stage"/*.deb; do
            [ -f "$f" ] && dpkg -x "$f" /
        done
        ldconfig 2>/dev/null || true
    fi
    mkdir -p /etc/OpenCL/vendors
    if [ -f "$lib" ] && ! grep -qs nvidia /etc/OpenCL/vendors/*.icd; then
        echo "$lib" >/etc/OpenCL/vendors/nvidia.icd
    fi
    local egl=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
    [ -f "$egl" ] && export __EGL_VENDOR_LIBRARY_FILENAMES="$egl"
    local vk=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
    [ -f "$vk" ] && export VK_DRIVER_FILES="$vk"
    return 0
}

# Runs every test binary; prints one line per binary and the failures.
run_tests() {
    local stage="$1" outdir="$2" failed=0 passed=0
    local manifest
    manifest="$(cat "$stage/manifest_dir")"
    if [ ! -e "$manifest" ]; then
        mkdir -p "$(dirname "$manifest")" && ln -s "$root" "$manifest"
    fi
    export SHAPECUE_SHARED_DATA="$stage/shared-data"
    for t in "$stage"/tests/*; do
        local name log
        name="$(basename "$t")"
        log="$outdir/test-$name.log"
        if (cd "$manifest" && timeout 900 "$t" --test-threads 4 >"$log" 2>&1); then
            passed=$((passed + 1))
            echo "gpu-check: ok     $name: $(grep -E '^test result' "$log" | tail -1)"
        else
            failed=$((failed + 1))
            echo "gpu-check: FAILED $name:"
            grep -E '^test .* FAILED|panicked at|^---- ' "$log" | head -20 | sed 's/^/    /'
        fi
    done
    echo "gpu-check: test binaries: $passed passed, $failed failed"
    return "$failed"
}

# One timed command per row; each writes its stdout to OUTDIR/NAME.txt and,
# where it has one, its stats to OUTDIR/NAME.json.
table() {
    local outdir="$1" bin="${2:-target/release/shapecue}" data="${3:-../shared/data}"
    mkdir -p "$outdir"
    local small="${SHAPECUE_GPU_CHECK_SMALL:-}"
    local runs=50 torus=2000000 r1=256 r2=512 size=1024x1024 strokes=128
    if [ -n "$small" ]; then
        runs=3 torus=20000 r1=32 r2=48 size=256x256 strokes=40
    fi
    local rows=()
    row() { # name, command...
        local name="$1"
        shift
        if "$@" >"$outdir/$name.txt" 2>&1; then rows+=("$name"); else
            echo "gpu-check: $name failed: $(tail -2 "$outdir/$name.txt")"
        fi
    }
    "$bin" devices >"$outdir/devices.txt" 2>&1 || true
    for scheme in atomic atomic-native gather; do
        for m in bunny:"$data/meshes/stanford-bunny.obj" lucy:"$data/meshes/lucy.ply"; do
            [ -f "${m#*:}" ] || continue
            row "curvature-$scheme-${m%%:*}" "$bin" curvature "${m#*:}" --accumulate "$scheme" \
                --runs "$runs" --stats "$outdir/curvature-$scheme-${m%%:*}.json"
        done
        row "curvature-$scheme-torus" "$bin" curvature torus --vertices "$torus" \
            --accumulate "$scheme" --runs "$runs" --stats "$outdir/curvature-$scheme-torus.json"
    done
    for res in "$r1" "$r2"; do
        for fusion in direct hash edge; do
            row "isosurface-$fusion-$res" "$bin" isosurface --sdf gyroid --resolution "$res" \
                --fusion "$fusion" --runs 5 --stats "$outdir/isosurface-$fusion-$res.json"
        done
    done
    if [ -f "$data/meshes/stanford-bunny.obj" ]; then
        row edges-frame "$bin" edges "$data/meshes/stanford-bunny.obj" --caps adjacency \
            --size "$size" -o "$outdir/edges.png" --runs 20 --stats "$outdir/edges-frame.json" --force
    fi
    row strokes "$bin" strokes --sdf torus --resolution "$strokes" -o "$outdir/strokes.png" \
        --stats "$outdir/strokes.json" --force
    if [ -f "$data/animations/gltf/BrainStem.glb" ]; then
        SHAPECUE_SHARED_DATA="$data" row skinned-frame "$bin" render scenes/brainstem.toml \
            --out "$outdir/brainstem" --force
    fi
    python3 - "$outdir" <<'EOF'
import json, os, re, sys
out = sys.argv[1]
def txt(n):
    p = os.path.join(out, n + ".txt")
    return open(p).read() if os.path.exists(p) else ""
def js(n):
    p = os.path.join(out, n + ".json")
    try:
        return json.load(open(p))
    except Exception:
        return {}
def num(pattern, text):
    m = re.search(pattern, text)
    return float(m.group(1)) if m else None
# The paper's GTX 480 (Griffin et al.): curvature on the bunny 3.8 ms with the
# graphics pipeline, 8.1 ms with CUDA; its 2.7M-vertex engine 26.7 ms; the
# isosurface of that engine with vertex fusion 338 ms.
paper = {"bunny": "3.8 (GL) / 8.1 (CUDA)", "torus": "26.7 (2.7M-vertex engine)"}
rows = []
for scheme in ("atomic", "atomic-native", "gather"):
    for m in ("bunny", "lucy", "torus"):
        s = js(f"curvature-{scheme}-{m}")
        if s:
            rows.append((f"curvature {scheme}, {m}", s.get("kernel_median_ms"), s.get("wall_median_ms"), paper.get(m, "")))
for res in sorted({int(f.split("-")[-1][:-4]) for f in os.listdir(out) if f.startswith("isosurface-") and f.endswith(".txt")}):
    for fusion in ("direct", "hash", "edge"):
        t = txt(f"isosurface-{fusion}-{res}")
        k = num(r"median ([0-9.]+) ms kernels", t)
        w = num(r"kernels, ([0-9.]+) ms wall", t)
        if k is not None:
            rows.append((f"isosurface {fusion}, gyroid {res}^3", k, w, "338 (engine, fusion)" if fusion != "direct" else ""))
t = txt("edges-frame")
if t:
    rows.append(("edges frame, bunny, adjacency caps", num(r"([0-9.]+) ms kernels", t), num(r"median ([0-9.]+) ms per frame", t), ""))
s = js("strokes")
if s:
    k = s.get("kernel_ms", {})
    rows.append(("strokes, torus", k.get("total") if isinstance(k, dict) else k, s.get("wall_ms"), ""))
t = txt("skinned-frame")
if t:
    rows.append(("skinned BrainStem frame, pose passes", num(r"pose passes ([0-9.]+) ms", t), None, ""))
dev = txt("devices").strip().splitlines()
device = next((l.strip() for l in dev if "*" in l), dev[0] if dev else "unknown")
device = re.split(r"\s{2,}", device)[-1]
f = lambda x: "" if x is None else f"{x:.3f}"
print(f"GPU table: {device}")
print()
print("| work | kernel median ms | wall median ms | paper's GTX 480 ms |")
print("|---|---|---|---|")
for r in rows:
    print(f"| {r[0]} | {f(r[1])} | {f(r[2])} | {r[3]} |")
json.dump({"device": device, "rows": [dict(work=r[0], kernel_ms=r[1], wall_ms=r[2], paper=r[3]) for r in rows]},
          open(os.path.join(out, "gpu-table.json"), "w"), indent=1)
print()
print(json.dumps({"device": device, "rows": len(rows)}))
EOF
}

case "$cmd" in
bundle) bundle "${2:-}" ;;
run)
    b="${2:-target/gpu-check/bundle.tar.xz}"
    outdir="${3:-target/gpu-check/out}"
    mkdir -p "$outdir" target/gpu-check
    rm -rf target/gpu-check/stage
    xz -dc "$b" | tar -C target/gpu-check -xf -
    stage="$root/target/gpu-check/stage"
    setup_nvidia "$stage"
    "$stage/bin/shapecue" devices
    status=0
    run_tests "$stage" "$outdir" || status=1
    table "$outdir" "$stage/bin/shapecue" "$stage/shared-data"
    exit "$status"
    ;;
table) table "${2:-target/gpu-check/out}" ;;
*)
    echo "usage: scripts/gpu-check.sh bundle|run|table" >&2
    exit 2
    ;;
esac
