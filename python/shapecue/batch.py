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
and whose output still exists (for the ``lines`` task, made with the same
options), so an interrupted batch resumes.

Tasks:

- ``"curvature"``: a mesh file (.obj/.ply/.off) to ``<stem>.npz`` with the
  arrays of :class:`shapecue.Curvature` (plus ``vertices`` and ``faces``);
  the file is read by the library's loader (``options={"weld": True}``
  welds it) and the curvature starts from the normals it stores, unless
  ``options={"normals": "computed"}`` (as ``shapecue curvature
  --normals``);
- ``"isosurface"``: a volume file to ``<stem>.npz`` with ``vertices``,
  ``faces`` (and the curvature arrays with ``options={"curvature": True}``);
  ``options={"iso": value}`` is required;
- ``"render"``: a scene file, its images and report into ``<stem>/``;
- ``"lines"``: a mesh file's line drawings from many views
  (:func:`shapecue.lines` with ``cameras``) into ``<stem>/``, the files of
  ``shapecue lines MESH --views N --out DIR --npz --fields`` under their
  names and byte for byte: per view ``<stem>_f0000_v<NN>_segments.npz``
  (the pieces: ``a``, ``b``, ``family`` (uint32 codes), ``strength``,
  ``visible``, ``faces``, ``chain``, ``face``, ``bary``, then the code
  table ``family_codes`` (uint32) and ``family_names`` (``<U24``;
  ``family_names[i]`` names code ``family_codes[i]``, as
  :data:`shapecue.FAMILY_CODES`)) and, unless ``options={"fields":
  False}``, ``<stem>_f0000_v<NN>_fields.npz`` (the per-vertex ``ndotv``,
  ``kr``, ``dwkr``, ``q1``); ``<NN>`` the view's index with 2 digits, or as
  many as the last index needs. The bytes are the library's, made from the
  same arrays as the command line's. Then ``views.json``: the input, its
  vertex and face counts, the device, the options, the code table
  ``family_codes`` of the command line's manifest, and per view its
  ``index``, ``camera`` (eye, target, up, fov, ortho, near, far), piece
  count and ``files`` (``{"name", "sha256"}`` each, as the command line's
  manifest lists a view's files). ``options``: ``views`` (a number of views,
  default 16) or ``cameras`` (a list of camera dicts, or a camera JSON
  file), ``fields``, and the keyword options of :func:`shapecue.lines`
  (``lines``, ``size``, ``fov``, ``ortho``, the thresholds, ``normals``
  "file" or "computed", ...), checked
  by :func:`run` before any task starts. The folder is written whole
  (made beside it, then renamed). The task's record adds the options as
  ``views.json`` lists them, ``views``, ``views_per_second`` (the views
  over the wall-clock time of computing them) and, in ``timings``, the
  wall-clock ``first_view_ms`` (device set-up and the pose passes
  included) and ``later_views_ms``. A rerun redoes an input whose
  options changed. (Before, each view was one ``view_NNN.npz`` holding
  the pieces, the fields and the camera; the cameras are in
  ``views.json``.)

The curvature, isosurface and lines tasks give the same bytes for the same
inputs and options: the NPZ files are written with fixed zip time stamps
(``numpy.savez`` stamps the time of writing; the lines task's are the
library's bytes, as the command line writes them) and ``views.json`` holds no
timing; the run's timings and workers are in ``manifest.jsonl`` (and a
render task's scene report, written by the library, has its own).
"""

from __future__ import annotations

import glob as _glob
import hashlib
import inspect
import json
import os
import time
import traceback
import uuid
import zipfile
from typing import Any, Dict, Iterable, List, Optional, Tuple, Union

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


#: The time stamp of every zip entry the batch writes (the earliest a zip
#: holds): np.savez stamps the current time, so its bytes differ run to run.
_ZIP_TIME = (1980, 1, 1, 0, 0, 0)


def _write_npz(path: str, arrays: Dict[str, Any]) -> None:
    """An uncompressed NPZ, as :func:`numpy.savez` writes it (``np.load``
    reads it) but the same bytes for the same arrays: fixed time stamps and
    attributes, entries in the order given."""
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_STORED, allowZip64=True) as zf:
        for name, a in arrays.items():
            info = zipfile.ZipInfo(name + ".npy", date_time=_ZIP_TIME)
            info.create_system = 3
            info.external_attr = 0o644 << 16
            with zf.open(info, "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, np.asanyarray(a), allow_pickle=False)


def _save_npz(path: str, arrays: Dict[str, np.ndarray]) -> None:
    # Written whole or not at all: a task killed mid-write leaves no output
    # that a rerun would take for finished.
    tmp = path + ".part.npz"
    try:
        _write_npz(tmp, arrays)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def _jsonable(x: Any) -> Any:
    """``x`` as JSON holds it: tuples and numpy arrays as lists, numpy
    scalars as numbers."""
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, os.PathLike):
        return os.fspath(x)
    return x


def _sha256(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


#: What the lines task takes besides the keyword options of shapecue.lines.
_LINES_TASK_KEYS = ("views", "cameras", "fields", "device")
#: Keyword options of shapecue.lines the task does not take: they set the
#: one camera of a single view.
_LINES_ONE_EYE = ("eye", "direction", "target", "up")
#: Keyword options of shapecue.lines the task sets itself: it always
#: writes the files' bytes.
_LINES_SET = ("npz",)


def _lines_defaults() -> Dict[str, Any]:
    """The keyword options of :func:`shapecue.lines` the task passes on,
    with their defaults."""
    import shapecue

    skip = set(_LINES_TASK_KEYS) | set(_LINES_ONE_EYE) | set(_LINES_SET)
    return {
        k: p.default
        for k, p in inspect.signature(shapecue.lines).parameters.items()
        if p.kind is inspect.Parameter.KEYWORD_ONLY and k not in skip
    }


def _lines_options(options: Optional[Dict[str, Any]]) -> Tuple[Dict[str, Any], Dict[str, Any]]:
    """The ``lines`` task's options checked: the keywords of
    :func:`shapecue.lines` (cameras and fields included, the device not) and
    the options as the output and the record list them (every option with
    its default filled in, the families in code order, a camera file's
    SHA-256), so that a rerun compares them. Raises :class:`ValueError`
    naming the option for an unknown one, ``views`` and ``cameras``
    together, a count of views outside 1 to 10000, cameras the library
    would refuse, unknown families, and isophotes of no level."""
    import shapecue
    from shapecue import _shapecue

    given = dict(options or {})
    given.pop("device", None)
    defaults = _lines_defaults()
    for k in given:
        if k in _LINES_ONE_EYE:
            raise ValueError(
                f"the lines task: option {k!r} sets the one camera of shapecue.lines; the task "
                f"draws views: give views (a number) or cameras (a list or a camera file)"
            )
        if k not in defaults and k not in _LINES_TASK_KEYS:
            known = ", ".join(sorted(set(defaults) | set(_LINES_TASK_KEYS)))
            raise ValueError(f"the lines task: unknown option {k!r}: the options are {known}")
    views = given.pop("views", None)
    cameras = given.pop("cameras", None)
    if views is not None and cameras is not None:
        raise ValueError("the lines task: give the option views or cameras, not both")
    if views is not None:
        if isinstance(views, (bool, np.bool_)) or not isinstance(views, (int, np.integer)):
            raise ValueError(
                f"the lines task: views={views!r}: give a number of views from 1 to "
                f"{_shapecue.MAX_VIEWS}"
            )
        if not 1 <= int(views) <= _shapecue.MAX_VIEWS:
            raise ValueError(
                f"the lines task: views={int(views)}: give a number of views from 1 to "
                f"{_shapecue.MAX_VIEWS}"
            )
        views = int(views)
    elif cameras is None:
        views = 16
    fields = given.pop("fields", True)
    if not isinstance(fields, (bool, np.bool_)):
        raise ValueError(f"the lines task: fields={fields!r}: give True or False")
    merged = {**defaults, **given}
    names = merged["lines"]
    try:
        families = _shapecue.line_families(names if isinstance(names, str) else ",".join(names))
    except ValueError as e:
        raise ValueError(f"the lines task: option lines: {e}") from None
    if not families:
        raise ValueError(f"the lines task: lines={names!r} names no line family")
    levels = shapecue._levels(merged["isophotes"])
    if "isophotes" in families and levels == 0:
        raise ValueError("the lines task: isophotes=0: isophotes need at least 1 level")
    if not isinstance(merged["normals"], str) or merged["normals"] not in ("file", "computed"):
        raise ValueError(
            f"the lines task: normals={merged['normals']!r}: give 'file' (the normals the mesh "
            f"files store, if any) or 'computed' (from the faces)"
        )
    fov, ortho = float(merged["fov"]), bool(merged["ortho"])
    doc: Dict[str, Any] = {"views": views, "cameras": None}
    if cameras is not None:
        text, file, n = shapecue._camera_set(cameras)
        _shapecue.check_cameras(text, file, n, fov, ortho)
        if file is not None:
            file = os.path.abspath(file)
            doc["cameras"] = file
            doc["cameras_sha256"] = _sha256(file)
            cameras = file
        elif n is not None:
            doc["views"] = n
        else:
            doc["cameras"] = json.loads(text)["cameras"]
    else:
        _shapecue.check_cameras(None, None, views, fov, ortho)
    doc["fields"] = bool(fields)
    doc.update(_jsonable({k: v for k, v in merged.items() if k != "lines"}))
    doc["lines"] = list(families)
    doc = json.loads(json.dumps(doc, sort_keys=True))
    kwargs = dict(merged, cameras=cameras if cameras is not None else views, fields=bool(fields))
    return kwargs, doc


def _lines_task(path: str, out: str, device: Optional[str], options: Dict[str, Any]) -> Dict[str, Any]:
    """The ``lines`` task: returns the record's extra fields and the
    compute-phase split (ms)."""
    import shutil

    import shapecue
    from shapecue import _shapecue

    kwargs, doc_options = _lines_options(options)
    t0 = time.perf_counter()
    # Read by the library's loader, as `shapecue lines FILE --normals ...`.
    mesh = _shapecue.load_mesh(path, False, kwargs.pop("normals"))
    t1 = time.perf_counter()
    views = shapecue.lines(mesh, device=device, npz=True, **kwargs)
    t2 = time.perf_counter()
    codes = sorted(shapecue.FAMILY_CODES.items())
    stem = os.path.splitext(os.path.basename(path))[0] or "mesh"
    part = f"{out}.part-{uuid.uuid4().hex[:8]}"
    os.makedirs(part)
    try:
        # The command line's names (output_paths in the library): the view
        # number with 2 digits, or as many as the last index needs.
        digits = max(2, len(str(len(views) - 1)))
        entries = []
        for i, view in enumerate(views):
            files = []
            for what in ("segments", "fields"):
                data = view.npz.get(what)
                if data is None:
                    continue
                name = f"{stem}_f0000_v{i:0{digits}d}_{what}.npz"
                with open(os.path.join(part, name), "wb") as fh:
                    fh.write(data)
                files.append({"name": name, "sha256": hashlib.sha256(data).hexdigest()})
            entries.append(
                {"index": i, "camera": view.camera, "pieces": int(len(view.a)), "files": files}
            )
        doc = {
            "input": path,
            "vertices": int(mesh.n_vertices),
            "faces": int(mesh.n_faces),
            "device": views[0].device if views else None,
            "options": doc_options,
            "family_codes": {str(c): n for c, n in codes},
            "views": entries,
        }
        with open(os.path.join(part, "views.json"), "w", encoding="utf-8") as fh:
            json.dump(doc, fh, indent=1)
            fh.write("\n")
        if os.path.isdir(out):
            shutil.rmtree(out)
        os.replace(part, out)
    except BaseException:
        shutil.rmtree(part, ignore_errors=True)
        raise
    compute_s = t2 - t1
    return {
        "options": doc_options,
        "views": len(views),
        # Wall clock: the views over the time the call computing them took
        # (not the passes' own clocks, which leave out what lies between).
        "views_per_second": len(views) / compute_s if views and compute_s > 0 else None,
        "first_view_ms": views[0].wall_ms if views else 0.0,
        "later_views_ms": float(sum(x.wall_ms for x in views[1:])),
        "load_ms": (t1 - t0) * 1e3,
        "compute_ms": compute_s * 1e3,
    }


def process_one(
    path: str, task: str, out_dir: str, options: Optional[Dict[str, Any]] = None
) -> Dict[str, Any]:
    """Runs one task on this process (a Dask worker, or the caller) and
    returns its manifest record; never raises for a failure of the input or
    the device, which is recorded as ``status: "error"``."""
    import shapecue
    from shapecue import _shapecue

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
            # Read by the library's loader, the file's stored normals kept
            # unless options={"normals": "computed"} (as --normals).
            weld = bool(options.pop("weld", False))
            normals = options.pop("normals", "file")
            if not isinstance(normals, str):
                raise ValueError(
                    f"the curvature task: normals={normals!r}: give 'file' or 'computed'"
                )
            mesh = _shapecue.load_mesh(path, weld, normals)
            v, f, _ = mesh.arrays()
            t1 = time.perf_counter()
            c = shapecue.curvature(mesh, device=device, **options)
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
            view_ms = {k: extra.pop(k) for k in ("first_view_ms", "later_views_ms")}
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
        if task == "lines":
            timings.update(view_ms)
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
    ``iso``, ``fusion``, ``curvature``, ``device``, ...). The isosurface
    task's ``iso`` and the lines task's options (known names, ``views`` from
    1 to 10000 or ``cameras``, not both, the families, the cameras
    themselves) are checked here, before any cluster or client is started
    or asked for: a bad one raises :class:`ValueError` and nothing runs. ``resources``,
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
    # The lines task's options are checked here, before any cluster starts,
    # and listed as its records list them, to find the inputs whose options
    # changed since their last run.
    wanted = _lines_options(options)[1] if task == "lines" else None
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
    def finished(p: str) -> bool:
        r = last.get(p, {})
        same = wanted is None or r.get("options") == wanted
        return r.get("status") == "ok" and same and os.path.exists(r.get("output", ""))

    todo = [p for p in paths if not finished(p)]
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
