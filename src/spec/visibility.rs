//! Shared types of the `visibility` family: exact, object-space visibility
//! of line segments, for SVG output without a rasterizer, by
//! occlusion queries towards the eye over the `bvh` family's tree. The
//! options ([`VisibilityOptions`], [`Spacing`]), the output ([`Piece`],
//! [`Pieces`]) and its bound ([`visibility_bound`], [`MAX_INTERVALS`]).
//!
//! Method: each segment is sampled at `n + 1` evenly spaced points
//! (`t = k / n`, `n` from [`Spacing`], at most [`MAX_INTERVALS`]); each
//! sample casts one query towards the eye (perspective: to the eye point;
//! orthographic: along the direction towards the viewer to beyond the
//! mesh's bounding sphere), leaving out the faces the segment lies on.
//! Between neighbouring samples whose answers differ, `bisect` halvings
//! place the split (the midpoint of the last bracket). A point behind the
//! eye (perspective, nearer than the near plane) is hidden without a query.
//!
//! Contours lie on the grazing set, where the ray towards the eye runs
//! along the surface and the neighbouring faces of a polyhedral mesh may
//! cross it within about an edge length. The chosen method: every query
//! starts `contour_offset` × the local edge length (the mean edge of the
//! segment's face) along the ray towards the eye. It needs no normals and
//! no exclusion slots (a vertex end may already name more faces than the
//! four slots hold), and is the same for every family; its price is that
//! a real occluder nearer than that offset is missed. Measured (f64
//! reference, icosphere level 4, whose contours are all visible): 0.05
//! edge hides 44–46 % of the contour length, 0.25 hides 17–22 %, 0.5 hides
//! 0.4–0.9 %, 1.0 hides none; hence the default 1.0 (`tests/visibility.rs`).
//!
//! Mirrors: none in a kernel (the device work is `bvh_occluded`).

/// How the hidden parts of an SVG's lines are found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VisibilityMethod {
    /// In object space, by occlusion queries over the mesh's BVH on the
    /// device (this family): exact up to the sampling and the contour
    /// offset, and no GL context is needed.
    #[default]
    Exact,
    /// Against the depth buffer the renderer draws (GL): approximate at
    /// silhouettes and dependent on the image size.
    Depth,
}

impl VisibilityMethod {
    /// Every method, in `--help` order.
    pub const ALL: [VisibilityMethod; 2] = [VisibilityMethod::Exact, VisibilityMethod::Depth];

    /// The name on the command line, in scene files and in reports.
    pub fn name(self) -> &'static str {
        match self {
            VisibilityMethod::Exact => "exact",
            VisibilityMethod::Depth => "depth",
        }
    }
}

crate::spec::named_choice!(VisibilityMethod, "visibility method");

/// How far apart the samples along a segment are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Spacing {
    /// A fraction of the view's size (of the NDC square's side, 2): a
    /// segment spanning a fraction `s` of the view gets `ceil(s / f)`
    /// intervals. A segment with an end behind the eye gets
    /// [`MAX_INTERVALS`].
    View(f32),
    /// A fraction of the mesh's bounding-box diagonal, in world space.
    Diagonal(f32),
}

/// Options of the classification.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisibilityOptions {
    /// Sample spacing.
    pub spacing: Spacing,
    /// Halvings of a bracket between two samples whose answers differ
    /// (0 to [`MAX_BISECT`]); the split lies within `2^-bisect` of the
    /// interval from the true transition (when there is one). Default 6:
    /// at the default spacing an interval spans at most 0.5 % of the view
    /// (2.4 pixels of a 480-pixel picture), so the split lies within 0.04
    /// pixel, and each further level is one more round of queries (10
    /// levels cost the Stanford bunny about 7 ms more on PoCL; see
    /// docs/visibility.md).
    pub bisect: u32,
    /// Start of every query along the ray towards the eye, as a fraction of
    /// the local edge length (0 to 10): see the module note on contours.
    pub contour_offset: f32,
}

impl Default for VisibilityOptions {
    fn default() -> Self {
        VisibilityOptions {
            spacing: Spacing::View(0.005),
            bisect: 6,
            contour_offset: 1.0,
        }
    }
}

/// Most halvings of a bracket.
pub const MAX_BISECT: u32 = 20;
/// Most intervals (samples − 1) of one segment.
pub const MAX_INTERVALS: usize = 1024;

impl VisibilityOptions {
    /// Rejects options no classification can use, in plain words.
    pub fn check(&self) -> crate::error::Result<()> {
        let bad = |m: String| Err(crate::error::Error::InvalidArgument(m));
        let (what, f) = match self.spacing {
            Spacing::View(f) => ("of the view", f),
            Spacing::Diagonal(f) => ("of the bounding diagonal", f),
        };
        if !(f.is_finite() && f > 0.0) {
            return bad(format!(
                "visibility: a sample spacing of {f} {what}, a positive fraction expected"
            ));
        }
        if self.bisect > MAX_BISECT {
            return bad(format!(
                "visibility: {} bisection levels, at most {MAX_BISECT}",
                self.bisect
            ));
        }
        let o = self.contour_offset;
        if !(o.is_finite() && (0.0..=10.0).contains(&o)) {
            return bad(format!(
                "visibility: a contour offset of {o} edge lengths, 0 to 10 expected"
            ));
        }
        Ok(())
    }
}

/// A segment end on no face of the mesh (the ends' field of
/// [`crate::spec::feature_lines::Segment`]): a curve on another surface,
/// as a curvature-directed stroke on a distance field's isosurface (the
/// mesh is its marching-cubes chords). Its queries leave no face out and
/// start the contour offset × the segment's length along the ray.
pub const NO_FACE: [u32; 2] = [u32::MAX, u32::MAX];

/// The faces a segment lies on, or an end sample leaves out of its query:
/// at most four (as many as a query leaves out), in a fixed array (no
/// allocation per segment). Reads as a slice.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Faces {
    n: u8,
    f: [u32; 4],
}

impl Faces {
    /// The first four of `faces`.
    pub fn of(faces: &[u32]) -> Faces {
        let mut out = Faces::default();
        for &f in faces.iter().take(4) {
            out.push(f);
        }
        out
    }

    /// Adds `face` where fewer than four are held; whether it is held (a
    /// face already held is not held twice).
    pub fn push(&mut self, face: u32) -> bool {
        if self.as_slice().contains(&face) {
            return true;
        }
        let n = self.n as usize;
        if n == 4 {
            return false;
        }
        self.f[n] = face;
        self.n += 1;
        true
    }

    /// The faces, in order.
    pub fn as_slice(&self) -> &[u32] {
        &self.f[..self.n as usize]
    }
}

impl std::ops::Deref for Faces {
    type Target = [u32];

    fn deref(&self) -> &[u32] {
        self.as_slice()
    }
}

/// A piece of a segment: `(t0, t1, visible)`, `t` the fraction of the way
/// from its first end to its second (`0 ≤ t0 < t1 ≤ 1`, or `(0, 1)` for a
/// zero-length segment).
pub type Piece = (f32, f32, bool);

/// The pieces of one segment, in order of `t`, covering `[0, 1]`,
/// neighbours differing in visibility.
pub type Pieces = Vec<Piece>;

/// Most pieces of a segment sampled over `intervals` intervals: one split
/// per interval whose ends differ, so `intervals + 1`.
pub fn visibility_bound(intervals: usize) -> usize {
    intervals + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_are_checked_in_plain_words() {
        assert!(VisibilityOptions::default().check().is_ok());
        let o = VisibilityOptions {
            spacing: Spacing::Diagonal(0.0),
            ..Default::default()
        };
        assert!(format!("{:?}", o.check()).contains("spacing"));
        let o = VisibilityOptions {
            bisect: 99,
            ..Default::default()
        };
        assert!(o.check().is_err());
        let o = VisibilityOptions {
            contour_offset: f32::NAN,
            ..Default::default()
        };
        assert!(o.check().is_err());
        assert_eq!(visibility_bound(1), 2);
    }
}
