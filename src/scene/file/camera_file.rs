//! Camera sets as scene views: the fitted views of evenly spread directions
//! ([`fibonacci_views`]) and camera files ([`load_camera_file`]), JSON
//! lists of explicit cameras:
//!
//! ```json
//! {"cameras": [
//!   {"eye": [0, 0.5, 3], "target": [0, 0.5, 0]},
//!   {"eye": [3, 1, 0], "target": [0, 0.5, 0], "up": [0, 1, 0], "fov": 30},
//!   {"eye": [0, 4, 0.1], "target": [0, 0, 0], "ortho": 2.5}
//! ]}
//! ```
//!
//! `eye` and `target` are required (world coordinates); `up` defaults to
//! +Y (+Z when looking along Y); `fov` is the vertical field of view in
//! degrees; `ortho` an orthographic projection showing that world-space
//! height at the target (a view takes `fov` or `ortho`, not both). Cameras
//! are counted from 0, as the views they become.

use super::{CameraKind, ViewSpec};
use crate::error::{Error, Result};
use crate::spec::cameras::{MAX_VIEWS, fibonacci_directions};
use std::path::Path;

/// What a camera of a set takes when it does not say: the vertical field
/// of view in degrees and whether the view is orthographic (showing the
/// height the perspective view shows at the target).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraDefaults {
    /// Vertical field of view in degrees, within [`FOV_RANGE`].
    pub fov: f32,
    /// Orthographic.
    pub ortho: bool,
}

impl Default for CameraDefaults {
    fn default() -> Self {
        CameraDefaults {
            fov: 40.0,
            ortho: false,
        }
    }
}

/// One camera of a camera file, as written (read as f64, so that a value
/// too large for the renderer is named as written rather than as the
/// infinity an f32 would make of it).
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraEntry {
    eye: [f64; 3],
    target: [f64; 3],
    up: Option<[f64; 3]>,
    fov: Option<f64>,
    ortho: Option<f64>,
}

/// The largest coordinate (and orthographic height) a camera may have, in
/// the mesh's units: the renderer and the line kernels work in f32, whose
/// squared distances overflow past about 1e19.
pub const MAX_COORDINATE: f64 = 1e12;

/// The fields of view a camera may have, in degrees: below the smallest
/// the projection of a fitted view needs more than f32 precision; towards
/// 180 every line projects onto a point.
pub const FOV_RANGE: (f32, f32) = (0.01, 170.0);

/// The largest camera file read: a set of [`MAX_VIEWS`] cameras written
/// with long numbers takes a few MB; a larger file is refused before it is
/// parsed.
pub const MAX_CAMERA_FILE_BYTES: u64 = 16 << 20;

/// `n` views fitted to the bounds (the bounding sphere filling the view
/// with a 5 % margin) from the directions of
/// [`fibonacci_directions`], each looking at the centre of the bounds.
///
/// # Errors
/// [`Error::InvalidArgument`] for `n` outside 1..=[`MAX_VIEWS`] or a field
/// of view outside (0, 180) degrees.
pub fn fibonacci_views(n: usize, defaults: CameraDefaults) -> Result<Vec<ViewSpec>> {
    if !(1..=MAX_VIEWS).contains(&n) {
        return Err(Error::InvalidArgument(format!(
            "a camera set holds 1 to {MAX_VIEWS} views, not {n}"
        )));
    }
    check_fov(defaults.fov).map_err(Error::InvalidArgument)?;
    Ok(fibonacci_directions(n)
        .into_iter()
        .map(|d| ViewSpec {
            kind: CameraKind::Fit(d),
            up: None,
            fov: defaults.fov,
            ortho: defaults.ortho,
        })
        .collect())
}

/// The views of the camera file at `path` (see the module's format), one
/// per camera in order, each with `defaults` where it says nothing.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read; [`Error::InvalidInput`]
/// naming the file, the camera and the problem otherwise
/// ([`parse_camera_file`]).
pub fn load_camera_file(path: &Path, defaults: CameraDefaults) -> Result<Vec<ViewSpec>> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let len = std::fs::metadata(path).map_err(io)?.len();
    if len > MAX_CAMERA_FILE_BYTES {
        return Err(Error::input(
            path.display().to_string(),
            "the file",
            format!(
                "{len} bytes, more than the {MAX_CAMERA_FILE_BYTES} a camera file may hold \
                 ({MAX_VIEWS} cameras at most)"
            ),
        ));
    }
    let text = std::fs::read_to_string(path).map_err(io)?;
    parse_camera_file(&text, &path.display().to_string(), defaults)
}

/// The views of a camera file's `text`; errors name `name` (the file).
///
/// # Errors
/// [`Error::InvalidInput`] naming the file and the camera (counted from 0)
/// for text that is not JSON, a document without its `cameras` list, an
/// empty list or one of more than [`MAX_VIEWS`], and a camera with a
/// missing or unknown key, a non-finite number, eye and target at one
/// point, a zero `up` or one along the view, a field of view outside
/// (0, 180) degrees, a height that is not positive, or both `fov` and
/// `ortho`.
pub fn parse_camera_file(
    text: &str,
    name: &str,
    defaults: CameraDefaults,
) -> Result<Vec<ViewSpec>> {
    let bad = |element: &str, problem: String| Error::input(name, element, problem);
    let doc: serde_json::Value =
        serde_json::from_str(text).map_err(|e| bad("the file", format!("not JSON ({e})")))?;
    let list = (doc.as_object())
        .and_then(|o| o.get("cameras"))
        .and_then(|c| c.as_array())
        .ok_or_else(|| {
            bad(
                "the file",
                "expected an object with a \"cameras\" list, as {\"cameras\": [{\"eye\": \
                 [0, 0, 3], \"target\": [0, 0, 0]}]}"
                    .into(),
            )
        })?;
    if let Some(k) = (doc.as_object().into_iter().flat_map(|o| o.keys())).find(|k| *k != "cameras")
    {
        return Err(bad(
            "the file",
            format!("unknown key \"{k}\" (only \"cameras\")"),
        ));
    }
    if list.is_empty() {
        return Err(bad(
            "the camera list",
            "it is empty: give at least one camera".into(),
        ));
    }
    if list.len() > MAX_VIEWS {
        return Err(bad(
            "the camera list",
            format!(
                "{} cameras, more than the {MAX_VIEWS} a set may hold",
                list.len()
            ),
        ));
    }
    (list.iter().enumerate())
        .map(|(i, v)| {
            let element = format!("camera {i}");
            check_shape(v).map_err(|p| bad(&element, p))?;
            let entry: CameraEntry =
                serde_json::from_value(v.clone()).map_err(|e| bad(&element, e.to_string()))?;
            check_magnitudes(v).map_err(|p| bad(&element, p))?;
            camera_view(&entry, defaults).map_err(|p| bad(&element, p))
        })
        .collect()
}

/// Checks that a camera is an object of the keys a camera takes, each of
/// its kind (three numbers, or one), in words rather than the JSON
/// parser's.
fn check_shape(v: &serde_json::Value) -> std::result::Result<(), String> {
    const KEYS: &str = "eye, target, up, fov and ortho";
    let Some(o) = v.as_object() else {
        return Err(format!(
            "{v} is not a camera: give an object such as {{\"eye\": [0, 0, 3], \"target\": [0, 0, 0]}}"
        ));
    };
    if let Some(k) = o
        .keys()
        .find(|k| !["eye", "target", "up", "fov", "ortho"].contains(&k.as_str()))
    {
        return Err(format!("unknown key \"{k}\" (a camera takes {KEYS})"));
    }
    for key in ["eye", "target"] {
        if !o.contains_key(key) {
            return Err(format!(
                "no \"{key}\": every camera needs an eye and a target"
            ));
        }
    }
    for (key, x) in o {
        let three = matches!(key.as_str(), "eye" | "target" | "up");
        let ok = match x {
            serde_json::Value::Array(a) if three => a.len() == 3 && a.iter().all(|c| c.is_number()),
            serde_json::Value::Number(_) => !three,
            serde_json::Value::Null => key == "up" || key == "fov" || key == "ortho",
            _ => false,
        };
        if !ok {
            let want = if three {
                "three numbers [x, y, z]"
            } else {
                "a number"
            };
            return Err(format!("{key} must be {want}, not {x}"));
        }
    }
    Ok(())
}

/// Refuses a coordinate or height beyond [`MAX_COORDINATE`], naming the
/// key and the value as written.
fn check_magnitudes(v: &serde_json::Value) -> std::result::Result<(), String> {
    for key in ["eye", "target", "ortho"] {
        let numbers: Vec<&serde_json::Value> = match v.get(key) {
            Some(serde_json::Value::Array(a)) => a.iter().collect(),
            Some(x) => vec![x],
            None => vec![],
        };
        for n in numbers {
            if n.as_f64().is_some_and(|x| x.abs() > MAX_COORDINATE) {
                return Err(format!(
                    "{key} has {n}, beyond the {MAX_COORDINATE:e} a camera may have (the \
                     drawing works in single precision)"
                ));
            }
        }
    }
    Ok(())
}

/// One camera's view; the error is the problem in words.
fn camera_view(c: &CameraEntry, defaults: CameraDefaults) -> std::result::Result<ViewSpec, String> {
    let vectors = [
        ("eye", Some(c.eye)),
        ("target", Some(c.target)),
        ("up", c.up),
    ];
    for (key, v) in vectors {
        if let Some(v) = v
            && !v.iter().all(|x| x.is_finite())
        {
            return Err(format!(
                "{key} has a number that is not finite (or too large)"
            ));
        }
    }
    let f = |v: [f64; 3]| v.map(|x| x as f32);
    let (eye, target) = (glam::Vec3::from(f(c.eye)), glam::Vec3::from(f(c.target)));
    let dir = target - eye;
    let scale = eye.abs().max(target.abs()).max_element().max(1.0);
    if dir.length() <= 1e-6 * scale {
        return Err("eye and target are at one point: the camera looks nowhere".into());
    }
    if let Some(u) = c.up {
        let u = glam::DVec3::from(u).normalize_or_zero().as_vec3();
        if u.length() == 0.0 || !u.length().is_finite() {
            return Err("up is zero: give the direction that is up in the image".into());
        }
        if dir.normalize().cross(u.normalize()).length() < 1e-4 {
            return Err(
                "up lies along the view (eye to target): the image would have no up".into(),
            );
        }
    }
    let (fov, ortho) = match (c.fov, c.ortho) {
        (Some(_), Some(_)) => {
            return Err("give fov (perspective) or ortho (orthographic height), not both".into());
        }
        (Some(f), None) => (f as f32, false),
        // The executor's orthographic view shows the height the
        // perspective view of `fov` shows at the target: the fov whose
        // view shows `h` there.
        (None, Some(h)) => {
            if !(h.is_finite() && h > 0.0) {
                return Err(format!("ortho {h} must be a positive height"));
            }
            let fov = 2.0 * (0.5 * h / f64::from(dir.length())).atan().to_degrees();
            return finish(c, fov as f32, true).map_err(|_| {
                format!(
                    "ortho {h} from {} away gives a field of view of {fov:.4} degrees, outside \
                     [{}, {}]: give a height nearer the eye's distance",
                    dir.length(),
                    FOV_RANGE.0,
                    FOV_RANGE.1
                )
            });
        }
        (None, None) => (defaults.fov, defaults.ortho),
    };
    finish(c, fov, ortho)
}

/// The view of a checked camera with its field of view.
fn finish(c: &CameraEntry, fov: f32, ortho: bool) -> std::result::Result<ViewSpec, String> {
    check_fov(fov)?;
    let f = |v: [f64; 3]| v.map(|x| x as f32);
    Ok(ViewSpec {
        kind: CameraKind::LookAt {
            eye: f(c.eye),
            target: Some(f(c.target)),
        },
        up: c.up.map(f),
        fov,
        ortho,
    })
}

/// A field of view within [`FOV_RANGE`] degrees.
pub fn check_fov(fov: f32) -> std::result::Result<(), String> {
    let (lo, hi) = FOV_RANGE;
    if (lo..=hi).contains(&fov) {
        Ok(())
    } else {
        Err(format!(
            "fov {fov} degrees is outside [{lo}, {hi}], the field of view a camera may have: \
             narrower views need more than single precision, and towards 180 degrees every line \
             projects onto a point"
        ))
    }
}
