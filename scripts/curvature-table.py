#!/usr/bin/env python3
"""Prints the README's curvature speed tables on each CPU OpenCL runtime
installed (PoCL; Intel's CPU runtime when scripts/setup-intel-opencl.sh has
put it in target/intel-opencl): kernel time of every pass with the mesh on
the device, and a fresh `shapecue curvature IN -o OUT.ply` process end to end,
beside trimesh2's single-threaded figures measured on this kind of machine.

    python3 scripts/curvature-table.py [--bin target/release/shapecue] [--runs 7]

Meshes: the Stanford bunny and lucy (from ../shared/data/meshes, skipped when
absent) and generated tori of 500k and 2M vertices. Per mesh and runtime: one
process to warm the runtime's kernel cache, then `--runs N --stats`
(medians of N timed runs of all passes, dcurv included, after the run whose
results are written), then N fresh processes timed end to end (median). Both
accumulation schemes are timed; the process column uses the default (gather
on CPU devices). Nothing else should run on the machine meanwhile.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

# trimesh2 2.16, one thread: kernel (curvature + dcurv) and process (read,
# compute, write), ms, measured on this kind of 2-core machine.
TRIMESH2 = {
    "bunny": (19.7, 56),
    "lucy": (28.7, 38),
    "torus 500k": (253, None),
    "torus 2M": (1014, 1463),
}


def run(cmd, env):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(root, "target/release/shapecue"))
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--data", default=os.path.join(root, "../shared/data/meshes"))
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="shapecue-curvature-table-")
    base_env = dict(os.environ)
    runtimes = [("PoCL", dict(base_env, SHAPECUE_DEVICE="pthread"))]
    intel_env = os.path.join(root, "target/intel-opencl/env.sh")
    if os.path.exists(intel_env):
        out = subprocess.run(["bash", "-c", f". {intel_env} && env -0"], check=True,
                             capture_output=True).stdout.decode()
        env = dict(kv.split("=", 1) for kv in out.split("\0") if "=" in kv)
        env["SHAPECUE_DEVICE"] = "intel"
        runtimes.append(("Intel CPU runtime", env))
    else:
        print("Intel's CPU runtime not installed (scripts/setup-intel-opencl.sh): PoCL only",
              file=sys.stderr)
    inputs = []
    for name, f in [("bunny", "stanford-bunny.obj"), ("lucy", "lucy.ply")]:
        p = os.path.join(a.data, f)
        if os.path.exists(p):
            inputs.append((name, p))
        else:
            print(f"skipping {f}: not in {a.data}", file=sys.stderr)
    for name, n in [("torus 500k", 500_000), ("torus 2M", 2_000_000)]:
        # A binary PLY file of the generated torus (its curvature properties
        # are read past).
        ply = os.path.join(tmp, name.replace(" ", "") + ".ply")
        run([a.bin, "curvature", "--generate", "torus", "--resolution", str(n), "-o", ply], base_env)
        inputs.append((name, ply))
    rows = []
    for rt, env in runtimes:
        for name, path in inputs:
            out, stats = os.path.join(tmp, "o.ply"), os.path.join(tmp, "s.json")
            base = [a.bin, "curvature", path, "-o", out, "--force"]
            run(base, env)  # warm the kernel cache
            k = {}
            for acc in ["atomic", "gather"]:
                run(base + ["--accumulate", acc, "--runs", str(a.runs), "--stats", stats], env)
                with open(stats) as f:
                    k[acc] = json.load(f)["kernel_median_ms"]
            wall = []
            for _ in range(a.runs):
                t = time.perf_counter()
                run(base, env)
                wall.append((time.perf_counter() - t) * 1e3)
            rows.append((rt, name, k, statistics.median(wall)))
            print(f"{rt} {name}: done", file=sys.stderr)
    print("| runtime | mesh | atomic kernels | gather kernels | trimesh2 kernels ÷ faster scheme | "
          "process (default) | trimesh2 process |")
    print("|---|---|---|---|---|---|---|")
    for rt, name, k, proc in rows:
        tk, tp = TRIMESH2.get(name, (None, None))
        best = min(k.values())
        ratio = f"{tk / best:.2f}" if tk else "–"
        print(f"| {rt} | {name} | {k['atomic']:.1f} | {k['gather']:.1f} | {ratio} | "
              f"{proc:.0f} | {tp if tp else '–'} |")


if __name__ == "__main__":
    main()
