//! libigl's linear-blend-skinning sets: a rest mesh (`<stem>.obj`), a
//! skeleton (`<stem>.tgf`), dense skinning weights (`<stem>-weights.dmat`)
//! and a per-frame bone-transform animation (`<stem>-anim.dmat`), as in the
//! libigl tutorial's elephant (Direct Delta Mush, tutorial 408).
//!
//! Conventions (those of `igl::readDMAT`, `igl::readTGF` and `igl::lbs_matrix`):
//! - DMAT: a first line `cols rows`, then the `rows × cols` values in
//!   column-major order, as text; or, for the binary form, a first line
//!   `0 0`, a second line `cols rows`, then the values as little-endian
//!   float64, column-major.
//! - TGF: joint lines `index x y z` up to a line starting with `#`, then
//!   edge lines `a b [flags]` (1-based) up to the next `#`. Every edge is a
//!   bone (what `igl::readTGF(path, C, BE)` returns), in file order; bone `b`
//!   is column `b` of the weights.
//! - Weights W: `n × B`, one row per mesh vertex in file order.
//! - Animation T: `12·B × frames`. Column `f` read column-major as a
//!   `4B × 3` matrix `Tf` stacks, for bone `b`, the 4×3 block `A_b =
//!   Tf[4b..4b+4, :]`, which maps a row `[v 1]` to `[v 1]·A_b`. The dense
//!   skinned pose is `U = M·Tf` with `M[:, 4b..4b+4] = W[:, b]·[v 1]`, i.e.
//!   `u = Σ_b W[v,b] · A_bᵀ·[v;1]`.
//!
//! [`LbsAnimation::to_skinned`] keeps the four largest weights per vertex
//! (renormalized) for the device skinning stage (`kernels/skinning.cl`,
//! at most four influences) and reports what the dropped weights were;
//! [`LbsAnimation::dense_frame`] is the exact all-weights reference in f64.

use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3, Vec4};

use super::skinned::{SkinnedMesh, Trs};
use super::{LoadOptions, Mesh, load};
use crate::error::{Error, Result};

/// A dense matrix read from a DMAT file, stored column-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Dmat {
    /// Number of rows.
    pub rows: usize,
    /// Number of columns.
    pub cols: usize,
    /// `rows × cols` values, column after column.
    pub data: Vec<f64>,
}

impl Dmat {
    /// The value at row `i`, column `j` (panics when out of range).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        assert!(i < self.rows && j < self.cols, "({i}, {j}) out of range");
        self.data[j * self.rows + i]
    }

    /// Column `j` (panics when out of range).
    pub fn column(&self, j: usize) -> &[f64] {
        &self.data[j * self.rows..(j + 1) * self.rows]
    }
}

/// Reads a libigl DMAT file, text or binary (see the module docs).
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read; [`Error::InvalidInput`]
/// naming the file, the element (`header line 1`, `entry (row 3, column
/// 0)`) and the problem for a malformed header, a truncated file, trailing
/// data, an unparsable or non-finite (NaN, infinite) value.
pub fn read_dmat(path: &Path) -> Result<Dmat> {
    let bytes = read(path)?;
    parse_dmat(&bytes, &path.display().to_string())
}

/// Parses the bytes of a DMAT file; `source` names it in errors.
///
/// # Errors
///
/// As [`read_dmat`].
pub fn parse_dmat(bytes: &[u8], source: &str) -> Result<Dmat> {
    let (first, rest) = header_line(bytes, source, 1)?;
    let (cols, rows) = first;
    if (cols, rows) == (0, 0) {
        let ((cols, rows), payload) = header_line(rest, source, 2)?;
        return parse_binary(payload, rows, cols, source);
    }
    parse_text(rest, rows, cols, source)
}

fn read(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Splits off one header line `cols rows` and parses it.
fn header_line<'a>(bytes: &'a [u8], source: &str, n: usize) -> Result<((usize, usize), &'a [u8])> {
    let element = format!("header line {n}");
    // A header is two short numbers: look for its end in the first bytes
    // only, so that a binary file without a line end is not scanned whole.
    let window = &bytes[..bytes.len().min(256)];
    let end = window.iter().position(|&c| c == b'\n').ok_or_else(|| {
        let problem = if bytes.len() <= window.len() {
            "unexpected end of file (expected a line 'cols rows')"
        } else {
            "no line end within 256 bytes (expected a line 'cols rows')"
        };
        Error::input(source, &element, problem)
    })?;
    let line = std::str::from_utf8(&bytes[..end])
        .map_err(|_| Error::input(source, &element, "not text (expected 'cols rows')"))?;
    let toks: Vec<&str> = line.split_whitespace().collect();
    let dims = match toks.as_slice() {
        [c, r] => c.parse::<usize>().ok().zip(r.parse::<usize>().ok()),
        _ => None,
    };
    let dims = dims.ok_or_else(|| {
        Error::input(
            source,
            &element,
            format!(
                "'{}' is not two non-negative integers 'cols rows'",
                line.trim()
            ),
        )
    })?;
    Ok((dims, &bytes[end + 1..]))
}

/// Number of values of a `rows × cols` matrix, or an error on overflow.
fn count(rows: usize, cols: usize, source: &str, line: usize) -> Result<usize> {
    rows.checked_mul(cols).ok_or_else(|| {
        Error::input(
            source,
            format!("header line {line}"),
            format!("{cols} columns × {rows} rows overflows"),
        )
    })
}

fn entry(k: usize, rows: usize) -> String {
    format!("entry (row {}, column {})", k % rows, k / rows)
}

fn check_finite(v: f64, k: usize, rows: usize, source: &str, at: &str) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::input(
            source,
            entry(k, rows),
            format!("{at}non-finite value {v}"),
        ))
    }
}

fn parse_binary(payload: &[u8], rows: usize, cols: usize, source: &str) -> Result<Dmat> {
    let n = count(rows, cols, source, 2)?;
    let need = n.checked_mul(8).ok_or_else(|| {
        Error::input(
            source,
            "header line 2",
            format!("{cols} columns × {rows} rows overflows"),
        )
    })?;
    if payload.len() < need {
        return Err(Error::input(
            source,
            "data",
            format!(
                "truncated: the header declares {rows} rows × {cols} columns of float64 \
                 ({need} bytes), but {} bytes follow it",
                payload.len()
            ),
        ));
    }
    if payload.len() > need {
        return Err(Error::input(
            source,
            "data",
            format!(
                "{} bytes after the {rows} rows × {cols} columns of float64 the header \
                 declares (wrong header?)",
                payload.len() - need
            ),
        ));
    }
    let data = payload
        .chunks_exact(8)
        .enumerate()
        .map(|(k, b)| {
            let v = f64::from_le_bytes(b.try_into().expect("8 bytes"));
            check_finite(v, k, rows, source, "")
        })
        .collect::<Result<Vec<f64>>>()?;
    Ok(Dmat { rows, cols, data })
}

fn parse_text(body: &[u8], rows: usize, cols: usize, source: &str) -> Result<Dmat> {
    let n = count(rows, cols, source, 1)?;
    let text = std::str::from_utf8(body).map_err(|e| {
        Error::input(
            source,
            "data",
            format!(
                "not text at byte {} after the header (a binary DMAT starts with '0 0')",
                e.valid_up_to()
            ),
        )
    })?;
    // Each value takes at least two bytes (a digit and a separator).
    let mut data = Vec::with_capacity(n.min(body.len() / 2 + 1));
    for (i, line) in text.lines().enumerate() {
        let ln = i + 2;
        for tok in line.split_whitespace() {
            let k = data.len();
            if k == n {
                return Err(Error::input(
                    source,
                    "data",
                    format!(
                        "line {ln}: more than the {rows} rows × {cols} columns of values \
                         the header declares"
                    ),
                ));
            }
            let v: f64 = tok.parse().map_err(|_| {
                Error::input(
                    source,
                    entry(k, rows),
                    format!("line {ln}: cannot parse '{tok}' as a number"),
                )
            })?;
            data.push(check_finite(v, k, rows, source, &format!("line {ln}: "))?);
        }
    }
    if data.len() < n {
        return Err(Error::input(
            source,
            "data",
            format!(
                "truncated: the header declares {rows} rows × {cols} columns ({n} values), \
                 found {}",
                data.len()
            ),
        ));
    }
    Ok(Dmat { rows, cols, data })
}

/// A skeleton from a TGF file: joint positions and bones (joint pairs).
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    /// Joint positions, in file order.
    pub joints: Vec<[f64; 3]>,
    /// Bones as (from, to) joint indices, 0-based, in file order.
    pub bones: Vec<[u32; 2]>,
}

impl Skeleton {
    /// For each bone, the bone ending at its first joint (as
    /// `igl::directed_edge_parents`), or `None` for a root bone.
    pub fn bone_parents(&self) -> Vec<Option<usize>> {
        self.bones
            .iter()
            .enumerate()
            .map(|(i, b)| (0..self.bones.len()).find(|&p| p != i && self.bones[p][1] == b[0]))
            .collect()
    }
}

/// Reads a TGF skeleton (see the module docs). Edge flags and anything after
/// the second `#` line are ignored; blank lines are skipped.
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read; [`Error::InvalidInput`]
/// naming the file, the joint or bone and the line for a malformed line, a
/// non-finite coordinate, a joint index out of range, or a file without
/// joints or bones.
pub fn read_tgf(path: &Path) -> Result<Skeleton> {
    let bytes = read(path)?;
    parse_tgf(
        &String::from_utf8_lossy(&bytes),
        &path.display().to_string(),
    )
}

/// Parses TGF text: joint lines, then after a `#` line the bone lines
/// (after a second `#` line everything is ignored).
fn parse_tgf(text: &str, source: &str) -> Result<Skeleton> {
    let mut joints = Vec::new();
    let mut bones = Vec::new();
    let mut section = 0; // 0: joints, 1: edges, 2: ignored
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        if line.starts_with('#') {
            section += 1;
            continue;
        }
        let toks: Vec<&str> = line.split_whitespace().collect();
        if toks.is_empty() || section >= 2 {
            continue;
        }
        if section == 0 {
            joints.push(tgf_joint(&toks, ln, joints.len(), source)?);
        } else {
            bones.push(tgf_bone(&toks, ln, (bones.len(), joints.len()), source)?);
        }
    }
    if joints.is_empty() {
        return Err(Error::input(source, "joints", "the file has no joint"));
    }
    if bones.is_empty() {
        return Err(Error::input(
            source,
            "bones",
            "the file has no bone (edges follow the first '#' line)",
        ));
    }
    Ok(Skeleton { joints, bones })
}

/// Reads joint `index` from the fields `toks` of line `ln`: `index x y z`.
fn tgf_joint(toks: &[&str], ln: usize, index: usize, source: &str) -> Result<[f64; 3]> {
    let element = format!("joint {index}");
    if toks.len() < 4 {
        return Err(Error::input(
            source,
            element,
            format!(
                "line {ln}: expected 'index x y z', found {} fields",
                toks.len()
            ),
        ));
    }
    let mut p = [0.0; 3];
    for (c, tok) in p.iter_mut().zip(&toks[1..4]) {
        *c = tok
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                Error::input(
                    source,
                    &element,
                    format!("line {ln}: '{tok}' is not a finite number"),
                )
            })?;
    }
    Ok(p)
}

/// Reads bone `index` from the fields `toks` of line `ln`: `from to`, two
/// 1-based indices among the `joints` joints, made 0-based.
fn tgf_bone(
    toks: &[&str],
    ln: usize,
    (index, joints): (usize, usize),
    source: &str,
) -> Result<[u32; 2]> {
    let element = format!("bone {index}");
    if toks.len() < 2 {
        return Err(Error::input(
            source,
            element,
            format!("line {ln}: expected 'from to', found {} fields", toks.len()),
        ));
    }
    let mut b = [0u32; 2];
    for (v, tok) in b.iter_mut().zip(&toks[..2]) {
        *v = match tok.parse::<u64>() {
            Ok(k) if k >= 1 && k <= joints as u64 => (k - 1) as u32,
            _ => {
                return Err(Error::input(
                    source,
                    &element,
                    format!(
                        "line {ln}: joint '{tok}' is not in 1..={joints} (TGF indices are \
                         1-based)"
                    ),
                ));
            }
        };
    }
    Ok(b)
}

/// The weight above which [`TruncationStats::significant_over_4`] counts an influence.
pub const SIGNIFICANT_WEIGHT: f64 = 1e-3;

/// What keeping only the four largest weights per vertex drops.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TruncationStats {
    /// Largest sum of dropped weight magnitudes of one vertex.
    pub max_dropped: f64,
    /// Mean over vertices of the dropped weight magnitudes.
    pub mean_dropped: f64,
    /// Vertices with more than four non-zero weights.
    pub vertices_over_4: usize,
    /// Vertices with more than four weights above [`SIGNIFICANT_WEIGHT`]
    /// (solver output such as bounded biharmonic weights has tiny non-zero
    /// noise on most bones, which `vertices_over_4` counts).
    pub significant_over_4: usize,
    /// Largest number of non-zero weights of one vertex.
    pub max_influences: usize,
}

/// A libigl LBS set: rest mesh, skeleton, dense weights and bone transforms.
#[derive(Clone, Debug)]
pub struct LbsAnimation {
    /// The rest mesh, vertices in file order (not welded: weights are per
    /// stored vertex).
    pub rest: Mesh,
    /// The skeleton; bone `b` is weight column `b`.
    pub skeleton: Skeleton,
    /// W: one row per vertex, one column per bone.
    pub weights_dense: Dmat,
    /// T: `12·B` rows, one column per frame (see the module docs).
    pub anim: Dmat,
    /// Number of frames.
    pub frames: usize,
    /// Number of bones B.
    pub n_bones: usize,
    /// The animation file (for error messages).
    pub anim_path: PathBuf,
}

/// The sibling files of a libigl set, by its naming: `<stem>.tgf`,
/// `<stem>-weights.dmat` and `<stem>-anim.dmat` beside the rest mesh.
pub fn siblings(obj: &Path) -> [PathBuf; 3] {
    let stem = obj
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let dir = obj.parent().unwrap_or(Path::new(""));
    [
        dir.join(format!("{stem}.tgf")),
        dir.join(format!("{stem}-weights.dmat")),
        dir.join(format!("{stem}-anim.dmat")),
    ]
}

/// Loads a libigl LBS set from its rest mesh: `<stem>.obj` (or any mesh
/// [`load`] reads) with `<stem>.tgf`, `<stem>-weights.dmat` and
/// `<stem>-anim.dmat` beside it.
///
/// # Errors
///
/// [`Error::InvalidInput`] naming every missing sibling file; the errors of
/// [`load`], [`read_tgf`] and [`read_dmat`]; [`Error::InvalidInput`] naming
/// the weights file when its rows differ from the mesh's vertices or its
/// columns from the skeleton's bones, and naming the animation file when
/// its rows are not 12 per bone or it has no frame.
pub fn load_elephant_set(obj: &Path) -> Result<LbsAnimation> {
    let [tgf, weights, anim] = siblings(obj);
    let missing: Vec<String> = [obj, &tgf, &weights, &anim]
        .iter()
        .filter(|p| !p.is_file())
        .map(|p| p.display().to_string())
        .collect();
    if !missing.is_empty() {
        return Err(Error::input(
            obj.display().to_string(),
            "libigl LBS set",
            format!("missing file(s): {}", missing.join(", ")),
        ));
    }
    let rest = load(obj, &LoadOptions::default())?;
    let skeleton = read_tgf(&tgf)?;
    let w = read_dmat(&weights)?;
    let t = read_dmat(&anim)?;
    let nb = skeleton.bones.len();
    let wname = weights.display().to_string();
    if w.rows != rest.n_vertices() {
        return Err(Error::input(
            wname,
            "header",
            format!(
                "{} rows, but the mesh {} has {} vertices",
                w.rows,
                obj.display(),
                rest.n_vertices()
            ),
        ));
    }
    if w.cols != nb {
        return Err(Error::input(
            wname,
            "header",
            format!(
                "{} columns (bones), but the skeleton {} has {nb} bones",
                w.cols,
                tgf.display()
            ),
        ));
    }
    let aname = anim.display().to_string();
    if t.rows != 12 * nb {
        return Err(Error::input(
            aname,
            "header",
            format!(
                "{} rows, but {nb} bones need 12 × {nb} = {} (a 4×3 affine block per bone)",
                t.rows,
                12 * nb
            ),
        ));
    }
    if t.cols == 0 {
        return Err(Error::input(aname, "header", "no frame (0 columns)"));
    }
    Ok(LbsAnimation {
        rest,
        skeleton,
        frames: t.cols,
        n_bones: nb,
        weights_dense: w,
        anim: t,
        anim_path: anim,
    })
}

impl LbsAnimation {
    /// The affine transforms of frame `f` as 3×4 row-major matrices
    /// `[R | t]` (f64), one per bone: `p' = R·p + t`.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidArgument`] when `f` is not a frame.
    pub fn frame_affines(&self, f: usize) -> Result<Vec<[[f64; 4]; 3]>> {
        if f >= self.frames {
            return Err(Error::InvalidArgument(format!(
                "frame {f}: {} has {} frames",
                self.anim_path.display(),
                self.frames
            )));
        }
        let col = self.anim.column(f);
        let nr = 4 * self.n_bones; // rows of Tf (column-major 4B × 3)
        Ok((0..self.n_bones)
            .map(|b| std::array::from_fn(|r| std::array::from_fn(|k| col[r * nr + 4 * b + k])))
            .collect())
    }

    /// The per-bone transforms of frame `f` as [`Mat4`] (column-major, last
    /// row 0 0 0 1), in the convention of [`crate::stages::skinning::Skinner`]
    /// and [`crate::cpu::skinning::skin_lbs`]: skinned = Σ w_j · M_j · [rest, 1].
    ///
    /// # Errors
    ///
    /// [`Error::InvalidArgument`] when `f` is not a frame.
    pub fn frame_matrices(&self, f: usize) -> Result<Vec<Mat4>> {
        Ok(self
            .frame_affines(f)?
            .iter()
            .map(|a| {
                let col =
                    |k: usize, w: f32| Vec4::new(a[0][k] as f32, a[1][k] as f32, a[2][k] as f32, w);
                Mat4::from_cols(col(0, 0.0), col(1, 0.0), col(2, 0.0), col(3, 1.0))
            })
            .collect())
    }

    /// The exact dense LBS of frame `f` with all weights, in f64: libigl's
    /// `U = M·Tf`. The reference for [`LbsAnimation::to_skinned`].
    ///
    /// # Errors
    ///
    /// [`Error::InvalidArgument`] when `f` is not a frame.
    pub fn dense_frame(&self, f: usize) -> Result<Vec<[f64; 3]>> {
        let a = self.frame_affines(f)?;
        let w = &self.weights_dense;
        let mut out = vec![[0.0f64; 3]; self.rest.n_vertices()];
        // Bone-major: walks the column-major weights contiguously.
        for (b, ab) in a.iter().enumerate() {
            for ((o, p), &wb) in out.iter_mut().zip(&self.rest.positions).zip(w.column(b)) {
                if wb == 0.0 {
                    continue;
                }
                for r in 0..3 {
                    o[r] += wb * (ab[r][0] * p[0] + ab[r][1] * p[1] + ab[r][2] * p[2] + ab[r][3]);
                }
            }
        }
        Ok(out)
    }

    /// A [`SkinnedMesh`] for [`crate::stages::skinning::Skinner`]: the four
    /// largest weights of each vertex (renormalized to sum 1; a vertex
    /// without a positive weight gets none and keeps its rest position),
    /// one joint per bone (`joint_nodes` 0..B, identity inverse binds,
    /// identity rest transforms, node parents from the skeleton's bone
    /// hierarchy, and one extra root node B for the mesh), no clips: poses
    /// come from [`LbsAnimation::frame_matrices`]. Also returns what dropping
    /// the other weights costs.
    pub fn to_skinned(&self) -> (SkinnedMesh, TruncationStats) {
        let nv = self.rest.n_vertices();
        let nb = self.n_bones;
        let w = &self.weights_dense;
        let mut joints = Vec::with_capacity(nv);
        let mut weights = Vec::with_capacity(nv);
        let mut stats = TruncationStats::default();
        let mut total_dropped = 0.0;
        let mut row: Vec<(f64, u32)> = Vec::with_capacity(nb);
        for v in 0..nv {
            row.clear();
            row.extend((0..nb).map(|b| (w.get(v, b), b as u32)));
            // Largest first; ties by bone index, for determinism.
            row.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
            let nonzero = row.iter().filter(|x| x.0 != 0.0).count();
            stats.max_influences = stats.max_influences.max(nonzero);
            if nonzero > 4 {
                stats.vertices_over_4 += 1;
            }
            if row
                .iter()
                .filter(|x| x.0.abs() > SIGNIFICANT_WEIGHT)
                .count()
                > 4
            {
                stats.significant_over_4 += 1;
            }
            let mut j = [0u32; 4];
            let mut wk = [0f64; 4];
            for (k, &(x, b)) in row.iter().take(4).enumerate() {
                if x > 0.0 {
                    j[k] = b;
                    wk[k] = x;
                }
            }
            let kept: f64 = wk.iter().sum();
            let all: f64 = row.iter().map(|x| x.0.abs()).sum();
            let dropped = all - kept;
            stats.max_dropped = stats.max_dropped.max(dropped);
            total_dropped += dropped;
            joints.push(j);
            weights.push(if kept > 0.0 {
                wk.map(|x| (x / kept) as f32)
            } else {
                [0.0; 4]
            });
        }
        stats.mean_dropped = if nv > 0 {
            total_dropped / nv as f64
        } else {
            0.0
        };
        let identity = Trs {
            t: Vec3::ZERO,
            r: Quat::IDENTITY,
            s: Vec3::ONE,
        };
        // Node b is bone b; node B, a root, holds the mesh.
        let mut parents = self.skeleton.bone_parents();
        parents.push(None);
        let skinned = SkinnedMesh {
            rest: self.rest.clone(),
            joints,
            weights,
            parents,
            rest_trs: vec![identity; nb + 1],
            joint_nodes: (0..nb).collect(),
            inverse_bind: vec![Mat4::IDENTITY; nb],
            joint_mesh_node: vec![nb; nb],
            clips: Vec::new(),
        };
        (skinned, stats)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_and_binary_dmat_agree() {
        // 2 rows × 3 columns, column-major 1 2 | 3 4 | 5 6.
        let text = parse_dmat(b"3 2\n1\n2\n3 4\n5 6\n", "t").unwrap();
        let mut bin = b"0 0\n3 2\n".to_vec();
        for v in 1..=6 {
            bin.extend_from_slice(&f64::from(v).to_le_bytes());
        }
        let bin = parse_dmat(&bin, "b").unwrap();
        assert_eq!(text, bin);
        assert_eq!((text.rows, text.cols), (2, 3));
        assert_eq!(text.get(1, 0), 2.0);
        assert_eq!(text.get(0, 2), 5.0);
        assert_eq!(text.column(1), &[3.0, 4.0]);
    }

    #[test]
    fn tgf_bones_and_parents() {
        let s = parse_tgf("1 0 0 0\n2 0 1 0\n3 0 2 0\n#\n1 2 1 0 0\n2 3\n#\n", "s").unwrap();
        assert_eq!(s.joints.len(), 3);
        assert_eq!(s.bones, vec![[0, 1], [1, 2]]);
        assert_eq!(s.bone_parents(), vec![None, Some(0)]);
        let e = parse_tgf("1 0 0 0\n#\n1 2\n", "s").unwrap_err().to_string();
        assert!(e.contains("bone 0") && e.contains("line 3"), "{e}");
        let e = parse_tgf("1 0 0\n", "s").unwrap_err().to_string();
        assert!(e.contains("joint 0"), "{e}");
        assert!(parse_tgf("1 0 0 0\n#\n", "s").is_err());
    }
}
