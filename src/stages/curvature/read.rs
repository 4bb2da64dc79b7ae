//! Reading an estimator's results back: copied and converted to f64
//! ([`CurvatureEstimator::read_placed`], [`CurvatureEstimator::read_intermediate`])
//! or read in place from the mapped device buffers ([`MappedField`]), with
//! the same operations and so the same bits either way.

use super::{CurvatureEstimator, Intermediate};
use crate::error::{Error, Result};
use crate::gpu::Mapped;
use crate::spec::curvature::{CurvatureField, Precision, VertexCurvature};
use opencl3::memory::Buffer;

impl CurvatureEstimator {
    /// One device real (f32 or f64 bytes, host byte order) as f64.
    fn real_at(&self, b: &[u8]) -> f64 {
        match self.opts.precision {
            Precision::F32 => f64::from(f32::from_ne_bytes(b.try_into().expect("4 bytes"))),
            Precision::F64 => f64::from_ne_bytes(b.try_into().expect("8 bytes")),
        }
    }

    /// Device reals as f64, in one pass with one allocation (a 2M-vertex
    /// read-back is ~300 MB of f64s, and every intermediate vector costs its
    /// page faults).
    fn to_f64(&self, bytes: &[u8]) -> Vec<f64> {
        self.rows::<1>(bytes).map(|[x]| x).collect()
    }

    fn to_vecs<const N: usize>(&self, bytes: &[u8]) -> Vec<[f64; N]> {
        self.rows(bytes).collect()
    }

    /// The values of a buffer of `N` device reals per vertex, vertex by
    /// vertex, as f64.
    fn rows<'b, const N: usize>(&'b self, bytes: &'b [u8]) -> impl Iterator<Item = [f64; N]> + 'b {
        let r = self.real;
        bytes
            .chunks_exact(N * r)
            .map(move |c| std::array::from_fn(|i| self.real_at(&c[i * r..(i + 1) * r])))
    }

    /// Reads the raw device state (normalized coordinates): the seven
    /// buffers one after another through one staging buffer, each converted
    /// to f64 as it arrives. One staging buffer rather than seven: on a
    /// 2M-vertex mesh the seven would be 150 MB of fresh pages whose first
    /// touch costs more than the copies.
    pub fn read_intermediate(&self) -> Result<Intermediate> {
        let mut st = vec![0u8; 4 * self.nv * self.real];
        Ok(Intermediate {
            normals: self.to_vecs::<3>(self.fetch(&mut st, &self.nrm, 3)?),
            areas: self.to_f64(self.fetch(&mut st, &self.area, 1)?),
            pd1: self.to_vecs::<3>(self.fetch(&mut st, &self.pd1, 3)?),
            pd2: self.to_vecs::<3>(self.fetch(&mut st, &self.pd2, 3)?),
            tensor: self.to_vecs::<3>(self.fetch(&mut st, &self.tens, 3)?),
            k: self.to_vecs::<2>(self.fetch(&mut st, &self.kk, 2)?),
            dk: self.to_vecs::<4>(self.fetch(&mut st, &self.dk, 4)?),
        })
    }

    /// Reads the first `n` reals per vertex of `buf` into `staging`.
    fn fetch<'s>(&self, staging: &'s mut [u8], buf: &Buffer<u8>, n: usize) -> Result<&'s [u8]> {
        let out = &mut staging[..n * self.nv * self.real];
        self.gpu.read(buf, out)?;
        Ok(out)
    }

    /// Reads the results of the last full run, mapped back to the pose's
    /// own coordinates.
    pub fn read(&self) -> Result<CurvatureField> {
        self.read_placed(None)
    }

    /// [`CurvatureEstimator::read`] with vertex `v`'s values stored at index
    /// `place[v]` of the field (a permutation, e.g. back to an input order
    /// the mesh was renumbered from). Each buffer is converted, scaled back
    /// and placed as it arrives, in one pass into the field's own vectors:
    /// on a 2M-vertex mesh every extra copy of the field is 300 MB of fresh
    /// pages, whose first touch costs more than the conversion.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidArgument`] when `place` is not a permutation of the
    /// vertices; OpenCL errors of the reads.
    pub fn read_placed(&self, place: Option<&[u32]>) -> Result<CurvatureField> {
        let n = self.nv;
        check_place("read_placed", place, n)?;
        let at = |v: usize| place.map_or(v, |p| p[v] as usize);
        let s = self.norm.scale;
        let mut f = CurvatureField::zeros(n);
        let mut st = vec![0u8; 4 * n * self.real];
        // The scalings are those of `Normalization::unapply`, operation for
        // operation, so that the values are the same bits.
        for (v, x) in self
            .rows::<3>(self.fetch(&mut st, &self.nrm, 3)?)
            .enumerate()
        {
            f.normals[at(v)] = x;
        }
        for (v, [a]) in self
            .rows::<1>(self.fetch(&mut st, &self.area, 1)?)
            .enumerate()
        {
            f.areas[at(v)] = a * (s * s);
        }
        for (v, x) in self
            .rows::<3>(self.fetch(&mut st, &self.pd1, 3)?)
            .enumerate()
        {
            f.d1[at(v)] = x;
        }
        for (v, x) in self
            .rows::<3>(self.fetch(&mut st, &self.pd2, 3)?)
            .enumerate()
        {
            f.d2[at(v)] = x;
        }
        for (v, [a, b]) in self
            .rows::<2>(self.fetch(&mut st, &self.kk, 2)?)
            .enumerate()
        {
            let i = at(v);
            f.k1[i] = a / s;
            f.k2[i] = b / s;
        }
        if self.opts.dcurv {
            for (v, d) in self
                .rows::<4>(self.fetch(&mut st, &self.dk, 4)?)
                .enumerate()
            {
                f.dk[at(v)] = d.map(|d| d / (s * s));
            }
        }
        Ok(f)
    }

    /// The results of the last full run read where they lie, with no copy
    /// of the field: the device buffers mapped (on CPU runtimes the device's
    /// memory is the host's, so mapping copies nothing), each vertex's values
    /// converted and scaled back when asked for, with the same operations
    /// and so the same bits as [`CurvatureEstimator::read_placed`] with the
    /// same `place`. For writing a large field straight to a file: on a
    /// 2M-vertex mesh the field is 256 MB of fresh pages whose first touch
    /// costs more than the conversions.
    ///
    /// # Errors
    ///
    /// As [`CurvatureEstimator::read_placed`]; OpenCL errors of the maps.
    pub fn mapped(&self, place: Option<&[u32]>) -> Result<MappedField<'_>> {
        let n = self.nv;
        check_place("mapped", place, n)?;
        let device_of = place.map(|p| {
            let mut d = vec![0u32; n];
            for (v, &i) in p.iter().enumerate() {
                d[i as usize] = v as u32;
            }
            d
        });
        let map = |b, comps: usize| self.map_reals(b, comps);
        Ok(MappedField {
            n,
            precision: self.opts.precision,
            scale: self.norm.scale,
            device_of,
            nrm: map(&self.nrm, 3)?,
            area: map(&self.area, 1)?,
            pd1: map(&self.pd1, 3)?,
            pd2: map(&self.pd2, 3)?,
            kk: map(&self.kk, 2)?,
            dk: if self.opts.dcurv {
                Some(map(&self.dk, 4)?)
            } else {
                None
            },
        })
    }

    /// The line thresholds' scale `size` of the mesh (`positions`, `faces`:
    /// this estimator's topology, in world units) with this pose's
    /// curvature, read in place at the vertices rtsc samples
    /// ([`crate::mesh::feature_size::resolve`]).
    ///
    /// # Errors
    /// OpenCL errors of the maps.
    pub fn feature_size(
        &self,
        size: crate::spec::feature_lines::FeatureSize,
        positions: &[[f64; 3]],
        faces: &[[u32; 3]],
    ) -> Result<f64> {
        let field = self.mapped(None)?;
        let at = |i: usize| {
            let v = field.vertex(i);
            [v.k1, v.k2]
        };
        Ok(crate::mesh::feature_size::resolve(
            size,
            positions,
            faces,
            Some(&at),
        ))
    }

    /// Maps the first `comps` reals per vertex of `b` for reading.
    fn map_reals<'a>(&'a self, b: &'a Buffer<u8>, comps: usize) -> Result<Mapped<'a, u8>> {
        self.gpu.map_read(b, comps * self.nv * self.real)
    }
}

/// Refuses a `place` that is not a permutation of the `n` vertices.
fn check_place(what: &str, place: Option<&[u32]>, n: usize) -> Result<()> {
    if let Some(p) = place {
        let mut seen = vec![false; n];
        let permutation = p.len() == n
            && p.iter()
                .all(|&i| (i as usize) < n && !std::mem::replace(&mut seen[i as usize], true));
        if !permutation {
            return Err(Error::InvalidArgument(format!(
                "{what}: {} places are not a permutation of the {n} vertices",
                p.len()
            )));
        }
    }
    Ok(())
}

/// The results of a run read in place from the device buffers
/// ([`CurvatureEstimator::mapped`]); the buffers stay mapped, and the
/// estimator borrowed, while it lives.
pub struct MappedField<'a> {
    n: usize,
    precision: Precision,
    scale: f64,
    /// For each vertex of the field's order, the device's vertex.
    device_of: Option<Vec<u32>>,
    nrm: Mapped<'a, u8>,
    area: Mapped<'a, u8>,
    pd1: Mapped<'a, u8>,
    pd2: Mapped<'a, u8>,
    kk: Mapped<'a, u8>,
    dk: Option<Mapped<'a, u8>>,
}

impl MappedField<'_> {
    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True when there are no vertices.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The values of vertex `i` (below [`MappedField::len`]) in the field's
    /// order, in the pose's own coordinates: the scalings of
    /// [`CurvatureEstimator::read_placed`], operation for operation.
    pub fn vertex(&self, i: usize) -> VertexCurvature {
        let v = self.device_of.as_ref().map_or(i, |d| d[i] as usize);
        match self.precision {
            Precision::F32 => self.vertex_as::<f32>(v),
            Precision::F64 => self.vertex_as::<f64>(v),
        }
    }

    /// [`MappedField::vertex`] of device vertex `v`, the buffers holding
    /// reals of type `R`: each buffer's slice for the vertex cut once, its
    /// reals read unaligned (the maps' pointers are only known to be byte
    /// aligned), so a vertex costs a few bounds checks, not one per value.
    #[inline]
    fn vertex_as<R: bytemuck::Pod + Into<f64>>(&self, v: usize) -> VertexCurvature {
        fn reals<R: bytemuck::Pod + Into<f64>, const N: usize>(b: &[u8], v: usize) -> [f64; N] {
            let w = std::mem::size_of::<R>();
            let b = &b[N * w * v..N * w * (v + 1)];
            std::array::from_fn(|c| {
                bytemuck::pod_read_unaligned::<R>(&b[c * w..(c + 1) * w]).into()
            })
        }
        let s = self.scale;
        let [area] = reals::<R, 1>(&self.area, v);
        let [k1, k2] = reals::<R, 2>(&self.kk, v);
        VertexCurvature {
            normal: reals::<R, 3>(&self.nrm, v),
            area: area * (s * s),
            k1: k1 / s,
            k2: k2 / s,
            d1: reals::<R, 3>(&self.pd1, v),
            d2: reals::<R, 3>(&self.pd2, v),
            dk: self
                .dk
                .as_ref()
                .map_or([0.0; 4], |b| reals::<R, 4>(b, v).map(|d| d / (s * s))),
        }
    }
}
