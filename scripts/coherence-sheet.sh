#!/usr/bin/env bash
# Draws docs/images/coherence-sheet.svg: consecutive frames of the libigl
# elephant's ridges, valleys and K = 0 lines side by side, coherence off (top
# row) and on (bottom row), each frame's SVG as `shapecue render` writes it.
# Needs the elephant set of the shared data ($SHAPECUE_SHARED_DATA, else
# ../shared/data beside the repository):
#   bash scripts/coherence-sheet.sh [FIRST_FRAME] [FRAMES]
set -euo pipefail
cd "$(dirname "$0")/.."
shared="${SHAPECUE_SHARED_DATA:-../shared/data}"
obj="$shared/animations/elephant/elephant.obj"
[ -f "$obj" ] || { echo "coherence-sheet: $obj not found (the libigl elephant set)" >&2; exit 1; }
first="${1:-20}"
n="${2:-6}"
cargo build --release --quiet
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cat >"$tmp/elephant.toml" <<EOF
[input]
lbs = "$(realpath "$obj")"
[frames]
start = $first
end = $((first + n))
[[camera]]
direction = [1.0, 0.25, 0.8]
[effects]
ridges = {}
valleys = {}
k_zero = {}
[output]
size = [360, 300]
formats = ["svg"]
background = [1.0, 1.0, 1.0]
EOF
for c in off on; do
    target/release/shapecue render "$tmp/elephant.toml" --coherence "$c" --out "$tmp/$c" >/dev/null
done
python3 - "$tmp" "$first" "$n" <<'PY'
import os, re, sys
tmp, first, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
w, h, label = 360, 300, 24
out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w * n}" height="{2 * (h + label)}">',
       '<rect width="100%" height="100%" fill="white"/>']
for row, c in enumerate(["off", "on"]):
    for i in range(n):
        f = first + i
        path = os.path.join(tmp, c, f"elephant_f{f:04d}_v00.svg")
        body = open(path).read()
        body = re.sub(r"<\?xml[^>]*\?>", "", body)
        x, y = i * w, row * (h + label)
        out.append(f'<text x="{x + 8}" y="{y + 17}" font-family="sans-serif" font-size="14">'
                   f'coherence {c}, frame {f}</text>')
        out.append(f'<g transform="translate({x},{y + label})">{body}</g>')
out.append("</svg>")
open("docs/images/coherence-sheet.svg", "w").write("\n".join(out) + "\n")
PY
echo "coherence-sheet: wrote docs/images/coherence-sheet.svg" >&2
