//! Flipbook sequences: an animation stored as one mesh file per frame
//! (`hand_00.obj` … `hand_43.obj`, as in the Utah 3D Animation Repository),
//! all frames sharing one topology.
//!
//! [`Flipbook::open`] expands a glob pattern, sorts the matches in natural
//! order (`frame_2` before `frame_10`) and loads the first frame, whose faces
//! are the topology. [`Flipbook::frame`] loads one frame at a time (the
//! sequence is never held in memory) and checks that it has the same vertex
//! count and the same faces as the first; a mismatch is an error naming the
//! file and the first differing element, never a silently wrong pose.
//!
//! [`Flipbook::check_frames`] runs those checks on the frames a scene will
//! render before any is rendered (in full for small sequences, from the
//! file headers for large ones), so that a bad frame fails a run at once.
//!
//! With [`LoadOptions::weld`], the weld map of the first frame is applied to
//! every frame (welding each frame on its own could merge different vertices
//! when two of them touch in one pose); a frame in which two vertices welded
//! in the first frame have moved apart is an error.

use std::cmp::Ordering;
use std::path::{Path, PathBuf};

use super::{LoadOptions, Mesh, header_counts, load};
use crate::error::{Error, Result};

/// A sequence of mesh files with one topology, loaded frame by frame.
#[derive(Clone, Debug)]
pub struct Flipbook {
    /// The frame files, in natural order.
    pub frames: Vec<PathBuf>,
    /// The triangles of every frame (those of the first frame, welded if asked).
    pub faces: Vec<[u32; 3]>,
    /// Vertices per frame (after welding, if asked).
    pub n_vertices: usize,
    /// The glob pattern as expanded (joined to the base folder).
    pub pattern: String,
    /// The first frame as stored (before welding): what every frame must match.
    raw_faces: Vec<[u32; 3]>,
    raw_n_vertices: usize,
    /// For each stored vertex, its welded index (`None` without welding).
    weld: Option<Vec<u32>>,
}

impl Flipbook {
    /// Expands `pattern` (a glob such as `frames/hand_*.obj`, relative to
    /// `base` unless absolute), sorts the matching files in natural order
    /// and loads the first one, whose faces become the topology of the
    /// sequence. Folders matching the pattern are skipped. `opts.weld` welds
    /// every frame with the weld map of the first frame.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidInput`] naming the pattern when it is malformed, not
    /// UTF-8 once joined to `base`, or matches no file; [`Error::Io`] when a
    /// folder cannot be listed; any error of [`load`] for the first frame.
    pub fn open(pattern: &str, base: &Path, opts: &LoadOptions) -> Result<Flipbook> {
        let full = if Path::new(pattern).is_absolute() {
            pattern.to_string()
        } else {
            // The base folder is a literal path: escape its metacharacters.
            let base = base.to_str().ok_or_else(|| {
                Error::input(
                    base.display().to_string(),
                    "glob pattern",
                    "the base folder is not valid UTF-8",
                )
            })?;
            if base.is_empty() {
                pattern.to_string()
            } else {
                Path::new(&glob::Pattern::escape(base))
                    .join(pattern)
                    .to_string_lossy()
                    .into_owned()
            }
        };
        let paths = glob::glob(&full)
            .map_err(|e| Error::input(&full, "glob pattern", format!("malformed: {e}")))?;
        let mut frames = Vec::new();
        for entry in paths {
            let path = entry.map_err(|e| Error::Io {
                path: e.path().to_path_buf(),
                source: std::io::Error::new(e.error().kind(), e.error().to_string()),
            })?;
            if path.is_file() {
                frames.push(path);
            }
        }
        if frames.is_empty() {
            return Err(Error::input(&full, "glob pattern", "no file matches"));
        }
        frames.sort_by(|a, b| natural_cmp(&a.to_string_lossy(), &b.to_string_lossy()));

        let raw = load(&frames[0], &LoadOptions::default())?;
        let (mesh, weld) = if opts.weld {
            let (m, remap) = raw.weld();
            (m, Some(remap))
        } else {
            (raw.clone(), None)
        };
        Ok(Flipbook {
            frames,
            faces: mesh.faces,
            n_vertices: mesh.positions.len(),
            pattern: full,
            raw_n_vertices: raw.positions.len(),
            raw_faces: raw.faces,
            weld,
        })
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether the sequence has no frame (never true for an opened one).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Loads the positions of frame `i` (`n_vertices` of them, in the order
    /// of the first frame).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidArgument`] when `i` is past the last frame; any error
    /// of [`load`] for the frame's file; [`Error::InvalidInput`] naming the
    /// file when its vertex count, face count or a face differs from the
    /// first frame's (the first differing face is named), or when two
    /// vertices welded in the first frame are apart in this one.
    pub fn frame(&self, i: usize) -> Result<Vec<[f64; 3]>> {
        let path = self.frames.get(i).ok_or_else(|| {
            Error::InvalidArgument(format!(
                "frame {i}: the sequence '{}' has {} frames",
                self.pattern,
                self.frames.len()
            ))
        })?;
        let m = load(path, &LoadOptions::default())?;
        let name = path.display().to_string();
        let first = self.frames[0].display();
        if m.positions.len() != self.raw_n_vertices {
            return Err(Error::input(
                name,
                "vertices",
                format!(
                    "{} vertices, but the first frame ({first}) has {}",
                    m.positions.len(),
                    self.raw_n_vertices
                ),
            ));
        }
        if m.faces.len() != self.raw_faces.len() {
            return Err(Error::input(
                name,
                "faces",
                format!(
                    "{} triangles, but the first frame ({first}) has {}",
                    m.faces.len(),
                    self.raw_faces.len()
                ),
            ));
        }
        if let Some((k, (f, g))) = m
            .faces
            .iter()
            .zip(&self.raw_faces)
            .enumerate()
            .find(|(_, (f, g))| f != g)
        {
            return Err(Error::input(
                name,
                format!("face {k}"),
                format!(
                    "vertices {}, but face {k} of the first frame ({first}) is {} \
                     (frames must share one topology)",
                    crate::error::values(f, " "),
                    crate::error::values(g, " ")
                ),
            ));
        }
        let Some(remap) = &self.weld else {
            return Ok(m.positions);
        };
        let mut out: Vec<Option<(usize, [f64; 3])>> = vec![None; self.n_vertices];
        for (v, (&p, &w)) in m.positions.iter().zip(remap).enumerate() {
            match out[w as usize] {
                None => out[w as usize] = Some((v, p)),
                Some((u, q)) if q != p => {
                    return Err(Error::input(
                        name,
                        format!("vertex {v}"),
                        format!(
                            "welded with vertex {u} in the first frame ({first}), but here \
                             at ({}) instead of ({})",
                            crate::error::values(p, ", "),
                            crate::error::values(q, ", ")
                        ),
                    ));
                }
                Some(_) => {}
            }
        }
        // Every welded vertex has at least one stored vertex mapping to it.
        Ok(out
            .into_iter()
            .map(|o| o.map_or([0.0; 3], |(_, p)| p))
            .collect())
    }

    /// Checks, before anything is rendered, that frames `indices` have the
    /// topology of the first frame, so that a run fails at once rather
    /// than at the bad frame.
    ///
    /// Kept cheap: when the frame files to check total at most
    /// [`FULL_CHECK_BYTES`], each is loaded and compared in full (vertex
    /// and face counts, every face, the weld map) as [`Flipbook::frame`]
    /// does; parsing such small files once more when they are rendered
    /// costs a fraction of a second, and holding the positions of every
    /// frame instead would defeat loading one frame at a time. Larger
    /// sequences compare the vertex and face counts that each PLY or OFF
    /// header declares with the first frame's, reading headers only; their
    /// faces (and OBJ frames, which have no header) are compared when each
    /// frame is loaded for rendering.
    ///
    /// # Errors
    ///
    /// The index of the first bad frame with its error: as
    /// [`Flipbook::frame`], or [`Error::Io`] when its file cannot be read.
    pub fn check_frames(&self, indices: &[usize]) -> std::result::Result<(), (usize, Error)> {
        let mut total = 0u64;
        for &i in indices {
            let path = self.frames.get(i).ok_or_else(|| {
                let e = Error::InvalidArgument(format!(
                    "frame {i}: the sequence '{}' has {} frames",
                    self.pattern,
                    self.frames.len()
                ));
                (i, e)
            })?;
            let len = std::fs::metadata(path)
                .map_err(|source| {
                    let e = Error::Io {
                        path: path.clone(),
                        source,
                    };
                    (i, e)
                })?
                .len();
            total = total.saturating_add(len);
        }
        if total <= FULL_CHECK_BYTES {
            // Frame 0 is the first frame itself.
            for &i in indices.iter().filter(|&&i| i != 0) {
                self.frame(i).map_err(|e| (i, e))?;
            }
            return Ok(());
        }
        let first_path = &self.frames[0];
        let Some((nv0, nf0)) = header_counts(first_path).map_err(|e| (0, e))? else {
            return Ok(());
        };
        let ext = |p: &Path| p.extension().map(|e| e.to_ascii_lowercase());
        for &i in indices.iter().filter(|&&i| i != 0) {
            let path = &self.frames[i];
            if ext(path) != ext(first_path) {
                continue;
            }
            let Some((nv, nf)) = header_counts(path).map_err(|e| (i, e))? else {
                continue;
            };
            let first = first_path.display();
            let (element, problem) = if nv != nv0 {
                (
                    "vertices",
                    format!("{nv} vertices, but the first frame ({first}) has {nv0}"),
                )
            } else if nf != nf0 {
                (
                    "faces",
                    format!("{nf} faces, but the first frame ({first}) has {nf0}"),
                )
            } else {
                continue;
            };
            let e = Error::input(
                path.display().to_string(),
                element,
                format!("{problem} (frames must share one topology)"),
            );
            return Err((i, e));
        }
        Ok(())
    }

    /// Frame `i` as a mesh (the positions of [`Flipbook::frame`] with the
    /// shared faces).
    ///
    /// # Errors
    ///
    /// As [`Flipbook::frame`].
    pub fn mesh(&self, i: usize) -> Result<Mesh> {
        Ok(Mesh {
            positions: self.frame(i)?,
            faces: self.faces.clone(),
            normals: None,
        })
    }
}

/// The most bytes of frame files that [`Flipbook::check_frames`] loads in
/// full to compare them with the first frame (32 MiB: a few tenths of a
/// second of parsing); larger sequences are checked from their headers.
pub const FULL_CHECK_BYTES: u64 = 32 << 20;

/// Natural order of two strings: runs of ASCII digits compare as numbers
/// (`frame_2` < `frame_10`), everything else character by character. Numbers
/// equal in value compare by their number of leading zeros (fewer first),
/// and equal strings under those rules fall back to plain string order, so
/// the order is total and deterministic.
pub fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (x, y) = (a.as_bytes(), b.as_bytes());
    let (mut i, mut j) = (0, 0);
    while i < x.len() && j < y.len() {
        if x[i].is_ascii_digit() && y[j].is_ascii_digit() {
            let run = |s: &[u8], k: usize| {
                let end = k + s[k..].iter().take_while(|c| c.is_ascii_digit()).count();
                let zeros = s[k..end].iter().take_while(|&&c| c == b'0').count();
                (k + zeros, end)
            };
            let ((xs, xe), (ys, ye)) = (run(x, i), run(y, j));
            // Without leading zeros, a longer run is a larger number; equal
            // lengths compare digit by digit. No overflow on long runs.
            let ord = (xe - xs)
                .cmp(&(ye - ys))
                .then_with(|| x[xs..xe].cmp(&y[ys..ye]))
                .then_with(|| (xs - i).cmp(&(ys - j)));
            if ord != Ordering::Equal {
                return ord;
            }
            (i, j) = (xe, ye);
        } else {
            // Byte order within UTF-8 is code point order.
            match x[i].cmp(&y[j]) {
                Ordering::Equal => (i, j) = (i + 1, j + 1),
                ord => return ord,
            }
        }
    }
    (x.len() - i).cmp(&(y.len() - j)).then_with(|| a.cmp(b))
}

#[cfg(test)]
mod tests {
    use super::natural_cmp;
    use std::cmp::Ordering::*;

    #[test]
    fn natural_order() {
        assert_eq!(natural_cmp("frame_2.obj", "frame_10.obj"), Less);
        assert_eq!(natural_cmp("frame_10.obj", "frame_2.obj"), Greater);
        assert_eq!(natural_cmp("a", "a"), Equal);
        assert_eq!(natural_cmp("a9", "a09"), Less);
        assert_eq!(natural_cmp("a09", "a10"), Less);
        assert_eq!(natural_cmp("hand_", "hand_0"), Less);
        assert_eq!(natural_cmp("x/10/a", "x/9/b"), Greater);
        assert_eq!(
            natural_cmp("f99999999999999999999999", "f100000000000000000000000"),
            Less
        );
        let mut v = vec!["f_10", "f_1", "f_2", "g", "f_01", "f_0"];
        v.sort_by(|a, b| natural_cmp(a, b));
        assert_eq!(v, ["f_0", "f_1", "f_01", "f_2", "f_10", "g"]);
    }
}
