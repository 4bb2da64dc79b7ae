#!/usr/bin/env bash
# Byte comparison of two shapecue binaries' outputs (before and after a
# change): the main job's curvature, every scene of scenes/ (PNG and SVG),
# `lines` on Spot and, where ../shared/data is beside the checkout, the
# Stanford bunny (every family: SVG, segments, a views folder with NPZ),
# `edges` and `strokes`. Each binary writes into its own folder; then every
# file is compared byte for byte, JSON files with their clocks (keys ending
# in `_ms`, `timing`, `ms`, and the manifest's `timing`) left out. Prints one
# line per file that differs and a summary; exits 1 if any differs.
#
#   scripts/compare-outputs.sh OLD_BINARY NEW_BINARY [WORK_DIR]
#
# A difference is not an error in itself: the note of a change names each
# one and why.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 OLD_BINARY NEW_BINARY [WORK_DIR]" >&2; exit 2; }
old=$(realpath "$1")
new=$(realpath "$2")
cd "$(dirname "$0")/.."
work=${3:-$(mktemp -d /tmp/shapecue-compare.XXXXXX)}
mkdir -p "$work"
bunny=../shared/data/meshes/stanford-bunny.obj
all=contours,suggestive,ridges,valleys,apparent-ridges,suggestive-highlights,principal-highlights,isophotes,k-zero,h-zero,dwkr-zero,boundaries

outputs() {
  local bin=$1 out=$2
  rm -rf "$out"
  mkdir -p "$out"
  "$bin" curvature data/spot.obj -o "$out/spot.ply" --force >/dev/null
  "$bin" render scenes/*.toml --out "$out/scenes" --force >/dev/null 2>"$out/render.log" ||
    echo "note: $bin: some scenes did not render (see $out/render.log)" >&2
  "$bin" lines data/spot.obj --lines "$all" -o "$out/spot-lines.svg" \
    --segments "$out/spot-lines.json" --force >/dev/null
  "$bin" lines data/spot.obj --lines contours,suggestive --size 600x600 \
    -o "$out/spot-default.svg" --segments "$out/spot-default.json" --force >/dev/null
  "$bin" lines data/spot.obj --lines "$all" --views 4 --npz --segments --fields \
    --out "$out/spot-views" --force >/dev/null
  if [ -f "$bunny" ]; then
    "$bin" lines "$bunny" --lines "$all" -o "$out/bunny-lines.svg" \
      --segments "$out/bunny-lines.json" --force >/dev/null
  fi
  "$bin" edges data/spot.obj --caps adjacency --crease 40 -o "$out/spot-edges.svg" --force >/dev/null
  "$bin" strokes --sdf torus --resolution 96 -o "$out/torus-strokes.png" --svg "$out/torus-strokes.svg" \
    --geometry "$out/torus-strokes.ply" --force >/dev/null
}

echo "old: $old -> $work/old"
outputs "$old" "$work/old"
echo "new: $new -> $work/new"
outputs "$new" "$work/new"

python3 - "$work/old" "$work/new" <<'EOF'
import json, os, re, sys
old, new = sys.argv[1], sys.argv[2]
CLOCK = ("timing", "ms")
MS = re.compile(r"[0-9.]+ ms")

def strip(v, root):
    """A JSON value without its clocks: keys that time, times in text, and
    the output folder in paths."""
    if isinstance(v, dict):
        return {k: strip(x, root) for k, x in v.items()
                if k not in CLOCK and not k.endswith("_ms") and not k.endswith("_per_second")}
    if isinstance(v, list):
        return [strip(x, root) for x in v]
    if isinstance(v, str):
        return MS.sub("<ms>", v.replace(root, "<out>"))
    return v

def where(x, y, at=""):
    """The paths (key/index) where two JSON values differ, at most 4."""
    if isinstance(x, dict) and isinstance(y, dict):
        out = []
        for k in sorted(set(x) | set(y)):
            if k not in x or k not in y:
                out.append(f"{at}/{k} ({'new' if k in y else 'old'} only)")
            else:
                out += where(x[k], y[k], f"{at}/{k}")
        return out[:4]
    if isinstance(x, list) and isinstance(y, list) and len(x) == len(y):
        return [w for i, (p, q) in enumerate(zip(x, y)) for w in where(p, q, f"{at}/{i}")][:4]
    return [] if x == y else [at or "/"]

def same(a, b):
    """None where the files are the same, else a few words of where not."""
    if a.endswith(".log"):
        return None
    x, y = open(a, "rb").read(), open(b, "rb").read()
    if x == y:
        return None
    if a.endswith(".json"):
        try:
            p, q = strip(json.loads(x), old), strip(json.loads(y), new)
        except ValueError:
            return "not JSON"
        return None if p == q else "at " + ", ".join(where(p, q))
    return "bytes"

files = set()
for root in (old, new):
    for d, _, fs in os.walk(root):
        files.update(os.path.relpath(os.path.join(d, f), root) for f in fs)
differ = 0
for f in sorted(files):
    a, b = os.path.join(old, f), os.path.join(new, f)
    if not os.path.exists(a) or not os.path.exists(b):
        print(f"only in {'new' if os.path.exists(b) else 'old'}: {f}")
        differ += 1
    elif (how := same(a, b)) is not None:
        print(f"differs: {f} ({os.path.getsize(a)} -> {os.path.getsize(b)} bytes) {how}")
        differ += 1
print(f"{len(files) - differ} of {len(files)} files the same, {differ} differ")
sys.exit(1 if differ else 0)
EOF
