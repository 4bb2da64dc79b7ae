#!/usr/bin/env python3
"""Times shapecue's direct-numbering isosurface beside VTK's Flying Edges
(Schroeder, Maynard and Geveci 2015, vtkFlyingEdges3D) in the same run, on
the same raw volumes, and prints a Markdown table with the ratios.

    python3 scripts/isosurface-table.py [--bin target/release/shapecue] [--runs 11]
        [--rounds 3] [--sizes 256,512] [--small-only] [--passes]

Volumes: the sphere SDF and the gyroid at each size of --sizes (the values of
`shapecue isosurface --sdf NAME --resolution N`, written as raw f32 into a
temporary folder), and Bucky.raw (32³ u8, iso 51) and ironProt.vtk (68³ u8,
iso 128) from ../shared/data/volumes when that folder is there.

shapecue: one process per volume, `--runs N --stats`, the median kernel time
of N extractions with the volume on the device (the first, written, run is
not timed). Flying Edges: vtkFlyingEdges3D on a vtkImageData holding the same
values in memory, normals, gradients and scalars off, the STDThread backend
with 1 and 2 threads, the median of N Update() calls after one untimed call.
Flying Edges is timed only when `import vtk` works (pip install vtk); the
script says so otherwise and prints shapecue's times alone.

Each volume is timed in --rounds rounds, shapecue and Flying Edges in turn,
and the table gives the median of the rounds' medians (this kind of shared
2-core machine drifts by a third from minute to minute; taking the programs
in turn keeps the ratio fair).

The ratio is Flying Edges' best (fewer ms of 1 or 2 threads) over shapecue's
kernel median: above 1, shapecue is faster. --passes adds each pass's median.
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "data", "volumes")

# The procedural fields of src/volume/sdf.rs, in f64 then rounded to f32.
SPHERE_RADIUS = 0.8
GYROID_PERIODS = 4.0


def field(name, res):
    import numpy as np

    n = res - 1
    c = (2.0 * np.arange(res, dtype=np.float64) - n) / n
    if name == "sphere":
        z, y, x = np.meshgrid(c, c, c, indexing="ij")
        v = np.sqrt(x * x + y * y + z * z) - SPHERE_RADIUS
    else:
        w = math.pi * GYROID_PERIODS
        s, co = np.sin(w * c), np.cos(w * c)
        v = (
            s[None, None, :] * co[None, :, None]
            + s[None, :, None] * co[:, None, None]
            + s[:, None, None] * co[None, None, :]
        )
    return v.astype(np.float32)


def vtk_volume(path):
    """(numpy array z,y,x, dims) of a legacy .vtk STRUCTURED_POINTS u8 file."""
    import numpy as np

    with open(path, "rb") as f:
        data = f.read()
    head, _, _ = data.partition(b"LOOKUP_TABLE default\n")
    dims = None
    for line in head.split(b"\n"):
        if line.startswith(b"DIMENSIONS"):
            dims = [int(t) for t in line.split()[1:4]]
    n = dims[0] * dims[1] * dims[2]
    start = len(head) + len(b"LOOKUP_TABLE default\n")
    v = np.frombuffer(data[start : start + n], dtype=np.uint8)
    return v.reshape(dims[2], dims[1], dims[0]), dims


def flying_edges(arr, iso, runs, threads):
    import vtk
    from vtk.util import numpy_support

    smp = vtk.vtkSMPTools()
    smp.SetBackend("STDThread")
    smp.Initialize(threads)
    img = vtk.vtkImageData()
    nz, ny, nx = arr.shape
    img.SetDimensions(nx, ny, nz)
    a = numpy_support.numpy_to_vtk(arr.ravel(), deep=True)
    a.SetName("v")
    img.GetPointData().SetScalars(a)
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(img)
    fe.SetValue(0, float(iso))
    fe.ComputeNormalsOff()
    fe.ComputeGradientsOff()
    fe.ComputeScalarsOff()
    fe.Update()
    times = []
    for _ in range(runs):
        fe.Modified()
        t = time.perf_counter()
        fe.Update()
        times.append((time.perf_counter() - t) * 1e3)
    out = fe.GetOutput()
    return statistics.median(times), out.GetNumberOfPoints(), out.GetNumberOfCells()


def shapecue(binary, args, runs, tmp):
    stats = os.path.join(tmp, "stats.json")
    out = os.path.join(tmp, "out.ply")
    cmd = [binary, "isosurface", *args, "--runs", str(runs), "--stats", stats, "-o", out, "--force"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(stats) as f:
        s = json.load(f)
    passes = {}
    for p in s.get("passes_median", []):
        passes[p["pass"]] = passes.get(p["pass"], 0.0) + p["kernel_ms"]
    q = s.get("extraction", {})
    return s["kernel_median_ms"], passes, q


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "shapecue"))
    ap.add_argument("--runs", type=int, default=11)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--sizes", default="256,512")
    ap.add_argument("--small-only", action="store_true", help="only Bucky and ironProt")
    ap.add_argument("--passes", action="store_true", help="print each pass's median too")
    a = ap.parse_args()
    try:
        import numpy  # noqa: F401
    except ImportError:
        sys.exit("isosurface-table.py needs numpy (pip install numpy)")
    try:
        import vtk  # noqa: F401

        have_vtk = True
    except ImportError:
        have_vtk = False
        print("VTK is not installed (pip install vtk): Flying Edges is not timed.", file=sys.stderr)

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        vols = []
        if not a.small_only:
            for res in [int(s) for s in a.sizes.split(",") if s]:
                for name in ("sphere", "gyroid"):
                    vols.append((f"{name} {res}³", lambda n=name, r=res: field(n, r), 0.0))
        bucky = os.path.join(SHARED, "Bucky.raw")
        iron = os.path.join(SHARED, "ironProt.vtk")
        if os.path.exists(bucky):
            import numpy as np

            vols.append(
                ("Bucky 32³ u8, iso 51",
                 lambda: np.fromfile(bucky, dtype=np.uint8).reshape(32, 32, 32), 51.0)
            )
        if os.path.exists(iron):
            vols.append(("ironProt 68³ u8, iso 128", lambda: vtk_volume(iron)[0], 128.0))
        if not (os.path.exists(bucky) and os.path.exists(iron)):
            print(f"{SHARED} lacks Bucky.raw or ironProt.vtk: they are skipped.", file=sys.stderr)
        for label, make, iso in vols:
            arr = make()
            raw = os.path.join(tmp, "v.raw")
            arr.tofile(raw)
            nz, ny, nx = arr.shape
            kind = "f32" if arr.dtype.name == "float32" else "u8"
            args = [raw, "--dims", f"{nx},{ny},{nz}", "--type", kind, "--iso", str(iso)]
            if kind == "f32":
                args += ["--inside", "below"]
            ks, f1, f2, per = [], [], [], []
            for _ in range(max(1, a.rounds)):
                k, passes, q = shapecue(a.bin, args, a.runs, tmp)
                ks.append(k)
                per.append(passes)
                if have_vtk:
                    f1.append(flying_edges(arr, iso, a.runs, 1))
                    f2.append(flying_edges(arr, iso, a.runs, 2))
            k = statistics.median(ks)
            passes = {p: statistics.median(r[p] for r in per) for p in per[0]}
            fe1 = fe2 = None
            if have_vtk:
                fe1 = (statistics.median(f[0] for f in f1),) + f1[0][1:]
                fe2 = (statistics.median(f[0] for f in f2),) + f2[0][1:]
            rows.append((label, k, passes, q, fe1, fe2))
            os.remove(raw)
            print(f"{label}: shapecue {k:.2f} ms", file=sys.stderr)

    print(f"`{' '.join(sys.argv)}`: medians of {a.runs} runs, median of {a.rounds} rounds\n")
    print("| volume | shapecue `direct` ms | vertices, faces | Flying Edges 1 thread | 2 threads "
          "| FE vertices, faces | FE best / shapecue |")
    print("|---|---|---|---|---|---|---|")
    for label, k, passes, q, fe1, fe2 in rows:
        mine = f"{q.get('vertices', '?')}, {q.get('faces', '?')}"
        if fe1:
            best = min(fe1[0], fe2[0])
            print(f"| {label} | {k:.2f} | {mine} | {fe1[0]:.2f} | {fe2[0]:.2f} | "
                  f"{fe2[1]}, {fe2[2]} | **{best / k:.2f}×** |")
        else:
            print(f"| {label} | {k:.2f} | {mine} | – | – | – | – |")
    if a.passes:
        print("\nPer pass (median kernel ms):\n")
        for label, k, passes, q, _, _ in rows:
            print(f"- {label}: " + ", ".join(f"{p} {t:.2f}" for p, t in passes.items()))


if __name__ == "__main__":
    main()
