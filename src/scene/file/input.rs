//! `[input]` and `[frames]` checked: exactly one source, the keys that go
//! with it, and the frames to read from it.

use super::raw::{FramesSpec, InputSpec};
use super::{Checker, Source};
use crate::error::Result;
use crate::scene::planner::Input;
use std::ops::Range;
use toml::Spanned;

/// `[input]`, resolved.
pub(super) struct InputPart {
    /// Where the geometry comes from.
    pub source: Source,
    /// Weld mesh files.
    pub weld: bool,
    /// Keep or drop the normals mesh files store.
    pub normals: crate::mesh::NormalsSource,
    /// The source's key (`mesh`, `gltf`, ...), for errors that name it.
    pub kind: &'static str,
}

/// Checks `[input]`: one source, only the keys that apply to it.
pub(super) fn resolve(ck: &Checker<'_>, input: Spanned<InputSpec>) -> Result<InputPart> {
    let span = input.span();
    let inp = input.into_inner();
    let table = Table {
        ck,
        span,
        inp: &inp,
    };
    let kind = table.the_source()?;
    table.keys_apply(kind)?;
    let source = table.source()?;
    if let Source::Generate(_, n) = &source
        && !(12..=20_000_000).contains(n)
    {
        return Err(table.err(format!(
            "resolution {n}: a generated mesh needs 12..=20000000 vertices"
        )));
    }
    let normals = match &inp.normals {
        None => crate::mesh::NormalsSource::default(),
        Some(v) => v
            .get_ref()
            .parse()
            .map_err(|e: crate::error::Error| ck.err(v.span(), format!("input.normals: {e}")))?,
    };
    Ok(InputPart {
        source,
        weld: inp.weld,
        normals,
        kind,
    })
}

/// The `[input]` table with its span, for errors that name the table.
struct Table<'a> {
    ck: &'a Checker<'a>,
    span: Range<usize>,
    inp: &'a InputSpec,
}

impl Table<'_> {
    /// An error at the `[input]` table.
    fn err(&self, problem: impl Into<String>) -> crate::error::Error {
        self.ck.err(self.span.clone(), problem)
    }

    /// The key of the one source given; none or several is an error.
    fn the_source(&self) -> Result<&'static str> {
        let inp = self.inp;
        let given: Vec<&'static str> = [
            ("mesh", inp.mesh.is_some()),
            ("meshes", inp.meshes.is_some()),
            ("generate", inp.generate.is_some()),
            ("gltf", inp.gltf.is_some()),
            ("flipbook", inp.flipbook.is_some()),
            ("lbs", inp.lbs.is_some()),
            ("volume", inp.volume.is_some()),
            ("sdf", inp.sdf.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, g)| g.then_some(k))
        .collect();
        if given.len() != 1 {
            return Err(self.err(format!(
                "[input] needs exactly one of mesh, meshes, generate, gltf, flipbook, lbs, volume, sdf; got {}",
                if given.is_empty() {
                    "none".to_string()
                } else {
                    given.join(", ")
                }
            )));
        }
        Ok(given[0])
    }

    /// Checks that `clip`, `iso`, `resolution`, `inside`, `weld` and
    /// `normals` go with the `kind` source.
    fn keys_apply(&self, kind: &str) -> Result<()> {
        let inp = self.inp;
        let only = |key: &str, ok: bool| -> Result<()> {
            if ok {
                Ok(())
            } else {
                Err(self.err(format!("`{key}` does not apply to a {kind} input")))
            }
        };
        only("clip", inp.clip.is_none() || inp.gltf.is_some())?;
        only(
            "iso",
            inp.iso.is_none() || inp.volume.is_some() || inp.sdf.is_some(),
        )?;
        only(
            "resolution",
            inp.resolution.is_none() || inp.generate.is_some() || inp.sdf.is_some(),
        )?;
        only(
            "inside",
            inp.inside.is_none() || inp.volume.is_some() || inp.sdf.is_some(),
        )?;
        only(
            "weld",
            !inp.weld
                || inp.mesh.is_some()
                || inp.meshes.is_some()
                || inp.flipbook.is_some()
                || inp.gltf.is_some()
                || inp.lbs.is_some(),
        )?;
        only(
            "normals",
            inp.normals.is_none() || inp.mesh.is_some() || inp.meshes.is_some(),
        )
    }

    /// Whether the object is above the isovalue (`inside`, or `default`).
    fn above(&self, default: bool) -> Result<bool> {
        match &self.inp.inside {
            None => Ok(default),
            Some(v) => match v.get_ref().as_str() {
                "above" => Ok(true),
                "below" => Ok(false),
                other => Err(self.ck.err(
                    v.span(),
                    format!("inside = {other:?}: expected \"above\" or \"below\""),
                )),
            },
        }
    }

    /// The source, its files found and its parameters checked.
    fn source(&self) -> Result<Source> {
        let (ck, inp) = (self.ck, self.inp);
        Ok(if let Some(m) = &inp.mesh {
            Source::Mesh(ck.existing(m)?)
        } else if let Some(ms) = &inp.meshes {
            self.meshes(ms)?
        } else if let Some(g) = &inp.generate {
            use crate::mesh::GENERATED_NAMES as NAMES;
            if !NAMES.contains(&g.get_ref().as_str()) {
                let (got, want) = (g.get_ref(), crate::error::one_of(&NAMES));
                return Err(ck.err(g.span(), format!("generate = {got:?}: expected {want}")));
            }
            Source::Generate(g.get_ref().clone(), inp.resolution.unwrap_or(40_000))
        } else if let Some(g) = &inp.gltf {
            let clip = inp.clip.as_ref().map(|c| c.get_ref().clone());
            Source::Gltf(ck.existing(g)?, clip)
        } else if let Some(f) = &inp.flipbook {
            let pat = ck.relative(f.get_ref());
            Source::Flipbook(pat.to_string_lossy().into_owned())
        } else if let Some(l) = &inp.lbs {
            Source::Lbs(ck.existing(l)?)
        } else if let Some(v) = &inp.volume {
            self.volume(v)?
        } else {
            self.sdf(inp.sdf.as_ref().expect("one source is given"))?
        })
    }

    /// Several mesh files: at least two, each existing.
    fn meshes(&self, ms: &Spanned<Vec<String>>) -> Result<Source> {
        let ck = self.ck;
        if ms.get_ref().len() < 2 {
            return Err(ck.err(
                ms.span(),
                "meshes: give two or more files (one file is `mesh`)",
            ));
        }
        let mut paths = Vec::new();
        for (i, m) in ms.get_ref().iter().enumerate() {
            let p = ck.relative(m);
            if !p.exists() {
                let problem = format!("meshes[{i}]: {} does not exist", p.display());
                return Err(ck.err(ms.span(), problem));
            }
            paths.push(p);
        }
        Ok(Source::Meshes(paths))
    }

    /// A volume source: the file, `iso` (required) and `inside`.
    fn volume(&self, v: &Spanned<String>) -> Result<Source> {
        let Some(iso) = self.inp.iso else {
            return Err(self.ck.err(v.span(), "a volume input needs `iso`"));
        };
        if !iso.is_finite() {
            return Err(self.err(format!("iso {iso} must be finite")));
        }
        Ok(Source::Volume(self.ck.existing(v)?, iso, self.above(true)?))
    }

    /// An SDF source: the kind, its grid resolution, `iso` and `inside`.
    fn sdf(&self, s: &Spanned<String>) -> Result<Source> {
        const KINDS: [&str; 3] = ["sphere", "torus", "gyroid"];
        if !KINDS.contains(&s.get_ref().as_str()) {
            let (got, want) = (s.get_ref(), crate::error::one_of(&KINDS));
            return Err(self
                .ck
                .err(s.span(), format!("sdf = {got:?}: expected {want}")));
        }
        let res = self.inp.resolution.unwrap_or(128);
        if !(4..=1024).contains(&res) {
            return Err(self.err(format!(
                "resolution {res}: an SDF grid needs 4..=1024 points per axis"
            )));
        }
        Ok(Source::Sdf(
            s.get_ref().clone(),
            res,
            self.inp.iso.unwrap_or(0.0),
            self.above(false)?,
        ))
    }
}

/// First frame, end (exclusive; `None`: the whole animation), step.
type Frames = (usize, Option<usize>, usize);

/// Checks `[frames]` against the source: (start, end, step) and fps.
pub(super) fn frames(
    ck: &Checker<'_>,
    frames: Option<&Spanned<FramesSpec>>,
    source: &Source,
) -> Result<(Frames, f32)> {
    let Some(f) = frames else {
        return Ok(((0, None, 1), 30.0));
    };
    let s = f.get_ref();
    if s.step == 0 {
        return Err(ck.err(f.span(), "frames.step must be at least 1"));
    }
    if let Some(e) = s.end
        && e <= s.start
    {
        return Err(ck.err(
            f.span(),
            format!("frames: end {e} must be greater than start {}", s.start),
        ));
    }
    if !(s.fps.is_finite() && s.fps > 0.0) {
        return Err(ck.err(f.span(), format!("frames.fps {} must be positive", s.fps)));
    }
    if source.input() == Input::Static && (s.start > 0 || s.end.is_some_and(|e| e > 1)) {
        return Err(ck.err(
            f.span(),
            "a static mesh has one frame (0); use cameras for more views",
        ));
    }
    Ok(((s.start, s.end, s.step), s.fps))
}
