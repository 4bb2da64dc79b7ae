//! The one view type: what a stage needs to know of a camera and an image,
//! as plain data. The renderer's camera makes it (`render::Camera::view`);
//! the edges stage packs it into its parameter block
//! ([`crate::spec::edges::EdgeParams`]) and the feature-line stage reads its
//! eye ([`View::line_eye`]). Nothing here knows GL or
//! the device: compute takes a view, it never frames or draws one.

use glam::{Mat4, Vec3};

use crate::error::{Error, Result};

/// A camera seen from a stage: world-to-clip matrix, eye, view direction,
/// projection kind, near plane and viewport. Clip space is OpenGL's (z in
/// [−w, w]), the convention of the renderer that draws what stages write.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// World to clip space (projection × view), for the viewport's aspect.
    pub view_proj: Mat4,
    /// Eye position (world space).
    pub eye: Vec3,
    /// From the eye towards the point looked at, *not* normalized (its
    /// length is the distance to that point); [`View::unit_dir`] is the unit
    /// vector. Kept unnormalized so that `-dir` is exactly `eye − target`,
    /// the direction towards the viewer that orthographic line extraction
    /// has always used.
    pub dir: Vec3,
    /// Orthographic projection.
    pub ortho: bool,
    /// Near clipping distance (> 0).
    pub near: f32,
    /// Viewport width in pixels.
    pub width: u32,
    /// Viewport height in pixels.
    pub height: u32,
}

impl View {
    /// A view for line extraction alone, from the eye position (perspective)
    /// or, when `ortho`, the constant direction towards the viewer: the
    /// projection is the identity and the viewport 1×1, so it is not for
    /// drawing or for the edges stage (use `render::Camera::view`).
    pub fn from_eye(eye: [f32; 3], ortho: bool) -> View {
        let e = Vec3::from(eye);
        View {
            view_proj: Mat4::IDENTITY,
            eye: e,
            // −dir is exactly the direction towards the viewer.
            dir: -e,
            ortho,
            near: f32::MIN_POSITIVE,
            width: 1,
            height: 1,
        }
    }

    /// What line extraction reads: the eye, or the direction towards the
    /// viewer ([`View::toward_viewer`]) when orthographic.
    pub fn line_eye(&self) -> [f32; 3] {
        if self.ortho {
            self.toward_viewer().to_array()
        } else {
            self.eye.to_array()
        }
    }

    /// The unit view direction (eye towards the point looked at).
    pub fn unit_dir(&self) -> Vec3 {
        self.dir.normalize()
    }

    /// Width / height of the viewport.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// The direction towards the viewer, `eye − target` (orthographic line
    /// extraction's constant view vector).
    pub fn toward_viewer(&self) -> Vec3 {
        -self.dir
    }

    /// Rejects a view no stage can use: a non-finite eye or direction, a zero
    /// direction (eye and target coincide), a non-positive near plane, or a
    /// non-finite matrix, each as a `camera:` problem; an empty viewport as a
    /// `{what}: viewport` problem.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] naming the problem.
    pub fn check(&self, what: &str) -> Result<()> {
        let bad = |problem: String| Err(Error::InvalidArgument(problem));
        if !(self.eye.is_finite() && self.dir.is_finite() && self.near.is_finite()) {
            return bad(format!(
                "camera: non-finite value (eye {}, direction {}, near {})",
                self.eye, self.dir, self.near
            ));
        }
        if self.dir.length_squared() == 0.0 {
            return bad(format!(
                "camera: eye and target coincide at {} (no view direction)",
                self.eye
            ));
        }
        if !self.ortho && self.near <= 0.0 {
            return bad(format!("camera: near {} must be > 0", self.near));
        }
        if self.width == 0 || self.height == 0 {
            return bad(format!(
                "{what}: viewport {}x{} is empty",
                self.width, self.height
            ));
        }
        if !self.view_proj.is_finite() {
            return bad(format!(
                "{what}: the camera gives a non-finite view-projection matrix"
            ));
        }
        Ok(())
    }
}

/// The one projection to pixels: a clip-space point `(x, y, z, w)` in the
/// pixels of a `width` × `height` image (origin top left, y down), with its
/// window depth in [0, 1] (OpenGL's depth range). `w` must be positive
/// ([`project_to_pixel`] checks it).
pub fn clip_to_pixel(c: [f32; 4], width: u32, height: u32) -> [f32; 3] {
    let (x, y, z) = (c[0] / c[3], c[1] / c[3], c[2] / c[3]);
    [
        0.5 * (x + 1.0) * width as f32,
        0.5 * (1.0 - y) * height as f32,
        0.5 * (z + 1.0),
    ]
}

/// World point `p` in the pixels of a `width` × `height` image seen through
/// `view_proj` ([`clip_to_pixel`]), or `None` behind the eye.
pub fn project_to_pixel(view_proj: Mat4, p: [f32; 3], width: u32, height: u32) -> Option<[f32; 2]> {
    let c = view_proj * glam::Vec4::new(p[0], p[1], p[2], 1.0);
    if c.w.is_nan() || c.w <= 0.0 {
        return None;
    }
    let [x, y, _] = clip_to_pixel(c.to_array(), width, height);
    Some([x, y])
}
