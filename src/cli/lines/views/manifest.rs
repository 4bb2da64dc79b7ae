//! `manifest.json` of a many-views run: what made it (the shapecue
//! version, the mesh and its SHA-256, every option that changes the output,
//! the device) and each finished view with its camera and its files'
//! SHA-256. It is written as the views finish (atomically, so it is always
//! whole), which makes an interrupted or failed run one that `--resume`
//! continues; and it lets `--force` remove the files of the run it replaces,
//! and only those, so that a folder holds one run.
//!
//! Everything in it but `timing` is a function of the inputs and options:
//! two runs of the same command write the same bytes.

use super::super::LinesArgs;
use anyhow::{Result, bail};
use serde_json::{Map, Value, json};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The SHA-256 of a file, as 64 lowercase hex digits.
pub fn sha256_file(path: &Path) -> shapecue::Result<String> {
    let io = |source| shapecue::Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut f = std::fs::File::open(path).map_err(io)?;
    let mut h = Sha256::new();
    std::io::copy(&mut f, &mut h).map_err(io)?;
    Ok(hex(&h.finalize()))
}

/// The SHA-256 of bytes in memory, as [`sha256_file`] gives it.
pub fn sha256_bytes(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// A resolved camera as the manifest lists it.
pub fn camera_doc(cam: &shapecue::api::Camera) -> Value {
    json!({
        "eye": cam.eye.to_array(),
        "target": cam.target.to_array(),
        "up": cam.up.to_array(),
        "fov": cam.fov_y_deg,
        "ortho": cam.ortho_height,
        "near": cam.near,
        "far": cam.far,
    })
}

/// The keys that say what made a run: a run may continue another only when
/// every one of them is equal.
const IDENTITY: [&str; 6] = [
    "shapecue",
    "mesh",
    "mesh_sha256",
    "options",
    "view_count",
    "device",
];

/// What the manifest says of the run as a whole.
pub struct Head {
    doc: Map<String, Value>,
}

impl Head {
    /// A head with nothing in it (tests of the run's writer).
    #[cfg(test)]
    pub fn empty() -> Head {
        Head { doc: Map::new() }
    }

    /// The head of the run of `a` on `mesh` (its file hashed, or the
    /// generated mesh's name and size) on the device named `device`.
    pub fn new(
        a: &LinesArgs,
        c: &super::super::Common,
        mesh: &shapecue::Mesh,
        device: &str,
        view_count: usize,
        options: Value,
    ) -> Result<Head> {
        let mesh_sha = match c.generated {
            Some(_) => Value::Null,
            None => sha256_file(&c.path)?.into(),
        };
        let mut doc = Map::new();
        doc.insert("shapecue".into(), env!("CARGO_PKG_VERSION").into());
        doc.insert("mesh".into(), a.mesh.clone().into());
        doc.insert("mesh_sha256".into(), mesh_sha);
        doc.insert("vertices".into(), mesh.n_vertices().into());
        doc.insert("faces".into(), mesh.n_faces().into());
        doc.insert("options".into(), options);
        doc.insert("device".into(), device.into());
        doc.insert("view_count".into(), view_count.into());
        Ok(Head { doc })
    }

    /// Adds a key of the run as a whole (the report's name, the family
    /// codes).
    pub fn insert(&mut self, key: &str, value: Value) {
        self.doc.insert(key.into(), value);
    }
}

/// One finished view's entry: its index, and its camera and files as the
/// manifest lists them.
pub struct ViewEntry {
    pub index: usize,
    pub doc: Value,
}

/// The manifest an earlier run left in the folder.
pub struct Earlier {
    /// Its document, `None` where the file is not a manifest of this
    /// program (not JSON, or without its keys).
    doc: Option<Value>,
}

/// The manifest at `path`, if there is a file.
pub fn read(path: &Path) -> Result<Option<Earlier>> {
    if !path.exists() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(path);
    let doc = (text.ok())
        .and_then(|t| serde_json::from_str::<Value>(&t).ok())
        .filter(|d| d.get("shapecue").is_some() && d.get("views").is_some_and(Value::is_array));
    Ok(Some(Earlier { doc }))
}

/// A plain file name of the folder (no folder part, no `..`), as the
/// manifest lists them; `None` for anything else, which is never touched.
fn plain_name(v: &Value) -> Option<&str> {
    let n = v.as_str()?;
    let p = Path::new(n);
    let plain = p.components().count() == 1
        && matches!(p.components().next(), Some(std::path::Component::Normal(_)));
    plain.then_some(n)
}

impl Earlier {
    /// The renderer the earlier run named, if any.
    pub fn renderer(&self) -> Option<Value> {
        self.doc.as_ref()?.get("renderer").cloned()
    }

    /// The views of the earlier run that `--resume` keeps: those whose every
    /// file is there with the SHA-256 the manifest gives. Refuses a folder
    /// whose manifest is not this program's, or whose run differs from
    /// `head` (another mesh, option, camera set, device or version).
    pub fn views_to_keep(&self, head: &Head, path: &Path, out: &Path) -> Result<Vec<ViewEntry>> {
        let Some(doc) = &self.doc else {
            bail!(
                "--resume: {} is not a manifest of a shapecue lines run; nothing to continue",
                path.display()
            );
        };
        for key in IDENTITY {
            let (was, now) = (doc.get(key).unwrap_or(&Value::Null), &head.doc[key]);
            if was != now {
                bail!(
                    "--resume: the earlier run in {} had another {}{}; run without --resume \
                     (with --force to replace it)",
                    out.display(),
                    describe(key),
                    differing(was, now)
                );
            }
        }
        let count = head.doc["view_count"].as_u64().unwrap_or(0) as usize;
        let mut kept = Vec::new();
        for v in doc["views"].as_array().into_iter().flatten() {
            let Some(index) = v["index"].as_u64().map(|i| i as usize) else {
                continue;
            };
            if index >= count || kept.iter().any(|k: &ViewEntry| k.index == index) {
                continue;
            }
            let files = v["files"].as_array().map(Vec::as_slice).unwrap_or(&[]);
            let whole = !files.is_empty()
                && files.iter().all(|f| {
                    let (Some(name), Some(sha)) = (plain_name(&f["name"]), f["sha256"].as_str())
                    else {
                        return false;
                    };
                    sha256_file(&out.join(name)).is_ok_and(|h| h == sha)
                });
            if whole {
                kept.push(ViewEntry {
                    index,
                    doc: v.clone(),
                });
            }
        }
        Ok(kept)
    }

    /// With `--force`: removes the files the earlier run's manifest lists
    /// (its views and its report) that this run does not write, so that the
    /// folder holds one run. Only listed plain names in `out` are removed,
    /// never one of `inputs`, and nothing at all where the manifest is not
    /// this program's.
    pub fn remove_stale(&self, out: &Path, this_run: &[Vec<PathBuf>], inputs: &[&Path]) {
        let Some(doc) = &self.doc else {
            return;
        };
        let ours: Vec<PathBuf> = this_run.iter().flatten().cloned().collect();
        let listed = (doc["views"].as_array().into_iter().flatten())
            .flat_map(|v| v["files"].as_array().into_iter().flatten())
            .map(|f| &f["name"])
            .chain([&doc["report"]]);
        for name in listed.filter_map(plain_name) {
            let p = out.join(name);
            let same = |q: &Path| shapecue::export::output::same_file(q, &p);
            if ours.iter().any(|q| q == &p) || inputs.iter().any(|q| same(q)) {
                continue;
            }
            let _ = std::fs::remove_file(&p);
        }
    }
}

/// A key of the identity in words.
fn describe(key: &str) -> &'static str {
    match key {
        "shapecue" => "shapecue version",
        "mesh" => "mesh",
        "mesh_sha256" => "mesh file content",
        "options" => "set of options",
        "view_count" => "number of views",
        _ => "device",
    }
}

/// What differs between two values of a key, briefly: the option names
/// whose values differ, or both values.
fn differing(was: &Value, now: &Value) -> String {
    match (was, now) {
        (Value::Object(a), Value::Object(b)) => {
            let keys: Vec<&str> = (a.keys().chain(b.keys()))
                .filter(|k| a.get(*k) != b.get(*k))
                .map(String::as_str)
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect();
            format!(" ({})", keys.join(", "))
        }
        _ => format!(" ({was} then, {now} now)"),
    }
}

/// The manifest as the run goes: the head, the views finished (kept from
/// an earlier run, or computed now), written whole each time.
pub struct Log {
    head: Head,
    views: BTreeMap<usize, Value>,
    path: PathBuf,
    started: Instant,
    /// Wall time spent writing the manifest so far.
    write_ms: f64,
}

impl Log {
    /// The log of a run with `head`, starting from the views `kept`.
    pub fn new(head: Head, kept: Vec<ViewEntry>, path: PathBuf) -> Log {
        Log {
            head,
            views: kept.into_iter().map(|v| (v.index, v.doc)).collect(),
            path,
            started: Instant::now(),
            write_ms: 0.0,
        }
    }

    /// A view finished.
    pub fn push(&mut self, v: ViewEntry) {
        self.views.insert(v.index, v.doc);
    }

    /// The views listed.
    pub fn views(&self) -> usize {
        self.views.len()
    }

    /// Writes the manifest of an unfinished run; `timing` only at the end.
    pub fn write(&mut self, end: Option<(Value, Option<Value>)>) -> Result<()> {
        let t = Instant::now();
        let mut doc = self.head.doc.clone();
        doc.insert(
            "complete".into(),
            Value::Bool(end.is_some() && self.views.len() == self.view_count()),
        );
        doc.insert(
            "views".into(),
            Value::Array(self.views.values().cloned().collect()),
        );
        if let Some((renderer, timing)) = end {
            doc.insert("renderer".into(), renderer);
            if let Some(t) = timing {
                doc.insert("timing".into(), t);
            }
        }
        let text = serde_json::to_string_pretty(&Value::Object(doc))? + "\n";
        shapecue::export::output::write_bytes_atomic(&self.path, text.as_bytes())?;
        self.write_ms += t.elapsed().as_secs_f64() * 1e3;
        Ok(())
    }

    /// Writes the manifest after a view while that costs at most 2 % of
    /// the run's time (after every view where views take far longer than
    /// a write, less often where they are quick; `--resume` computes the
    /// views finished since the last write again).
    pub fn write_now_and_then(&mut self) -> shapecue::Result<()> {
        let elapsed = self.started.elapsed().as_secs_f64() * 1e3;
        if self.write_ms <= 0.02 * elapsed {
            self.write(None)
                .map_err(|e| match e.downcast::<shapecue::Error>() {
                    Ok(e) => e,
                    Err(e) => shapecue::Error::InvalidArgument(e.to_string()),
                })?;
        }
        Ok(())
    }

    /// The run's views in all.
    fn view_count(&self) -> usize {
        self.head.doc["view_count"].as_u64().unwrap_or(0) as usize
    }

    /// Writes the finished run's manifest: the renderer (`None` where no
    /// view was computed now: the earlier run's) and the timing of what
    /// this run computed.
    pub fn finish(&mut self, renderer: Option<String>, timing: Option<Value>) -> Result<()> {
        let renderer = renderer.map_or_else(
            || {
                self.head
                    .doc
                    .get("renderer")
                    .cloned()
                    .unwrap_or(Value::Null)
            },
            Value::from,
        );
        self.write(Some((renderer, timing)))
    }
}
