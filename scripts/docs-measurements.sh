#!/usr/bin/env bash
# Regenerates the measured tables of docs/accuracy.md, docs/performance.md and
# docs/coherence.md:
# for each `<!-- report TOPIC -->` … `<!-- end report -->` pair in those pages,
# runs `shapecue report TOPIC` (with the options below) and puts its Markdown
# output between the markers; everything outside the markers is kept as it is.
# Each table opens with the day, the device and the command that made it.
# Run it on an otherwise idle machine (the times are medians, but other jobs
# still move them):
#   bash scripts/docs-measurements.sh            # every topic
#   bash scripts/docs-measurements.sh curvature  # only these topics
# The pipeline table needs a skinned glTF model: $SHAPECUE_PIPELINE_MODEL, else
# the Khronos BrainStem from the shared data sets, else the bundled Fox.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
bin=target/release/shapecue
shared="${SHAPECUE_SHARED_DATA:-../shared/data}"
model="${SHAPECUE_PIPELINE_MODEL:-$shared/animations/gltf/BrainStem.glb}"
[ -f "$model" ] || model=data/Fox.glb

# The command of each topic (as it appears in the pages' headers).
args_of() {
    case "$1" in
        curvature) echo "report curvature --vertices 40000" ;;
        isosurface) echo "report isosurface --max-resolution 256 --runs 3" ;;
        strokes) echo "report strokes" ;;
        pipeline) echo "report pipeline $model" ;;
        caps) echo "report caps --width 10 --fov 20" ;;
        memory) echo "report memory" ;;
        lines-batch) echo "report lines-batch" ;;
        visibility) echo "report visibility" ;;
        coherence) echo "report coherence --plot docs/images/coherence.svg --force" ;;
        *) echo "docs-measurements: unknown topic $1" >&2; return 1 ;;
    esac
}

want=("$@")
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
for page in docs/accuracy.md docs/performance.md docs/coherence.md; do
    topics=$(sed -nE 's/^<!-- report ([a-z-]+) -->$/\1/p' "$page")
    for t in $topics; do
        if ((${#want[@]})) && [[ ! " ${want[*]} " =~ " $t " ]]; then
            continue
        fi
        args=$(args_of "$t")
        echo "docs-measurements: shapecue $args" >&2
        # shellcheck disable=SC2086
        $bin $args >"$tmp/$t.md"
        python3 - "$page" "$t" "$tmp/$t.md" <<'PY'
import sys
page, topic, table = sys.argv[1], sys.argv[2], open(sys.argv[3]).read().rstrip("\n")
text = open(page).read()
start = f"<!-- report {topic} -->"
end = "<!-- end report -->"
i = text.index(start) + len(start)
j = text.index(end, i)
open(page + ".tmp", "w").write(text[:i] + "\n" + table + "\n" + text[j:])
PY
        mv "$page.tmp" "$page"
    done
done
echo "docs-measurements: wrote docs/accuracy.md, docs/performance.md and docs/coherence.md" >&2
