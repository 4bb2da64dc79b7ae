//! `[[camera]]` checked: each camera's vectors and mode, orbits expanded
//! into their fitted views; no camera is one fitted view.

use super::raw::CameraSpec;
use super::{CameraKind, Checker, ViewSpec};
use crate::error::Result;
use toml::Spanned;

/// The default view direction (centre → eye) of a fitted camera.
const DEFAULT_DIRECTION: [f32; 3] = [0.4, 0.3, 1.0];

/// Checks every `[[camera]]` and resolves them into views.
pub(super) fn resolve(ck: &Checker<'_>, cameras: &[Spanned<CameraSpec>]) -> Result<Vec<ViewSpec>> {
    let mut views = Vec::new();
    for c in cameras {
        views.extend(camera(c.get_ref()).map_err(|p| ck.err(c.span(), p))?);
    }
    if views.is_empty() {
        views.push(ViewSpec {
            kind: CameraKind::Fit(DEFAULT_DIRECTION),
            up: None,
            fov: 35.0,
            ortho: false,
        });
    }
    Ok(views)
}

/// One camera's views (an orbit has several); errors name the problem, the
/// caller adds the line.
fn camera(s: &CameraSpec) -> std::result::Result<Vec<ViewSpec>, String> {
    let fov = s.fov.unwrap_or(35.0);
    super::camera_file::check_fov(fov)?;
    check_vectors(s)?;
    check_mode(s)?;
    let view = |kind| ViewSpec {
        kind,
        up: s.up,
        fov,
        ortho: s.ortho,
    };
    if let Some(n) = s.orbit {
        return Ok(orbit(s, n)?.into_iter().map(view).collect());
    }
    if let Some(eye) = s.eye {
        if s.target == Some(eye) {
            return Err("eye and target must differ".into());
        }
        return Ok(vec![view(CameraKind::LookAt {
            eye,
            target: s.target,
        })]);
    }
    Ok(vec![view(CameraKind::Fit(
        s.direction.unwrap_or(DEFAULT_DIRECTION),
    ))])
}

/// Checks that the camera's vectors are finite, `up` and `direction`
/// non-zero, and that the view is not parallel to `up`.
fn check_vectors(s: &CameraSpec) -> std::result::Result<(), String> {
    let finite = |v: &Option<[f32; 3]>| v.is_none_or(|v| v.iter().all(|x| x.is_finite()));
    if !(finite(&s.eye) && finite(&s.target) && finite(&s.up) && finite(&s.direction)) {
        return Err("camera vectors must be finite".into());
    }
    if s.up.is_some_and(|u| u == [0.0; 3]) || s.direction.is_some_and(|d| d == [0.0; 3]) {
        return Err("up and direction must be non-zero".into());
    }
    // A view direction parallel to `up` has no image orientation;
    // checked here, with the line, rather than when the camera is
    // built after earlier scenes have rendered.
    let parallel = |d: glam::Vec3| {
        s.up.is_some_and(|u| {
            d.normalize_or_zero()
                .cross(glam::Vec3::from(u).normalize_or_zero())
                .length()
                < 1e-4
        })
    };
    if let Some(d) = s.direction
        && parallel(glam::Vec3::from(d))
    {
        return Err(format!(
            "direction {d:?} is parallel to up {:?}: the image would have no up",
            s.up.unwrap_or_default()
        ));
    }
    if let (Some(eye), Some(target)) = (s.eye, s.target)
        && target != eye
        && parallel(glam::Vec3::from(target) - glam::Vec3::from(eye))
    {
        return Err(format!(
            "the view from {eye:?} to {target:?} is parallel to up {:?}: the image \
             would have no up",
            s.up.unwrap_or_default()
        ));
    }
    Ok(())
}

/// Checks that the camera has one mode (eye, direction or orbit) and only
/// the keys that go with it.
fn check_mode(s: &CameraSpec) -> std::result::Result<(), String> {
    let modes = [s.eye.is_some(), s.direction.is_some(), s.orbit.is_some()];
    if modes.iter().filter(|&&m| m).count() > 1 {
        return Err("a camera has one of eye, direction or orbit".into());
    }
    if s.target.is_some() && s.eye.is_none() {
        return Err("target goes with eye".into());
    }
    if (s.elevation.is_some() || s.azimuth.is_some()) && s.orbit.is_none() {
        return Err("elevation and azimuth go with orbit".into());
    }
    Ok(())
}

/// The fitted views of an orbit of `n` views around the up axis.
fn orbit(s: &CameraSpec, n: usize) -> std::result::Result<Vec<CameraKind>, String> {
    if !(1..=360).contains(&n) {
        return Err(format!("orbit {n} must be 1..=360 views"));
    }
    let el = s.elevation.unwrap_or(20.0);
    if !(el.is_finite() && el.abs() < 90.0) {
        return Err(format!("elevation {el} must be in (−90, 90) degrees"));
    }
    let az0 = s.azimuth.unwrap_or(0.0);
    let up = glam::Vec3::from(s.up.unwrap_or([0.0, 1.0, 0.0])).normalize();
    // An orthonormal frame around `up`: the azimuth-0 view looks from +Z
    // when up is +Y.
    let side = up.any_orthonormal_pair();
    let (a, b) = if up.abs_diff_eq(glam::Vec3::Y, 1e-6) {
        (glam::Vec3::Z, glam::Vec3::X)
    } else {
        (side.1, side.0)
    };
    Ok((0..n)
        .map(|i| {
            let az = (az0 + 360.0 * i as f32 / n as f32).to_radians();
            let (el, az) = (el.to_radians(), az);
            let d = (a * az.cos() + b * az.sin()) * el.cos() + up * el.sin();
            CameraKind::Fit(d.to_array())
        })
        .collect())
}
