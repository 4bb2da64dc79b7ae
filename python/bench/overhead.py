"""Call overhead of the Python binding, and a comparison with libigl and
trimesh on the same meshes, in one process.

    python python/bench/overhead.py RUST_EXAMPLE_BINARY MESH [RUNS]

Prints the median wall time of ``shapecue.curvature(v, f)`` (Python in,
numpy arrays out) beside the Rust library's ``curvature_on`` on the same
file (the ``overhead`` example), then ``igl.principal_curvature`` (its
default radius) and trimesh's ball-integrated curvature measures on the
same mesh and on a 500k-vertex torus. They compute different estimators:
shapecue and libigl pointwise principal curvatures (per-face tensors after
Rusinkiewicz 2004; libigl quadric fitting over a k-ring), trimesh integral
measures over a ball of a given radius.
"""

import statistics
import subprocess
import sys
import time

import numpy as np

import shapecue


def median_ms(fn, runs, warm=True):
    if warm:
        fn()
    out = []
    for _ in range(runs):
        t = time.perf_counter()
        fn()
        out.append((time.perf_counter() - t) * 1e3)
    return statistics.median(out)


def torus(nu, nv, R=1.0, r=0.35):
    u = np.linspace(0, 2 * np.pi, nu, endpoint=False)
    v = np.linspace(0, 2 * np.pi, nv, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    verts = np.stack(
        [(R + r * np.cos(vv)) * np.cos(uu), (R + r * np.cos(vv)) * np.sin(uu), r * np.sin(vv)], -1
    ).reshape(-1, 3)
    idx = np.arange(nu * nv).reshape(nu, nv)
    b = np.roll(idx, -1, 0)
    c = np.roll(b, -1, 1)
    d = np.roll(idx, -1, 1)
    f = np.concatenate([np.stack([idx, b, c], -1).reshape(-1, 3), np.stack([idx, c, d], -1).reshape(-1, 3)])
    return verts, f.astype(np.int64)


def main():
    exe, mesh = sys.argv[1], sys.argv[2]
    runs = int(sys.argv[3]) if len(sys.argv) > 3 else 21
    v, f = shapecue.load_mesh(mesh)
    rust = float(subprocess.run([exe, mesh, str(runs)], capture_output=True, text=True, check=True).stdout)
    py = median_ms(lambda: shapecue.curvature(v, f), runs)
    # In one call: the caller's wall time and the library call inside it.
    calls = []
    for _ in range(runs):
        t = time.perf_counter()
        c = shapecue.curvature(v, f)
        calls.append(((time.perf_counter() - t) * 1e3, c.library_ms))
    wall = statistics.median(w for w, _ in calls)
    lib = statistics.median(x for _, x in calls)
    extra = statistics.median(w - x for w, x in calls)
    print(f"{mesh}: {len(v)} vertices, {len(f)} faces")
    print("| call | median ms |\n| --- | --- |")
    print(f"| Rust `shapecue::curvature_on` (device held; overhead example, own process) | {rust:.2f} |")
    print(f"| Python `shapecue.curvature(v, f)` | {py:.2f} |")
    print(f"| same calls: wall / library call inside / binding's own share | "
          f"{wall:.2f} / {lib:.2f} / {extra:.2f} ({100 * extra / lib:.1f} %) |")

    import igl
    import trimesh

    big = torus(1000, 500)
    rows = []
    for name, (vv, ff), n in [(mesh.rsplit("/", 1)[-1], (v, f.astype(np.int64)), runs), ("torus 500k", big, 3)]:
        m = trimesh.Trimesh(vv, ff, process=False)
        r = 0.01 * float(np.linalg.norm(m.extents))
        sc = median_ms(lambda: shapecue.curvature(vv, ff), n)
        ig = median_ms(lambda: igl.principal_curvature(vv, ff), min(n, 5), warm=n > 3)
        pts = m.vertices
        # trimesh's measures over all vertices take minutes at 500k; time
        # them on 2000 vertices and scale linearly (each point is independent).
        sub = pts if len(pts) <= 2000 else pts[:2000]
        tm = median_ms(lambda: trimesh.curvature.discrete_mean_curvature_measure(m, sub, r), 1, False)
        tg = median_ms(lambda: trimesh.curvature.discrete_gaussian_curvature_measure(m, sub, r), 1, False)
        scale = len(pts) / len(sub)
        rows.append((name, len(vv), sc, ig, tm * scale, tg * scale, scale > 1))
        print(rows[-1], flush=True)
    print("\n| mesh | vertices | shapecue | igl.principal_curvature | trimesh mean measure | trimesh gaussian measure |")
    print("| --- | --- | --- | --- | --- | --- |")
    for name, nv, sc, ig, tm, tg, est in rows:
        mark = " (from 2000 vertices)" if est else ""
        print(f"| {name} | {nv} | {sc:.1f} ms | {ig:.1f} ms | {tm:.0f} ms{mark} | {tg:.0f} ms{mark} |")


if __name__ == "__main__":
    main()
