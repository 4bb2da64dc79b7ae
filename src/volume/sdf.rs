//! Procedural scalar fields on the cube `[-1, 1]^3`: the analytic oracles of
//! the isosurface tests and the generated inputs of the benches, so they
//! need no downloaded file.
//!
//! The sphere and the torus are exact signed distances (negative inside),
//! computed in `f64` and stored as `f32`, with analytic principal curvatures
//! for checking curvature estimates on their zero isosurface. The gyroid is
//! the level-set `sin x cos y + sin y cos z + sin z cos x` (not a distance),
//! with [`GYROID_PERIODS`] periods across the cube: a large, genus-rich
//! surface for throughput measurements. The ellipsoid (semi-axes
//! [`ELLIPSOID_A`], [`ELLIPSOID_B`], [`ELLIPSOID_C`]) has no closed-form
//! distance; it stores a first-order distance whose zero set is exactly the
//! ellipsoid (see [`ellipsoid_distance`]), with analytic curvature
//! ([`ellipsoid_curvature`]): the oracle of the curvature-directed strokes.

use std::str::FromStr;

use super::Volume;
use crate::error::{Error, Result};

/// Radius of [`Sdf::Sphere`].
pub const SPHERE_RADIUS: f64 = 0.8;
/// Major radius of [`Sdf::Torus`] (centre of the tube to the z axis).
pub const TORUS_R: f64 = 0.6;
/// Tube radius of [`Sdf::Torus`].
pub const TORUS_TUBE: f64 = 0.25;
/// Periods of [`Sdf::Gyroid`] across the cube along each axis (the field
/// is evaluated at `π·P·p`). Chosen so that at 256³ samples 1,259,955 cells
/// have a sign change and 1,269,654 grid edges are crossed, i.e. about
/// 2.54 M marching-cubes triangles (twice the vertex count of a closed
/// triangulation); `tests/volume.rs` (`gyroid_calibration`) measures it.
pub const GYROID_PERIODS: f64 = 4.0;
/// Semi-axis of [`Sdf::Ellipsoid`] along x (the longest).
pub const ELLIPSOID_A: f64 = 0.8;
/// Semi-axis of [`Sdf::Ellipsoid`] along y.
pub const ELLIPSOID_B: f64 = 0.5;
/// Semi-axis of [`Sdf::Ellipsoid`] along z (the shortest).
pub const ELLIPSOID_C: f64 = 0.3;

/// A procedural field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sdf {
    /// Sphere of radius [`SPHERE_RADIUS`] at the origin.
    Sphere,
    /// Torus around the z axis, radii [`TORUS_R`] and [`TORUS_TUBE`].
    Torus,
    /// Gyroid with [`GYROID_PERIODS`] periods per axis.
    Gyroid,
    /// Axis-aligned ellipsoid at the origin with semi-axes [`ELLIPSOID_A`],
    /// [`ELLIPSOID_B`], [`ELLIPSOID_C`], sampled with [`ellipsoid_distance`].
    Ellipsoid,
}

impl FromStr for Sdf {
    type Err = Error;

    /// `sphere`, `torus`, `gyroid` or `ellipsoid` (case-insensitive).
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "sphere" => Ok(Sdf::Sphere),
            "torus" => Ok(Sdf::Torus),
            "gyroid" => Ok(Sdf::Gyroid),
            "ellipsoid" => Ok(Sdf::Ellipsoid),
            _ => Err(Error::InvalidArgument(format!(
                "unknown procedural volume '{s}' (expected sphere, torus, gyroid or ellipsoid)"
            ))),
        }
    }
}

/// Samples `kind` on a `res³` grid covering `[-1, 1]^3` (spacing
/// `2/(res-1)`, origin `-1`). `res` below 2 is taken as 2.
///
/// The grid coordinates are computed as `(2i - (res-1)) / (res-1)`, exactly
/// antisymmetric about the centre, so symmetric shapes give symmetric values.
pub fn sdf(kind: Sdf, res: usize) -> Volume {
    let res = res.max(2);
    let n = res - 1;
    let coord: Vec<f64> = (0..res)
        .map(|i| (2.0 * i as f64 - n as f64) / n as f64)
        .collect();
    let mut values = Vec::with_capacity(res * res * res);
    match kind {
        Sdf::Sphere => {
            for &z in &coord {
                for &y in &coord {
                    values.extend(coord.iter().map(|&x| sphere_distance([x, y, z]) as f32));
                }
            }
        }
        Sdf::Torus => {
            for &z in &coord {
                for &y in &coord {
                    values.extend(coord.iter().map(|&x| torus_distance([x, y, z]) as f32));
                }
            }
        }
        Sdf::Ellipsoid => {
            for &z in &coord {
                for &y in &coord {
                    values.extend(coord.iter().map(|&x| ellipsoid_distance([x, y, z]) as f32));
                }
            }
        }
        Sdf::Gyroid => {
            // sin and cos per axis once: the field is separable per term.
            let w = std::f64::consts::PI * GYROID_PERIODS;
            let s: Vec<f64> = coord.iter().map(|c| (w * c).sin()).collect();
            let c: Vec<f64> = coord.iter().map(|c| (w * c).cos()).collect();
            for z in 0..res {
                for y in 0..res {
                    values
                        .extend((0..res).map(|x| (s[x] * c[y] + s[y] * c[z] + s[z] * c[x]) as f32));
                }
            }
        }
    }
    let h = 2.0 / n as f64;
    Volume {
        dims: [res; 3],
        spacing: [h; 3],
        origin: [-1.0; 3],
        values,
    }
}

/// [`sdf`] by name (`sphere`, `torus`, `gyroid`, `ellipsoid`), checking `res`.
///
/// # Errors
///
/// [`Error::InvalidArgument`] for an unknown name, `res < 2`, or a grid too
/// large to address.
pub fn sdf_by_name(name: &str, res: usize) -> Result<Volume> {
    let kind: Sdf = name.parse()?;
    // Checked before allocating: the error names the option, the bytes and
    // the limit (a typo like 100000 must not abort on allocation).
    crate::spec::limits::check_volume_resolution("the field's resolution", res)?;
    Ok(sdf(kind, res))
}

/// Signed distance to the sphere (negative inside).
pub fn sphere_distance(p: [f64; 3]) -> f64 {
    (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - SPHERE_RADIUS
}

/// Signed distance to the torus (negative inside the tube).
pub fn torus_distance(p: [f64; 3]) -> f64 {
    let q = (p[0] * p[0] + p[1] * p[1]).sqrt() - TORUS_R;
    (q * q + p[2] * p[2]).sqrt() - TORUS_TUBE
}

/// First-order signed distance to the ellipsoid (negative inside):
/// `f = (k0 - 1) · k0 / k1` with `k0 = |p / (a,b,c)|` and
/// `k1 = |p / (a²,b²,c²)|`.
///
/// The exact distance to an ellipsoid needs a root of a sixth-degree
/// polynomial. This field has the same zero set exactly (`k0 = 1`), the
/// right sign (`k0 < 1` inside), and a gradient of length exactly 1 on the
/// surface (there `∇f = ∇k0 / k1` and `|∇k0| = k1`), so near the surface it
/// agrees with the true distance to first order, which the simpler
/// `(k0 - 1)·min(a,b,c)` does not (its gradient length varies from
/// `c/a` to 1 over the surface). Away from the surface it is a distance
/// estimate, not a distance. At the centre, where `k0/k1` has no limit,
/// it returns the true distance `-min(a,b,c)`.
pub fn ellipsoid_distance(p: [f64; 3]) -> f64 {
    let (a, b, c) = (ELLIPSOID_A, ELLIPSOID_B, ELLIPSOID_C);
    let k0 = ((p[0] / a).powi(2) + (p[1] / b).powi(2) + (p[2] / c).powi(2)).sqrt();
    let k1 =
        ((p[0] / (a * a)).powi(2) + (p[1] / (b * b)).powi(2) + (p[2] / (c * c)).powi(2)).sqrt();
    if k1 == 0.0 {
        return -a.min(b).min(c);
    }
    (k0 - 1.0) * k0 / k1
}

/// Principal curvatures `(k1, k2)`, `k1 >= k2`, of the ellipsoid of
/// [`Sdf::Ellipsoid`] at a point on it; positive = convex with respect to
/// the outward normal (at `(a, 0, 0)`: `a/c²` and `a/b²`). Same formula as
/// [`crate::mesh::ellipsoid_curvature`].
pub fn ellipsoid_curvature(p: [f64; 3]) -> (f64, f64) {
    crate::mesh::ellipsoid_curvature(ELLIPSOID_A, ELLIPSOID_B, ELLIPSOID_C, p)
}

/// Principal curvatures `(k1, k2)`, `k1 >= k2`, of the sphere at a point on
/// it; positive = convex with respect to the outward normal.
pub fn sphere_curvature(_p: [f64; 3]) -> (f64, f64) {
    (1.0 / SPHERE_RADIUS, 1.0 / SPHERE_RADIUS)
}

/// Principal curvatures `(k1, k2)`, `k1 >= k2`, of the torus at a point on
/// it (`1/r` around the tube, `cos v / (R + r cos v)` around the axis, which
/// is negative on the inner half); positive = convex with respect to the
/// outward normal. Same convention as [`crate::mesh::torus_curvature`].
pub fn torus_curvature(p: [f64; 3]) -> (f64, f64) {
    crate::mesh::torus_curvature(TORUS_R, TORUS_TUBE, p)
}
