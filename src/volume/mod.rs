//! Scalar volumes on a regular grid: the input of the isosurface stage
//! (`marching_cubes`) and of the SDF line stage.
//!
//! A [`Volume`] is a dense `f32` grid, x fastest, with an axis-aligned
//! geometry (spacing and origin). Every loader converts the file's scalar type
//! to `f32` in one bulk pass over the bytes, so a binary file loads at about
//! the speed it is read.
//!
//! Formats, one file each: headerless raw ([`RawSpec`]), NRRD (`.nrrd`,
//! `.nhdr`), MetaImage (`.mhd`, `.mha`), VTK legacy `STRUCTURED_POINTS`
//! (`.vtk`) and VTK XML ImageData (`.vti`) in `vtk.rs`, and SLC (`.slc`).
//! Procedural signed distance fields with analytic curvature are in [`sdf`].
//! This file holds the [`Volume`] type; `load.rs` the dispatcher
//! ([`load`]); `format.rs` what the readers share about formats (scalar types, sizes,
//! header numbers, geometry); `decode.rs` the decoding of samples
//! (conversion, ASCII numbers, decompression, NRRD and MetaImage payloads).
//!
//! All parsers are hand-written and strict about what they use: no NRRD crate
//! exists, and the VTK crate (`vtkio`) is a pre-release whose errors carry no
//! file or element context. Bad input never panics; it is an
//! [`Error::InvalidInput`] naming the file, the element (`header line 4`,
//! `data file quarter.7`, ...) and the problem, an [`Error::Io`] naming a file
//! that cannot be read, or an [`Error::UnsupportedFormat`] for valid input
//! that shapecue does not read (a sheared grid, a 64-bit integer type, ...).
//!
//! Memory is bounded by the file: a header's sizes are checked against the
//! bytes before anything is allocated, compressed data are inflated no
//! further than the header calls for, and the binary detached data files of
//! NRRD and MetaImage headers are sized from their metadata and read as a
//! stream (only the bytes to skip and the samples), so a data file much
//! larger than its header says is refused unread.
//!
//! Grids whose axes point the negative way (a negative spacing, or a
//! direction matrix with `-1` on its diagonal) are flipped on load so that
//! spacing is always positive and every sample keeps its world position.

mod data_files;
mod decode;
mod format;
pub mod gradient;
mod load;
mod mhd;
mod nrrd;
mod raw;
pub mod sdf;
mod slc;
mod vtk;

pub use format::{RawSpec, ScalarType};
pub use load::{load, load_with_files};

// The helpers the readers share, named here so that each reader takes them
// from `super`.
use decode::{
    Compression, Encoding, MAX_INFLATE, Payload, Skip, check_inflate, convert_into, decompress,
    parse_ascii_into,
};
use format::{
    byte_count, diagonal, dimension, dims_text, lines_with_end, number, numbers, open_file,
    oriented, read_file, scalar_type, size_problem, skip_line, skip_lines, voxel_count,
};

use crate::error::{Error, Result};
use crate::spec::marching_cubes::Inside;
use std::borrow::Cow;

/// A scalar volume on a regular grid.
///
/// Sample `(x, y, z)` is `values[x + nx*(y + ny*z)]` (x fastest) and lies at
/// world position `origin + spacing * (x, y, z)`.
#[derive(Clone, Debug)]
pub struct Volume {
    /// Number of samples along x, y and z (each at least 1).
    pub dims: [usize; 3],
    /// World units per voxel step along each axis (finite, > 0).
    pub spacing: [f64; 3],
    /// World position of sample `(0, 0, 0)`.
    pub origin: [f64; 3],
    /// The samples, converted from the file's scalar type; NaN is allowed.
    pub values: Vec<f32>,
}

impl Volume {
    /// A volume with spacing 1 and origin 0.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidInput`] (naming `source`) when a dimension is 0, the
    /// product of the dimensions overflows, or `values` does not hold exactly
    /// that many samples.
    pub fn new(dims: [usize; 3], values: Vec<f32>, source: &str) -> Result<Volume> {
        let n = voxel_count(dims, source, "dimensions")?;
        if values.len() != n {
            return Err(Error::input(
                source,
                "values",
                format!(
                    "{} values for a {} grid of {n} samples",
                    values.len(),
                    dims_text(dims)
                ),
            ));
        }
        Ok(Volume {
            dims,
            spacing: [1.0; 3],
            origin: [0.0; 3],
            values,
        })
    }

    /// Sets the spacing and origin.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidArgument`] when a spacing is not finite and positive or
    /// an origin coordinate is not finite.
    pub fn with_geometry(mut self, spacing: [f64; 3], origin: [f64; 3]) -> Result<Volume> {
        if let Some(s) = spacing.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(Error::InvalidArgument(format!(
                "volume spacing ({}): {s} is not a finite positive number",
                crate::error::values(spacing, ", ")
            )));
        }
        if !origin.iter().all(|o| o.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "volume origin ({}) is not finite",
                crate::error::values(origin, ", ")
            )));
        }
        self.spacing = spacing;
        self.origin = origin;
        Ok(self)
    }

    /// Index of sample `(x, y, z)` in [`Volume::values`].
    #[inline]
    pub fn index(&self, x: usize, y: usize, z: usize) -> usize {
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    /// Sample `(x, y, z)`. Panics when out of range, like slice indexing.
    #[inline]
    pub fn value(&self, x: usize, y: usize, z: usize) -> f32 {
        self.values[self.index(x, y, z)]
    }

    /// Number of samples.
    pub fn voxel_count(&self) -> usize {
        self.values.len()
    }

    /// World position of index-space point `p` (fractional indices allowed).
    pub fn world(&self, p: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| self.origin[i] + self.spacing[i] * p[i])
    }

    /// Smallest and largest sample, ignoring NaN; `None` when every sample
    /// is NaN.
    pub fn range(&self) -> Option<(f32, f32)> {
        let mut it = self.values.iter().copied().filter(|v| !v.is_nan());
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v))))
    }

    /// The largest magnitude of a finite sample (0 when there is none).
    pub fn max_finite_abs(&self) -> f32 {
        // Sixteen running maxima of plain selects (not f32::max, whose NaN
        // rule keeps the loop scalar), so that it vectorises: infinities
        // and NaN fail `a < INFINITY` and count as 0.
        fn keep(m: f32, v: f32) -> f32 {
            let a = v.abs();
            let a = if a < f32::INFINITY { a } else { 0.0 };
            if a > m { a } else { m }
        }
        let mut acc = [0f32; 16];
        let chunks = self.values.chunks_exact(16);
        let tail = chunks.remainder();
        for c in chunks {
            for (m, &v) in acc.iter_mut().zip(c) {
                *m = keep(*m, v);
            }
        }
        let m = tail.iter().fold(0f32, |m, &v| keep(m, v));
        acc.iter().fold(m, |a, &b| if b > a { b } else { a })
    }

    /// Size of the samples in memory, in bytes.
    pub fn bytes(&self) -> u64 {
        (self.values.len() as u64) * std::mem::size_of::<f32>() as u64
    }

    /// The volume and iso value that marching cubes and the SDF lines see
    /// for an object on the `inside` side of `iso`: both orient their
    /// output out of the region *below* the iso value, so for
    /// [`Inside::Below`] (distance fields) this is the volume itself, and for
    /// [`Inside::Above`] (density data such as CT) the values and the iso
    /// value are negated (exact in f32, NaN stays NaN), so normals point out
    /// of the object and its convex parts get positive curvature. The one
    /// place this rule is written.
    pub fn oriented(&self, iso: f32, inside: Inside) -> (Cow<'_, Volume>, f32) {
        match inside {
            Inside::Below => (Cow::Borrowed(self), iso),
            Inside::Above => (Cow::Owned(self.clone().negated()), -iso),
        }
    }

    /// [`Volume::oriented`] taking the volume by value: negates in place,
    /// without a copy, for a caller that keeps only the oriented volume.
    pub fn into_oriented(self, iso: f32, inside: Inside) -> (Volume, f32) {
        match inside {
            Inside::Below => (self, iso),
            Inside::Above => (self.negated(), -iso),
        }
    }

    fn negated(mut self) -> Volume {
        self.values.iter_mut().for_each(|x| *x = -*x);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oriented_negates_only_for_inside_above() {
        let v = Volume::new([2, 1, 1], vec![1.5, f32::NAN], "t").unwrap();
        let (b, iso) = v.oriented(0.25, Inside::Below);
        assert!(matches!(b, Cow::Borrowed(_)));
        assert_eq!(iso, 0.25);
        let (a, iso) = v.oriented(0.25, Inside::Above);
        assert!(matches!(a, Cow::Owned(_)));
        assert_eq!(iso, -0.25);
        assert_eq!(a.values[0], -1.5);
        assert!(a.values[1].is_nan());
        // Orientation preserves which samples are above the (new) iso.
        assert_eq!(1.5 > 0.25, a.values[0] < iso);
        let (o, iso2) = v.clone().into_oriented(0.25, Inside::Above);
        assert_eq!(o.values[0].to_bits(), a.values[0].to_bits());
        assert_eq!(iso2, iso);
        let (o, iso3) = v.into_oriented(0.25, Inside::Below);
        assert_eq!((o.values[0], iso3), (1.5, 0.25));
    }
}
