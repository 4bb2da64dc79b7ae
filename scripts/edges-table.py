#!/usr/bin/env python3
"""Prints the README's line-drawing table: `shapecue edges` per phase against
Blender's Line Art, on fandisk, the Stanford bunny, armadillo, lucy (from
../shared/data/meshes) and a generated 2M-vertex torus.

    python3 scripts/edges-table.py [--bin target/release/shapecue] [--runs 5]
        [--scene]   # also time the 12-view bunny scene (views per second)

Each mesh: one process to warm PoCL's kernel cache, then `shapecue edges`
with `--runs N --stats` (1024x1024, MSAA 4, 2-pixel edges, adjacency caps,
30-degree creases, framed automatically), whose stats give the first frame's
phases and the medians of N warm frames; then N fresh processes timed end to
end (median). Nothing else should run on the machine meanwhile.

The Line Art figures are Blender 3.4.1's Line Art modifier (contour + 30
degree crease + loose edges, default quality, recomputed per run) measured
on this kind of 2-core machine with the same meshes, camera and image size.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

LINE_ART_MS = {
    "fandisk": 6.9,
    "bunny": 41.0,
    "armadillo": 88.0,
    "lucy": 118.0,
    "torus 2M": 1578.0,
}
MESHES = [
    ("fandisk", "fandisk.obj"),
    ("bunny", "stanford-bunny.obj"),
    ("armadillo", "armadillo.obj"),
    ("lucy", "lucy.ply"),
]


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(here)
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(root, "target/release/shapecue"))
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--data", default=os.path.join(root, "../shared/data/meshes"))
    ap.add_argument("--no-torus", action="store_true", help="skip the 2M-vertex torus")
    ap.add_argument("--scene", action="store_true", help="also time scenes/bunny-lines.toml")
    a = ap.parse_args()
    if not os.path.exists(a.bin):
        sys.exit(f"{a.bin}: not found (cargo build --release)")
    tmp = tempfile.mkdtemp(prefix="shapecue-edges-table-")
    inputs = [(n, os.path.join(a.data, f)) for n, f in MESHES if os.path.exists(os.path.join(a.data, f))]
    missing = [f for _, f in MESHES if not os.path.exists(os.path.join(a.data, f))]
    if missing:
        print(f"skipping {', '.join(missing)}: not in {a.data}", file=sys.stderr)
    if not a.no_torus:
        torus = os.path.join(tmp, "torus2m.ply")
        run([a.bin, "curvature", "--generate", "torus", "--resolution", "2000000", "-o", torus])
        inputs.append(("torus 2M", torus))
    rows = []
    for name, path in inputs:
        png, stats = os.path.join(tmp, "e.png"), os.path.join(tmp, "e.json")
        base = [a.bin, "edges", path, "-o", png, "--size", "1024x1024", "--width", "2",
                "--caps", "adjacency", "--crease", "30", "--force"]
        run(base)  # warm PoCL's kernel cache
        run(base + ["--runs", str(a.runs), "--stats", stats])
        with open(stats) as f:
            d = json.load(f)
        wall = []
        for _ in range(a.runs):
            t = time.perf_counter()
            run(base)
            wall.append((time.perf_counter() - t) * 1e3)
        rows.append((name, d, statistics.median(wall)))
        print(f"{name}: done", file=sys.stderr)

    print("| mesh | vertices | Line Art | edges kernels | warm frame | × Line Art | "
          "edges pass | caps pass | render pass | first frame | topology | process |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, d, proc in rows:
        la = LINE_ART_MS.get(name)
        pm = d["phases_median_ms"]
        f = d["frame_median_ms"]
        ratio = f"{f / la:.2f}" if la else "–"
        print(f"| {name} | {d['vertices']:,} | {la if la else '–'} | {d['kernel_median_ms']:.2f} | "
              f"{f:.1f} | {ratio} | {pm['edges']:.1f} | {pm.get('caps', 0.0):.1f} | "
              f"{pm['render']:.1f} | {d['frame_ms']:.0f} | "
              f"{d['topology_ms']:.1f} | {proc:.0f} |")

    if a.scene:
        scene = os.path.join(root, "scenes/bunny-lines.toml")
        out = os.path.join(tmp, "scene")
        run([a.bin, "render", scene, "--out", out, "--force"])  # warm
        t = time.perf_counter()
        run([a.bin, "render", scene, "--out", out, "--force"])
        total = (time.perf_counter() - t) * 1e3
        reports = [os.path.join(out, f) for f in os.listdir(out) if f.endswith(".json")]
        with open(reports[0]) as f:
            r = json.load(f)
        views = r["views"] * len(r["frames"])
        laps = lambda name: [p["ms"] for p in r["timing"].get("phases", []) if p["phase"] == name]
        view_ms, render_ms = statistics.median(laps("view")), statistics.median(laps("render"))
        per_view = view_ms + render_ms
        print()
        print(f"scene {os.path.basename(scene)}: {views} views at {r['renderer'].split(';')[-1].strip()}; "
              f"per view {view_ms:.1f} ms passes + {render_ms:.1f} ms "
              f"drawing and files = {per_view:.1f} ms ({1e3 / per_view:.1f} views/s; Blender "
              f"Line Art + Workbench: 755 ms per view, 1.3 views/s); process {total:.0f} ms; "
              f"mesh uploads to GL: {r['gl_uploads']['topology']} of the faces, "
              f"{r['gl_uploads']['pose']} of the pose")


if __name__ == "__main__":
    main()
