//! Headerless ("raw") volumes: the samples only, described by a
//! [`RawSpec`]. The file size is checked against the spec before the file is
//! read, so a wrong type or dimension is reported without reading gigabytes.

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use super::{RawSpec, ScalarType, Volume, byte_count, convert_into, size_problem, voxel_count};
use crate::error::{Error, Result};

/// Reads `path` as `spec.dims` samples of `spec.scalar` after
/// `spec.header_bytes` bytes.
pub(super) fn load(path: &Path, spec: &RawSpec) -> Result<Volume> {
    let source = path.display().to_string();
    let count = voxel_count(spec.dims, &source, "raw dimensions")?;
    let expected = byte_count(count, spec.scalar, &source, "raw dimensions")?;
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let size = std::fs::metadata(path).map_err(io)?.len();
    let found = size.saturating_sub(spec.header_bytes as u64);
    if size < spec.header_bytes as u64 || found != expected as u64 {
        let mut problem = size_problem(
            &spec.dims,
            spec.scalar,
            usize::try_from(found).unwrap_or(usize::MAX),
        );
        if spec.header_bytes > 0 {
            problem += &format!(
                " after the {}-byte header (file size {size})",
                spec.header_bytes
            );
        }
        return Err(Error::input(&source, "data", problem));
    }
    if spec.scalar == ScalarType::F32 && spec.big_endian == cfg!(target_endian = "big") {
        // Native f32: read straight into the samples, no second buffer.
        let mut values = vec![0.0f32; count];
        let mut read = || -> std::io::Result<()> {
            let mut f = std::fs::File::open(path)?;
            f.seek(SeekFrom::Start(spec.header_bytes as u64))?;
            f.read_exact(bytemuck::cast_slice_mut(&mut values))
        };
        read().map_err(io)?;
        return finish(spec, values, &source);
    }
    let bytes = super::read_file(path)?;
    // The file may have changed since its size was taken.
    let data = bytes
        .get(spec.header_bytes..)
        .filter(|d| d.len() == expected)
        .ok_or_else(|| {
            Error::input(
                &source,
                "data",
                size_problem(
                    &spec.dims,
                    spec.scalar,
                    bytes.len().saturating_sub(spec.header_bytes),
                ),
            )
        })?;
    let mut values = Vec::with_capacity(count);
    convert_into(data, spec.scalar, spec.big_endian, &mut values);
    finish(spec, values, &source)
}

/// The volume of `values` with the spec's geometry.
fn finish(spec: &RawSpec, values: Vec<f32>, source: &str) -> Result<Volume> {
    Volume::new(spec.dims, values, source)?
        .with_geometry(spec.spacing, spec.origin)
        .map_err(|e| Error::input(source, "raw geometry", e.to_string()))
}
