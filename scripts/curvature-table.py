#!/usr/bin/env python3
"""Prints the README's curvature speed tables on each CPU OpenCL runtime
installed (PoCL; Intel's CPU runtime when scripts/setup-intel-opencl.sh has
put it in target/intel-opencl): kernel time of every pass with the mesh on
the device for each accumulation scheme, and a fresh
`shapecue curvature IN -o OUT.ply` process end to end, beside trimesh2.

    python3 scripts/curvature-table.py [--bin target/release/shapecue] [--runs 7] [--rounds 3]
        [--trimesh2-bench CMD] [--trimesh2-process CMD] [--only NAMES] [--lanes N]

Meshes: the Stanford bunny and lucy (from ../shared/data/meshes, skipped when
absent) and generated tori of 500k and 2M vertices. Per mesh and runtime: one
process to warm the runtime's kernel cache, then `--runs N --stats` for each
scheme (medians of N timed runs of all passes, dcurv included, after the run
whose results are written; in the memory order shapecue picks, and for the
gather scheme also in the file's own order, `--order input`; `--rounds R`
processes per scheme, every scheme in turn, and the median of their
medians), then N fresh processes with the default scheme
timed end to end (median), the same after `shapecue build-kernels` (which
fills shapecue's own kernel cache; an ordinary run fills it on Intel's runtime
but not on PoCL), and on the bunny one process with empty kernel caches
(nothing built) and one after `shapecue build-kernels` with PoCL's own cache
empty (the first run after an install that ran it).

PoCL compiles for the machine it runs on. To see the code an AVX2 CPU gets
(8 float lanes) on an AVX-512 machine, run the script with
POCL_LLVM_CPU_NAME=znver2 POCL_KERNELLIB_NAME=avx2 in its environment and
--lanes 8 (PoCL still reports the host's vector width, 16).

trimesh2 is timed in the same run when you give programs built from it
(this script does not build trimesh2):
  --trimesh2-bench CMD    `CMD MESH REPS` prints `kernel_ms median=X ...`: the
                          median of REPS runs of trimesh2's need_normals,
                          need_pointareas, need_curvatures and need_dcurv
  --trimesh2-process CMD  `CMD MESH OUT.ply` reads the mesh, computes the same
                          and writes the same 19 properties
Without them the trimesh2 columns are figures measured on another day on this
kind of machine, marked with *.

Nothing else should run on the machine meanwhile.
"""

import argparse
import json
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile
import time

# trimesh2 2.16, one thread, measured on another day on this kind of 2-core
# machine: kernel (normals, point areas, curvature, dcurv) and process (read,
# compute, write), ms.
TRIMESH2_OTHER_DAY = {
    "bunny": (19.7, 56),
    "lucy": (28.7, 38),
    "torus 500k": (253, None),
    "torus 2M": (1014, 1463),
}


def run(cmd, env):
    return subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          env=env)


def timed(cmd, env, n):
    wall = []
    for _ in range(n):
        t = time.perf_counter()
        run(cmd, env)
        wall.append((time.perf_counter() - t) * 1e3)
    return statistics.median(wall)


def kernel_median(base, extra, stats, runs, env):
    """Median kernel ms of `--runs` for one scheme, or None where the device
    refuses it (native float atomics on a device without them)."""
    r = subprocess.run(base + extra + ["--runs", str(runs), "--stats", stats],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    if r.returncode != 0:
        err = r.stderr.decode(errors="replace")
        if "cl_ext_float_atomics" in err:
            return None, None
        raise SystemExit(f"{shlex.join(base + extra)} failed:\n{err}")
    with open(stats) as f:
        s = json.load(f)
    return s["kernel_median_ms"], s.get("face_lanes")


def fmt(v, digits=1):
    return "–" if v is None else f"{v:.{digits}f}"


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(root, "target/release/shapecue"))
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--rounds", type=int, default=3,
                    help="processes per scheme, taken in turn (median of their medians)")
    ap.add_argument("--data", default=os.path.join(root, "../shared/data/meshes"))
    ap.add_argument("--trimesh2-bench", help="command timing trimesh2's kernels (see above)")
    ap.add_argument("--trimesh2-process", help="command running trimesh2's whole job (see above)")
    ap.add_argument("--only", help="comma-separated mesh names to time (bunny,lucy,torus 500k,...)")
    ap.add_argument("--lanes", type=int,
                    help="faces per work-item of the N-face schemes (default: the device's native "
                         "float width)")
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
    only = set(a.only.split(",")) if a.only else None
    inputs = []
    for name, f in [("bunny", "stanford-bunny.obj"), ("lucy", "lucy.ply")]:
        p = os.path.join(a.data, f)
        if only and name not in only:
            continue
        if os.path.exists(p):
            inputs.append((name, p))
        else:
            print(f"skipping {f}: not in {a.data}", file=sys.stderr)
    for name, n in [("torus 500k", 500_000), ("torus 2M", 2_000_000)]:
        if only and name not in only:
            continue
        # A binary PLY file of the generated torus (its curvature properties
        # are read past, by shapecue and by trimesh2).
        ply = os.path.join(tmp, name.replace(" ", "") + ".ply")
        run([a.bin, "curvature", "--generate", "torus", "--resolution", str(n), "-o", ply], base_env)
        inputs.append((name, ply))

    # trimesh2 first, in the same run as shapecue.
    tm2 = {}
    for name, path in inputs:
        kern, proc, star = None, None, False
        if a.trimesh2_bench:
            out = subprocess.run(shlex.split(a.trimesh2_bench) + [path, str(a.runs)], check=True,
                                 capture_output=True).stdout.decode()
            m = re.search(r"kernel_ms median=([0-9.]+)", out)
            if not m:
                raise SystemExit(f"--trimesh2-bench printed no `kernel_ms median=`:\n{out}")
            kern = float(m.group(1))
        if a.trimesh2_process:
            proc = timed(shlex.split(a.trimesh2_process) + [path, os.path.join(tmp, "t.ply")],
                         base_env, a.runs)
        if kern is None and proc is None:
            kern, proc = TRIMESH2_OTHER_DAY.get(name, (None, None))
            star = True
        tm2[name] = (kern, proc, star)
        print(f"trimesh2 {name}: done", file=sys.stderr)

    kernel_rows, process_rows = [], []
    for rt, env in runtimes:
        # shapecue's program cache as a new user has it: empty at first, so
        # that entries left in the user's own cache (from a run with
        # `shapecue build-kernels`, say) do not stand in for the default.
        env = dict(env, SHAPECUE_CACHE_DIR=os.path.join(tmp, "cache-" + rt.split()[0]))
        for name, path in inputs:
            out, stats = os.path.join(tmp, "o.ply"), os.path.join(tmp, "s.json")
            base = [a.bin, "curvature", path, "-o", out, "--force"]
            run(base, env)  # warm the kernel cache
            lanes = ["--lanes", str(a.lanes)] if a.lanes else []
            schemes = [("atomic 1", ["--accumulate", "atomic", "--lanes", "1"]),
                       ("atomic", ["--accumulate", "atomic", *lanes]),
                       ("atomic-native", ["--accumulate", "atomic-native", *lanes]),
                       ("gather 1", ["--accumulate", "gather", "--lanes", "1"]),
                       ("gather", ["--accumulate", "gather", *lanes]),
                       ("gather input", ["--accumulate", "gather", "--order", "input", *lanes])]
            # Rounds through every scheme in turn, so that a slow spell of
            # the machine does not fall on one scheme: the median over the
            # rounds of each process's median.
            got = {key: [] for key, _ in schemes}
            for _ in range(a.rounds):
                for key, extra in schemes:
                    got[key].append(kernel_median(base, extra, stats, a.runs, env))
            k = {}
            for key, vals in got.items():
                ms = [v[0] for v in vals if v[0] is not None]
                k[key] = (statistics.median(ms) if ms else None, vals[0][1])
            # After `shapecue build-kernels` (what the README's install
            # runs): shapecue's own program cache filled, which an ordinary
            # run does not fill on PoCL.
            built_dir = os.path.join(tmp, "built-" + rt.split()[0])
            built_env = dict(env, SHAPECUE_CACHE_DIR=built_dir)
            if not os.path.isdir(built_dir):
                run([a.bin, "build-kernels"], built_env)
            built = timed(base, built_env, a.runs)
            cold = cold_built = None
            if name == "bunny":
                # Empty kernel caches, PoCL's own and shapecue's: a first run
                # with nothing built.
                fresh = tempfile.mkdtemp(dir=tmp)
                cold = timed(base, dict(env, POCL_CACHE_DIR=os.path.join(fresh, "pocl"),
                                        SHAPECUE_CACHE_DIR=os.path.join(fresh, "shapecue")), 1)
                # The first run after build-kernels, with PoCL's cache empty
                # (so that only shapecue's cache can have the kernels).
                fresh = tempfile.mkdtemp(dir=tmp)
                cold_built = timed(base, dict(built_env,
                                              POCL_CACHE_DIR=os.path.join(fresh, "pocl")), 1)
            kernel_rows.append((rt, name, k))
            process_rows.append((rt, name, timed(base, env, a.runs), built, cold, cold_built))
            print(f"{rt} {name}: done", file=sys.stderr)

    def tm2_cell(v, star, digits=1):
        return fmt(v, digits) + ("*" if star and v is not None else "")

    print("| runtime | mesh | atomic (compare-and-swap), 1 face per work-item | "
          "atomic (compare-and-swap), N faces per work-item | "
          "atomic (native float add), N faces | "
          "gather, 1 face per work-item | gather, N faces per work-item | "
          "the same in the file's order | trimesh2 | trimesh2 ÷ fastest |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for rt, name, k in kernel_rows:
        tk, _, star = tm2[name]
        lanes = k["gather"][1]
        # Fastest of the schemes in the order shapecue computes in by default.
        best = min(v[0] for key, v in k.items() if v[0] is not None and key != "gather input")
        ratio = "–" if tk is None else f"{tk / best:.2f}" + ("*" if star else "")
        print(f"| {rt} | {name} | {fmt(k['atomic 1'][0])} | {fmt(k['atomic'][0])} | "
              f"{fmt(k['atomic-native'][0])} | "
              f"{fmt(k['gather 1'][0])} | {fmt(k['gather'][0])} (N = {lanes}) | "
              f"{fmt(k['gather input'][0])} | {tm2_cell(tk, star)} | {ratio} |")
    print()
    print("| runtime | mesh | shapecue process | after `shapecue build-kernels` | "
          "trimesh2 process | shapecue first run, nothing built (empty kernel caches) | "
          "first run after `shapecue build-kernels` (PoCL's cache empty) |")
    print("|---|---|---|---|---|---|---|")
    for rt, name, proc, built, cold, cold_built in process_rows:
        _, tp, star = tm2[name]
        print(f"| {rt} | {name} | {proc:.0f} | {built:.0f} | {tm2_cell(tp, star, 0)}"
              f" | {fmt(cold, 0)} | {fmt(cold_built, 0)} |")


if __name__ == "__main__":
    main()
