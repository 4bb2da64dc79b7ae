//! Limits on the sizes a user gives (resolutions, image sizes, counts), one
//! definition for the command line and scene files. Each check runs before
//! anything is allocated and names the option, the bytes the value implies
//! and the limit, so a typo such as `--resolution 100000` is an error in
//! microseconds instead of an abort after minutes.
//!
//! The memory limits are fixed, documented numbers rather than a probe of
//! the machine: they bound what one array may take on the host. The device's
//! own limits (`CL_DEVICE_MAX_MEM_ALLOC_SIZE`, global memory) are checked by
//! the stages with the `*_bound` functions before they allocate.

use crate::error::{Error, Result};

/// Largest image side in pixels (a 16384² RGBA image is 1 GiB).
pub const MAX_IMAGE_SIDE: u32 = 16_384;
/// Largest samples per axis of a generated volume (`--resolution` of the
/// procedural fields): 1024³ f32 samples are 4 GiB.
pub const MAX_VOLUME_RESOLUTION: usize = 1_024;
/// Largest host array one generated volume may take.
pub const MAX_VOLUME_BYTES: u64 = 4 << 30;
/// Largest vertex count of a generated mesh.
pub const MAX_MESH_VERTICES: usize = 50_000_000;
/// Host bytes per vertex of a generated mesh (f64 positions, about two
/// triangles of u32 indices per vertex).
pub const MESH_BYTES_PER_VERTEX: u64 = 24 + 2 * 12;

/// Bounding radii a drawn mesh may have: the renderer works in single
/// precision, where squared lengths of larger (or smaller) scenes overflow
/// (or vanish), so a mesh outside this range is refused with the range named
/// instead of drawing nothing. Curvature, isosurfaces and the other data
/// outputs have no such limit (they normalise the mesh).
pub const DRAWABLE_RADIUS: (f64, f64) = (1e-15, 1e15);

/// Checks that a mesh of bounding radius `radius` (world units) and centre
/// at distance `offset` from the origin can be drawn ([`DRAWABLE_RADIUS`]).
pub fn check_drawable(what: &str, radius: f64, offset: f64) -> Result<()> {
    let (lo, hi) = DRAWABLE_RADIUS;
    if !(radius.is_finite() && offset.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "{what}: the mesh's bounds are not finite; nothing can be drawn"
        )));
    }
    if radius > hi || offset > hi {
        return Err(Error::InvalidArgument(format!(
            "{what}: the mesh spans {radius:.3e} (bounding radius), {offset:.3e} from the origin; \
             drawing works in single precision and needs both below {hi:e}: rescale the mesh"
        )));
    }
    if radius > 0.0 && radius < lo && offset < lo * 1e6 {
        return Err(Error::InvalidArgument(format!(
            "{what}: the mesh spans {radius:.3e} (bounding radius); drawing works in single \
             precision and needs at least {lo:e}: rescale the mesh"
        )));
    }
    Ok(())
}

fn gib(b: u64) -> String {
    format!("{:.2} GiB", b as f64 / f64::from(1u32 << 30))
}

fn too(option: &str, msg: String) -> Error {
    Error::InvalidArgument(format!("{option}: {msg}"))
}

/// Checks an image size (`option` names where it came from, e.g. `--size`
/// or `output.size`): each side in 1..=[`MAX_IMAGE_SIDE`].
pub fn check_image_size(option: &str, width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 || width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        let bytes = 4 * u64::from(width) * u64::from(height);
        return Err(too(
            option,
            format!(
                "{width}x{height} pixels ({}) must be 1..={MAX_IMAGE_SIDE} pixels each",
                gib(bytes)
            ),
        ));
    }
    Ok(())
}

/// Checks the samples per axis of a generated volume: at least 2 (one cell),
/// at most [`MAX_VOLUME_RESOLUTION`], and n³ f32 samples within
/// [`MAX_VOLUME_BYTES`].
pub fn check_volume_resolution(option: &str, n: usize) -> Result<()> {
    let bytes = (n as u64).saturating_pow(3).saturating_mul(4);
    if n < 2 {
        return Err(too(
            option,
            format!("{n} samples per axis: a volume needs at least 2 (one cell)"),
        ));
    }
    if n > MAX_VOLUME_RESOLUTION || bytes > MAX_VOLUME_BYTES {
        return Err(too(
            option,
            format!(
                "{n}³ samples need {} of host memory; the limit is {MAX_VOLUME_RESOLUTION} per \
                 axis and {}",
                gib(bytes),
                gib(MAX_VOLUME_BYTES)
            ),
        ));
    }
    Ok(())
}

/// Checks the approximate vertex count of a generated mesh: at least 3, at
/// most [`MAX_MESH_VERTICES`].
pub fn check_mesh_vertices(option: &str, n: usize) -> Result<()> {
    let bytes = (n as u64).saturating_mul(MESH_BYTES_PER_VERTEX);
    if n < 3 {
        return Err(too(
            option,
            format!("{n} vertices: a mesh needs at least 3"),
        ));
    }
    if n > MAX_MESH_VERTICES {
        return Err(too(
            option,
            format!(
                "{n} vertices need about {} of host memory; the limit is {MAX_MESH_VERTICES} \
                 vertices ({})",
                gib(bytes),
                gib(MAX_MESH_VERTICES as u64 * MESH_BYTES_PER_VERTEX)
            ),
        ));
    }
    Ok(())
}

/// Checks a count that must be at least 1 (`--runs`, frames, views).
pub fn check_count(option: &str, n: usize, max: usize) -> Result<()> {
    if n == 0 || n > max {
        return Err(too(option, format!("{n} must be 1..={max}")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_name_the_option_the_bytes_and_the_limit() {
        let e = check_volume_resolution("--resolution", 100_000)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--resolution") && e.contains("GiB") && e.contains("1024"),
            "{e}"
        );
        let e = check_volume_resolution("--resolution", 0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("at least 2"), "{e}");
        check_volume_resolution("--resolution", 256).unwrap();
        let e = check_mesh_vertices("--resolution", 100_000_000_000)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--resolution") && e.contains("50000000"), "{e}");
        check_mesh_vertices("--resolution", 40_000).unwrap();
        assert!(check_image_size("--size", 0, 10).is_err());
        assert!(check_image_size("--size", 20_000, 10).is_err());
        check_image_size("--size", 1024, 1024).unwrap();
        let e = check_count("--runs", 0, 1000).unwrap_err().to_string();
        assert!(e.contains("--runs") && e.contains("1..=1000"), "{e}");
    }
}
