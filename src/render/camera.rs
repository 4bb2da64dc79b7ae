//! The camera: a right-handed look-at view and an OpenGL projection (clip z in
//! [-w, w]), the convention the edge kernels must follow when they write
//! projection-space vertices for [`Renderer::draw_clip_quads`].
//!
//! [`Renderer::draw_clip_quads`]: super::Renderer::draw_clip_quads

use glam::camera::rh::{proj::opengl, view};
use glam::{Mat4, Vec3};

use crate::error::{Error, Result};
use crate::spec::view::View;

/// A pinhole (or orthographic) camera. Plain data: build one with
/// [`Camera::look_at`] or [`Camera::fit`] and adjust the fields; the renderer
/// calls [`Camera::validate`] before using it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position (world space).
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Up direction; need not be orthogonal to the view direction, only not parallel.
    pub up: Vec3,
    /// Vertical field of view in degrees (perspective only), in (0, 180).
    pub fov_y_deg: f32,
    /// `Some(h)`: orthographic projection showing a world-space height `h`.
    pub ortho_height: Option<f32>,
    /// Near clipping distance, > 0.
    pub near: f32,
    /// Far clipping distance, > near.
    pub far: f32,
}

/// An up vector for a view direction: +Y, unless the view is (nearly) vertical,
/// then +Z.
fn default_up(dir: Vec3) -> Vec3 {
    if dir.normalize_or_zero().dot(Vec3::Y).abs() > 0.999 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// The bounding sphere of the box `lo..hi` (centre, radius; a flat or
/// point-like box still gets a small positive radius) and the distance from
/// its centre at which the sphere touches the narrower half-angle of a view
/// with vertical field of view `fov_y_deg` and `aspect` (width / height).
pub fn fit_sphere(lo: Vec3, hi: Vec3, fov_y_deg: f32, aspect: f32) -> (Vec3, f32, f32) {
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-6 * (1.0 + centre.length()));
    let half_v = 0.5 * fov_y_deg.to_radians();
    let half_h = (half_v.tan() * aspect).atan();
    (centre, radius, radius / half_v.min(half_h).sin())
}

impl Camera {
    /// A 45° perspective camera at `eye` looking at `target`, up +Y (+Z when
    /// looking straight up or down), near/far at 1/100 and 100 times the distance.
    pub fn look_at(eye: Vec3, target: Vec3) -> Camera {
        let dist = eye.distance(target);
        Camera {
            eye,
            target,
            up: default_up(target - eye),
            fov_y_deg: 45.0,
            ortho_height: None,
            near: 0.01 * dist,
            far: 100.0 * dist,
        }
    }

    /// A 45° perspective camera that looks at the centre of the box
    /// `bounds_min..bounds_max` from direction `eye_dir` (from the centre
    /// towards the eye) and keeps the box's bounding sphere inside the view of
    /// an image with the given `aspect` (width / height), with near and far
    /// hugging the sphere so that depth precision is not wasted.
    pub fn fit(bounds_min: Vec3, bounds_max: Vec3, eye_dir: Vec3, aspect: f32) -> Result<Camera> {
        let finite = bounds_min.is_finite() && bounds_max.is_finite() && eye_dir.is_finite();
        if !finite || eye_dir.length_squared() == 0.0 || !(aspect > 0.0 && aspect.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "Camera::fit: bounds {bounds_min}..{bounds_max}, direction {eye_dir} and aspect \
                 {aspect} must be finite, with a non-zero direction and a positive aspect"
            )));
        }
        let fov_y_deg = 45.0f32;
        let (centre, radius, dist) = fit_sphere(bounds_min, bounds_max, fov_y_deg, aspect);
        let dir = eye_dir.normalize();
        Ok(Camera {
            eye: centre + dir * dist,
            target: centre,
            up: default_up(-dir),
            fov_y_deg,
            ortho_height: None,
            near: ((dist - radius) * 0.95).max(dist * 1e-4),
            far: (dist + radius) * 1.05,
        })
    }

    /// The [`View`] the stages take: this camera's view-projection for a
    /// `width × height` viewport, eye, direction (target − eye), projection
    /// kind and near plane. Plain data; [`View::check`] (called by the
    /// stages) rejects what is unusable.
    pub fn view(&self, width: u32, height: u32) -> View {
        View {
            view_proj: self.view_proj(width as f32 / height as f32),
            eye: self.eye,
            dir: self.target - self.eye,
            ortho: self.ortho_height.is_some(),
            near: self.near,
            width,
            height,
        }
    }

    /// The world-to-view matrix (right-handed, looking down −Z).
    pub fn view_matrix(&self) -> Mat4 {
        // glam wants a unit up vector (a zero one is rejected by `validate`).
        view::look_at_mat4(self.eye, self.target, self.up.normalize_or(Vec3::Y))
    }

    /// The view-to-clip matrix for an image of the given aspect (width / height),
    /// OpenGL convention (NDC z in [−1, 1]).
    pub fn proj(&self, aspect: f32) -> Mat4 {
        match self.ortho_height {
            Some(h) => {
                let (hh, hw) = (0.5 * h, 0.5 * h * aspect);
                opengl::orthographic(-hw, hw, -hh, hh, self.near, self.far)
            }
            None => opengl::perspective(self.fov_y_deg.to_radians(), aspect, self.near, self.far),
        }
    }

    /// `proj(aspect) * view()`: world to clip space.
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        self.proj(aspect) * self.view_matrix()
    }

    /// Rejects a camera that would produce a singular or NaN matrix: a
    /// non-finite field, eye == target, an up vector that is zero or parallel
    /// to the view direction, a field of view outside (0°, 180°), a
    /// non-positive orthographic height, near ≤ 0 or far ≤ near.
    pub fn validate(&self) -> Result<()> {
        let bad = |problem: String| Err(Error::InvalidArgument(format!("camera: {problem}")));
        // First, as a framed camera's eye is placed from it: a bad field of
        // view shows as an infinite eye otherwise.
        if self.ortho_height.is_none() && !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return bad(format!(
                "field of view {}° must be in (0°, 180°)",
                self.fov_y_deg
            ));
        }
        let finite = self.eye.is_finite()
            && self.target.is_finite()
            && self.up.is_finite()
            && self.fov_y_deg.is_finite()
            && self.near.is_finite()
            && self.far.is_finite()
            && self.ortho_height.is_none_or(f32::is_finite);
        if !finite {
            return bad(format!(
                "non-finite value (eye {}, target {}, up {}, field of view {}°, near {}, far {})",
                self.eye, self.target, self.up, self.fov_y_deg, self.near, self.far
            ));
        }
        let dir = self.target - self.eye;
        let scale = self.eye.abs().max(self.target.abs()).max_element().max(1.0);
        if dir.length() <= 1e-6 * scale {
            return bad(format!(
                "eye ({}) and target ({}) coincide",
                crate::error::values(self.eye.to_array(), ", "),
                crate::error::values(self.target.to_array(), ", ")
            ));
        }
        let up = self.up.normalize_or_zero();
        if up == Vec3::ZERO {
            return bad("up vector is zero".into());
        }
        if dir.normalize().cross(up).length() < 1e-4 {
            return bad(format!(
                "up ({}) is parallel to the view direction ({}); give another up direction",
                crate::error::values(self.up.to_array(), ", "),
                crate::error::values(dir.to_array(), ", ")
            ));
        }
        if let Some(h) = self.ortho_height
            && h <= 0.0
        {
            return bad(format!("orthographic height {h} must be > 0"));
        }
        if self.near <= 0.0 {
            return bad(format!("near {} must be > 0", self.near));
        }
        if self.far <= self.near {
            return bad(format!("far {} must be > near {}", self.far, self.near));
        }
        Ok(())
    }
}

/// Where a framed camera's eye is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Placement {
    /// At this point (world space).
    At(Vec3),
    /// On this direction from the centre of the bounds, far enough that the
    /// bounding sphere fits the view with a 5 % margin (looking at the centre).
    Fit(Vec3),
}

/// The one framing of the CLI, the tables and the scene executor:
/// perspective with vertical field of view `fov_deg`, or orthographic showing
/// the height the perspective view would show at the target; near and far
/// hug the bounding sphere of `bounds` (near = 1/1000 of the radius when the
/// eye is inside it). `target` defaults to the centre of `bounds` (a
/// [`Placement::Fit`] always looks at the centre); `aspect` (width / height)
/// matters only for [`Placement::Fit`].
///
/// # Errors
/// [`Error::InvalidArgument`] for a camera [`Camera::validate`] rejects.
pub fn framed(
    placement: Placement,
    target: Option<Vec3>,
    up: Option<Vec3>,
    fov_deg: f32,
    ortho: bool,
    bounds: ([f64; 3], [f64; 3]),
    aspect: f32,
) -> Result<Camera> {
    let (lo, hi) = bounds;
    {
        let (l, h) = (glam::DVec3::from(lo), glam::DVec3::from(hi));
        crate::spec::limits::check_drawable(
            "drawing",
            0.5 * (h - l).length(),
            (0.5 * (l + h)).length(),
        )?;
    }
    let lo = glam::DVec3::from(lo).as_vec3();
    let hi = glam::DVec3::from(hi).as_vec3();
    let centre = 0.5 * (lo + hi);
    let (eye, target) = match placement {
        Placement::At(eye) => (eye, target.unwrap_or(centre)),
        Placement::Fit(d) => {
            // 5 % margin around the bounding sphere.
            let dist = fit_sphere(lo, hi, fov_deg, aspect).2 * 1.05;
            (centre + d.normalize() * dist, centre)
        }
    };
    let radius = (0.5 * (hi - lo).length()).max(1e-6);
    let mut cam = Camera::look_at(eye, target);
    if let Some(u) = up {
        cam.up = u;
    }
    cam.fov_y_deg = fov_deg;
    let d = eye.distance(centre);
    cam.near = ((d - radius) * 0.9).max(1e-3 * radius);
    cam.far = (d + radius) * 1.1 + cam.near;
    if ortho {
        let dist = eye.distance(target);
        cam.ortho_height = Some(2.0 * dist * (0.5 * fov_deg.to_radians()).tan());
        // Orthographic: nothing is behind the eye, so near can sit at the sphere.
        cam.near = (d - radius).max(1e-3 * radius) * 0.9;
    }
    cam.validate()?;
    Ok(cam)
}
