"""Batches of shapecue jobs on a Dask distributed cluster.

Dask (``dask.distributed``) and not a scheduler of our own: it is pure
Python from PyPI, a ``LocalCluster`` runs in a test or on one machine with no
service to install, and the same code runs on a real cluster (``dask
scheduler`` / ``dask worker``, dask-jobqueue on SLURM/PBS, dask-kubernetes)
by handing :func:`run` a ``Client`` connected to it.

Each input is one task. A task runs on an OpenCL device opened in its
worker (``device=``, or the worker's ``SHAPECUE_DEVICE`` environment
variable, so one GPU per worker is set where the worker starts; a worker
thread opens it on its first task and reuses it), reads its input,
computes, writes its output into ``out_dir`` and returns a record; failures (a broken file, a device
error) are caught in the task and recorded, and the other tasks go on. The
client appends one JSON line per task to ``out_dir/manifest.jsonl``::

    {"input": ..., "output": ..., "status": "ok" | "error", "error": null | "...",
     "timings": {"load_ms": ..., "compute_ms": ..., "write_ms": ..., "total_ms": ...},
     "task": "curvature", "worker": "tcp://..."}

A rerun with the same ``out_dir`` skips the inputs whose last record is "ok"
and whose output still exists, so an interrupted batch resumes.

Tasks:

- ``"curvature"``: a mesh file (.obj/.ply/.off) to ``<stem>.npz`` with the
  arrays of :class:`shapecue.Curvature` (plus ``vertices`` and ``faces``);
- ``"isosurface"``: a volume file to ``<stem>.npz`` with ``vertices``,
  ``faces`` (and the curvature arrays with ``options={"curvature": True}``);
  ``options={"iso": value}`` is required;
- ``"render"``: a scene file, its images and report into ``<stem>/``;
- ``"lines"``: a mesh file's line drawings from many views
  (:func:`shapecue.lines` with ``cameras``) into ``<stem>/``: per view
  ``view_NNN.npz`` with the pieces (``a``, ``b``, ``kind``, ``strength``,
  ``visible``, ``chain``, provenance ``faces``, ``face``, ``bary``), the
  per-vertex fields (``ndotv``, ``kr``, ``dwkr``, ``q1``; unless
  ``options={"fields": False}``) and the camera (``eye``, ``target``,
  ``up``), and ``views.json`` (the family names of ``kind``, each view's
  camera and piece count, the timing). ``options``: ``views`` (a number of
  views, default 16) or ``cameras`` (a list of camera dicts, or a camera
  JSON file), ``lines``, ``size``, the thresholds of :func:`shapecue.lines`.
  The folder is written whole (made beside it, then renamed).
"""

from __future__ import annotations

import glob as _glob
import json
import os
import time
import traceback
import uuid
from typing import Any, Dict, Iterable, List, Optional, Union

import numpy as np

TASKS = ("curvature", "isosurface", "render", "lines")
MANIFEST = "manifest.jsonl"

__all__ = ["run", "read_manifest", "TASKS", "MANIFEST"]


def _inputs(inputs: Union[str, Iterable[str]]) -> List[str]:
    if isinstance(inputs, (str, os.PathLike)):
        found = sorted(_glob.glob(os.fspath(inputs)))
        if not found:
            raise ValueError(f"no file matches {os.fspath(inputs)!r}")
        return [os.path.abspath(p) for p in found]
    return [os.path.abspath(os.fspath(p)) for p in inputs]


def _output_name(path: str, task: str, out_dir: str) -> str:
    stem = os.path.splitext(os.path.basename(path))[0]
    if task in ("render", "lines"):
        return os.path.join(out_dir, stem)
    return os.path.join(out_dir, stem + ".npz")


def read_manifest(out_dir: Union[str, os.PathLike]) -> List[Dict[str, Any]]:
    """The records of ``out_dir/manifest.jsonl``, oldest first (a
    half-written last line from a killed client is ignored)."""
    path = os.path.join(os.fspath(out_dir), MANIFEST)
    out = []
    if not os.path.exists(path):
        return out
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            line = line.strip()
            if not line:
                continue
            try:
                out.append(json.loads(line))
            except json.JSONDecodeError:
                continue
    return out


def _curvature_arrays(prefix: str, c) -> Dict[str, np.ndarray]:
    keys = ("normals", "area", "k1", "k2", "d1", "d2", "dk")
    d = {prefix + k: getattr(c, k) for k in keys}
    d[prefix + "degenerate_faces"] = np.array(c.degenerate_faces)
    d[prefix + "vertices_without_curvature"] = np.array(c.vertices_without_curvature)
    return d


def _save_npz(path: str, arrays: Dict[str, np.ndarray]) -> None:
    # Written whole or not at all: a task killed mid-write leaves no output
    # that a rerun would take for finished.
    tmp = path + ".part.npz"
    np.savez(tmp, **arrays)
    os.replace(tmp, path)


def _lines_task(path: str, out: str, device: Optional[str], options: Dict[str, Any]) -> Dict[str, Any]:
    """The ``lines`` task: returns the record's extra fields and the
    compute-phase split (ms)."""
    import shutil

    import shapecue

    cameras = options.pop("cameras", None)
    n = options.pop("views", None)
    if cameras is not None and n is not None:
        raise ValueError("give views or cameras, not both")
    cameras = cameras if cameras is not None else int(n if n is not None else 16)
    fields = bool(options.pop("fields", True))
    t0 = time.perf_counter()
    v, f = shapecue.load_mesh(path)
    t1 = time.perf_counter()
    views = shapecue.lines(v, f, cameras=cameras, fields=fields, device=device, **options)
    t2 = time.perf_counter()
    part = f"{out}.part-{uuid.uuid4().hex[:8]}"
    os.makedirs(part)
    try:
        digits = max(3, len(str(len(views) - 1)))
        entries = []
        for i, view in enumerate(views):
            arrays = {
                k: getattr(view, k)
                for k in ("a", "b", "kind", "strength", "visible", "chain", "faces", "face", "bary")
            }
            arrays["visible"] = arrays["visible"].astype(np.uint8)
            for k in ("eye", "target", "up"):
                arrays[k] = np.asarray(view.camera[k], dtype=np.float32)
            if view.fields is not None:
                arrays.update(view.fields)
            name = f"view_{i:0{digits}d}.npz"
            np.savez(os.path.join(part, name), **arrays)
            entries.append(
                {"file": name, "camera": view.camera, "pieces": int(len(view.a)),
                 "passes_ms": view.passes_ms}
            )
        kind_names = _kind_names(views)
        doc = {
            "input": path,
            "vertices": int(len(v)),
            "faces": int(len(f)),
            "family_names": sorted(set(kind_names.values())),
            "kind_names": kind_names,
            "views": entries,
            "timing": {
                "load_ms": (t1 - t0) * 1e3,
                "compute_ms": (t2 - t1) * 1e3,
                "first_view_ms": views[0].passes_ms if views else 0.0,
                "later_views_ms": sum(x.passes_ms for x in views[1:]),
            },
        }
        with open(os.path.join(part, "views.json"), "w", encoding="utf-8") as fh:
            json.dump(doc, fh, indent=1)
        if os.path.isdir(out):
            shutil.rmtree(out)
        os.replace(part, out)
    except BaseException:
        shutil.rmtree(part, ignore_errors=True)
        raise
    later = len(views) - 1
    per_view = doc["timing"]["later_views_ms"] / later if later > 0 else None
    return {
        "views": len(views),
        "views_per_second": (1e3 / per_view) if per_view else None,
        "load_ms": (t1 - t0) * 1e3,
        "compute_ms": (t2 - t1) * 1e3,
    }


def _kind_names(views: List[Any]) -> Dict[str, str]:
    """The family name of each ``kind`` code the views hold."""
    names: Dict[str, str] = {}
    for x in views:
        kinds, first = np.unique(x.kind, return_index=True)
        for k, i in zip(kinds.tolist(), first.tolist()):
            names.setdefault(str(k), str(x.family[i]))
    return dict(sorted(names.items(), key=lambda kv: int(kv[0])))


def process_one(
    path: str, task: str, out_dir: str, options: Optional[Dict[str, Any]] = None
) -> Dict[str, Any]:
    """Runs one task on this process (a Dask worker, or the caller) and
    returns its manifest record; never raises for a failure of the input or
    the device, which is recorded as ``status: "error"``."""
    import shapecue

    options = dict(options or {})
    device = options.pop("device", None) or os.environ.get("SHAPECUE_DEVICE") or None
    out = _output_name(path, task, out_dir)
    rec: Dict[str, Any] = {
        "input": path,
        "output": out,
        "task": task,
        "status": "error",
        "error": None,
    }
    try:
        from distributed import get_worker

        rec["worker"] = get_worker().address
    except Exception:
        rec["worker"] = None
    t0 = time.perf_counter()
    timings = {"load_ms": 0.0, "compute_ms": 0.0, "write_ms": 0.0}
    try:
        if task == "curvature":
            v, f = shapecue.load_mesh(path, weld=bool(options.pop("weld", False)))
            t1 = time.perf_counter()
            c = shapecue.curvature(v, f, device=device, **options)
            t2 = time.perf_counter()
            arrays = {"vertices": v, "faces": f, **_curvature_arrays("", c)}
            _save_npz(out, arrays)
        elif task == "isosurface":
            if "iso" not in options:
                raise ValueError('the isosurface task needs options={"iso": value}')
            iso = float(options.pop("iso"))
            vol = shapecue.load_volume(path)
            t1 = time.perf_counter()
            s = shapecue.isosurface(vol, iso, device=device, **options)
            t2 = time.perf_counter()
            arrays = {"vertices": s.vertices, "faces": s.faces}
            if s.curvature is not None:
                arrays.update(_curvature_arrays("curvature_", s.curvature))
            _save_npz(out, arrays)
        elif task == "lines":
            extra = _lines_task(path, out, device, options)
            t1 = t0 + extra.pop("load_ms") / 1e3
            t2 = t1 + extra.pop("compute_ms") / 1e3
            rec.update(extra)
        elif task == "render":
            t1 = time.perf_counter()
            report = shapecue.render(path, out, device=device, force=True, **options)
            t2 = time.perf_counter()
            rec["passes"] = [p.get("pass", p.get("name")) for p in report.get("passes", [])]
        else:
            raise ValueError(f"unknown task {task!r}: expected one of {', '.join(TASKS)}")
        t3 = time.perf_counter()
        timings = {
            "load_ms": (t1 - t0) * 1e3,
            "compute_ms": (t2 - t1) * 1e3,
            "write_ms": (t3 - t2) * 1e3,
        }
        rec["status"] = "ok"
    except Exception as e:  # recorded, the batch goes on
        rec["error"] = f"{type(e).__name__}: {e}"
        if not isinstance(e, (ValueError, OSError, RuntimeError)):
            rec["traceback"] = traceback.format_exc()
    timings["total_ms"] = (time.perf_counter() - t0) * 1e3
    rec["timings"] = timings
    return rec


def _check_resources(client: Any, resources: Dict[str, float]) -> None:
    """Raises where no worker of the cluster offers every resource a task
    asks for: Dask would hold the tasks forever, waiting for one."""
    workers = client.scheduler_info().get("workers", {})
    offered = [w.get("resources") or {} for w in workers.values()]
    if any(all(r.get(k, 0) >= v for k, v in resources.items()) for r in offered):
        return
    want = ", ".join(f"{k}={v:g}" for k, v in resources.items())
    seen = sorted({f"{k}={v:g}" for r in offered for k, v in r.items()})
    have = ", ".join(seen) if seen else "none"
    raise ValueError(
        f"no worker of the cluster offers the resources {want} that each task asks for "
        f"({len(workers)} worker(s); resources offered: {have}); start workers with "
        f"'dask worker ... --resources \"{want.replace(', ', ' ')}\"', or leave resources out"
    )


def run(
    inputs: Union[str, Iterable[str]],
    out_dir: Union[str, os.PathLike],
    *,
    task: str = "curvature",
    options: Optional[Dict[str, Any]] = None,
    client: Any = None,
    resources: Optional[Dict[str, float]] = None,
) -> List[Dict[str, Any]]:
    """Runs ``task`` over ``inputs`` (a list of paths, or a glob pattern) on
    the Dask cluster of ``client`` (default: the current client, else a
    ``LocalCluster`` for this call), writing outputs and
    ``out_dir/manifest.jsonl``. Returns the records of this run (skipped
    inputs are not run again and have no record here).

    ``options`` go to the shapecue call (``accumulate``, ``precision``,
    ``iso``, ``fusion``, ``curvature``, ``device``, ...). ``resources``,
    e.g. ``{"GPU": 1}``, are passed to ``client.submit`` so that each task
    takes one unit of a worker resource (start workers with
    ``dask worker ... --resources GPU=1`` and ``SHAPECUE_DEVICE=<index>``).
    A client's cluster with no worker that offers them is refused at once
    (Dask would wait for one forever); the ``LocalCluster`` made without a
    client gives each of its workers those resources.
    """
    if task not in TASKS:
        raise ValueError(f"unknown task {task!r}: expected one of {', '.join(TASKS)}")
    if task == "isosurface" and "iso" not in (options or {}):
        raise ValueError('the isosurface task needs options={"iso": value}')
    out_dir = os.path.abspath(os.fspath(out_dir))
    os.makedirs(out_dir, exist_ok=True)
    paths = _inputs(inputs)
    outs = {}
    for p in paths:
        o = _output_name(p, task, out_dir)
        if o in outs and outs[o] != p:
            raise ValueError(f"{outs[o]} and {p} would both write {o}: give inputs distinct names")
        outs[o] = p
    last = {}
    for r in read_manifest(out_dir):
        if r.get("task") == task:
            last[r.get("input")] = r
    todo = [
        p
        for p in paths
        if not (
            last.get(p, {}).get("status") == "ok" and os.path.exists(last[p].get("output", ""))
        )
    ]
    if not todo:
        return []

    from distributed import Client, LocalCluster, as_completed

    own = None
    if client is None:
        try:
            from distributed import get_client

            client = get_client()
        except ValueError:
            # Each local worker offers the resources asked for, so that
            # the tasks can be scheduled on it.
            own = LocalCluster(
                n_workers=min(2, os.cpu_count() or 1),
                threads_per_worker=1,
                dashboard_address=None,
                resources=dict(resources) if resources else None,
            )
            client = Client(own)
    records = []
    manifest = os.path.join(out_dir, MANIFEST)
    try:
        if resources and own is None:
            _check_resources(client, resources)
        # Keys unique per run: a key the cluster still holds would hand back
        # that earlier result instead of running the task again.
        run_id = uuid.uuid4().hex[:8]
        futures = {
            client.submit(
                process_one,
                p,
                task,
                out_dir,
                options,
                key=f"shapecue-{task}-{os.path.basename(p)}-{run_id}-{i}",
                resources=resources,
                pure=False,
            ): p
            for i, p in enumerate(todo)
        }
        with open(manifest, "a", encoding="utf-8") as fh:
            for fut in as_completed(futures):
                try:
                    rec = fut.result()
                except Exception as e:  # the worker died, or the task could not be shipped
                    p = futures[fut]
                    rec = {
                        "input": p,
                        "output": _output_name(p, task, out_dir),
                        "task": task,
                        "status": "error",
                        "error": f"{type(e).__name__}: {e}",
                        "timings": {},
                        "worker": None,
                    }
                fh.write(json.dumps(rec) + "\n")
                fh.flush()
                records.append(rec)
    finally:
        if own is not None:
            client.close()
            own.close()
    return records
