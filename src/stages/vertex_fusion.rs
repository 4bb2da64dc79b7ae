//! Host wiring of `kernels/vertex_fusion.cl`: the marching-cubes soup (one
//! key per vertex, written by `mc_triangles`) becomes an indexed mesh with
//! shared vertices, entirely on the device (Griffin et al. 2012, §3.4):
//! radix sort of (key, soup index) → `fuse_index` → `fuse_triangles` →
//! twin cancellation (`fuse_candidates`, sort, `fuse_cancel`) → `fuse_mark` →
//! scans → `fuse_compact_vertices`, `fuse_compact_faces`.
//! CPU twin: [`crate::cpu::vertex_fusion`]; shared variant, counts and
//! bounds: [`crate::spec::vertex_fusion`].

use crate::error::Result;
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::timing::{Step, Timing};
use crate::spec::vertex_fusion::FuseKernel;
use crate::spec::vertex_fusion::{Fusion, soup_triangles};
use crate::stages::kernel_files;
use crate::stages::radix_sort::RadixSort;
use crate::stages::scan::Scan;
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use std::sync::Arc;

use crate::spec::vertex_fusion::FusionCounts;

/// A growable device buffer.
pub(crate) struct Grow<T> {
    pub(crate) buf: Buffer<T>,
    pub(crate) len: usize,
}

impl<T> Grow<T> {
    pub(crate) fn new(gpu: &Gpu) -> Result<Self> {
        Ok(Grow {
            buf: gpu.buffer::<T>(1)?,
            len: 1,
        })
    }
    /// Makes room for `n` elements (grows by 1/8 extra to avoid re-allocating
    /// for every slightly larger frame, but never past the device's largest
    /// buffer, so that what fits is not refused for the slack).
    pub(crate) fn reserve(&mut self, gpu: &Gpu, n: usize) -> Result<()> {
        if n > self.len {
            let most = gpu.info.max_alloc / std::mem::size_of::<T>().max(1) as u64;
            let len = (n + n / 8).min(usize::try_from(most).unwrap_or(usize::MAX).max(n));
            self.buf = gpu.buffer::<T>(len)?;
            self.len = len;
        }
        Ok(())
    }
    pub(crate) fn bytes(&self) -> u64 {
        (self.len * std::mem::size_of::<T>()) as u64
    }
}

/// Fuses a soup on the device; holds its kernels, the scan and sort
/// primitives and its scratch and output buffers between calls.
pub struct Fuser {
    gpu: Arc<Gpu>,
    sort: RadixSort,
    scan: Scan,
    index: Kernel,
    clear: Kernel,
    triangles: Kernel,
    candidates: Kernel,
    cancel: Kernel,
    mark: Kernel,
    compact_vertices: Kernel,
    compact_faces: Kernel,
    rep: Grow<u32>,
    referenced: Grow<u32>,
    vert_id: Grow<u32>,
    keep: Grow<u32>,
    face_off: Grow<u32>,
    cand: Grow<u32>,
    cand_off: Grow<u32>,
    ckeys: Grow<u32>,
    cvals: Grow<u32>,
    /// Unique positions (index space), 3 floats per vertex.
    pub(crate) out_pos: Grow<f32>,
    /// Faces, 3 indices each.
    pub(crate) out_faces: Grow<u32>,
}

/// Build options of `kernels/vertex_fusion.cl` and `kernels/marching_cubes.cl`:
/// an optional hash mask that forces collisions (tests). Correctly rounded
/// division, so that positions match the CPU twin bit for bit, comes with
/// every strict build ([`crate::gpu::FpMode`]).
pub fn build_options(collide_mask: Option<u32>) -> String {
    collide_mask
        .map(|m| format!("-DSC_HASH_COLLIDE={m:#x}u"))
        .unwrap_or_default()
}

impl Fuser {
    /// Builds the kernels (and those of the radix sort and scan).
    pub fn new(gpu: Arc<Gpu>) -> Result<Self> {
        let file = kernel_files::VERTEX_FUSION;
        let p = gpu.program(&file, &build_options(None))?;
        Ok(Fuser {
            sort: RadixSort::new(gpu.clone())?,
            scan: Scan::new(gpu.clone())?,
            index: gpu.entry(&p, FuseKernel::Index)?,
            clear: gpu.entry(&p, FuseKernel::Clear)?,
            triangles: gpu.entry(&p, FuseKernel::Triangles)?,
            candidates: gpu.entry(&p, FuseKernel::Candidates)?,
            cancel: gpu.entry(&p, FuseKernel::Cancel)?,
            mark: gpu.entry(&p, FuseKernel::Mark)?,
            compact_vertices: gpu.entry(&p, FuseKernel::CompactVertices)?,
            compact_faces: gpu.entry(&p, FuseKernel::CompactFaces)?,
            rep: Grow::new(&gpu)?,
            referenced: Grow::new(&gpu)?,
            vert_id: Grow::new(&gpu)?,
            keep: Grow::new(&gpu)?,
            face_off: Grow::new(&gpu)?,
            cand: Grow::new(&gpu)?,
            cand_off: Grow::new(&gpu)?,
            ckeys: Grow::new(&gpu)?,
            cvals: Grow::new(&gpu)?,
            out_pos: Grow::new(&gpu)?,
            out_faces: Grow::new(&gpu)?,
            gpu,
        })
    }

    /// Device bytes held (scratch, outputs, the sort's scratch).
    pub fn device_bytes(&self) -> u64 {
        self.rep.bytes()
            + self.referenced.bytes()
            + self.vert_id.bytes()
            + self.keep.bytes()
            + self.face_off.bytes()
            + self.cand.bytes()
            + self.cand_off.bytes()
            + self.ckeys.bytes()
            + self.cvals.bytes()
            + self.out_pos.bytes()
            + self.out_faces.bytes()
            + self.sort.scratch_bytes()
            + self.scan.scratch_bytes()
    }

    /// Bytes [`Fuser::fuse`] needs for `n` soup vertices (before outputs),
    /// for the caller's memory check: [`crate::spec::vertex_fusion::device_bytes_bound`].
    pub fn bytes_bound(n: usize) -> u64 {
        crate::spec::vertex_fusion::device_bytes_bound(n)
    }

    /// Fuses `n` soup vertices: `keys`/`idx` (sorted in place here) and
    /// `pos` (3n floats), keys of `key_bits` bits. `fusion` must be `Hash`
    /// or `Edge` (the soup itself is the `None` variant).
    pub fn fuse(
        &mut self,
        fusion: Fusion,
        keys: &mut Buffer<u32>,
        idx: &mut Buffer<u32>,
        pos: &Buffer<f32>,
        n: usize,
        key_bits: u32,
    ) -> Result<(FusionCounts, Timing)> {
        let g = self.gpu.clone();
        let mut t = Timing::default();
        let nt = soup_triangles(n);
        if n == 0 {
            return Ok((FusionCounts::default(), t));
        }
        self.sort.sort_pairs(keys, idx, n, key_bits)?;
        t.add(Step::RadixSortPairs, self.sort.last_ms());
        self.rep.reserve(&g, n)?;
        let n32 = n as u32;
        let compare = u32::from(fusion == Fusion::Hash);
        let e_index = launch(
            &g,
            &self.index,
            n,
            &[
                Arg::U32(n32),
                buf(keys),
                buf(idx),
                buf(pos),
                Arg::U32(compare),
                buf(&self.rep.buf),
            ],
        )?;
        // The event's time is read by `finish_inner` once the queue is done.
        let (counts, ft) = self.finish_inner(None, pos, n, nt, e_index)?;
        t.extend(&ft);
        Ok((counts, t))
    }

    /// How many of the `nv` vertices the `nt` triangles of `faces` use
    /// (`fuse_clear`, `fuse_mark` with every triangle kept, their sum), with
    /// the kernel times: direct numbering's check that dropping triangles
    /// left no vertex unused. Leaves the marks for
    /// [`Fuser::compact_referenced`].
    pub(crate) fn count_referenced(
        &mut self,
        faces: &Buffer<u32>,
        nv: usize,
        nt: usize,
    ) -> Result<(usize, Timing)> {
        let g = self.gpu.clone();
        let mut t = Timing::default();
        if nt == 0 {
            return Ok((0, t));
        }
        self.referenced.reserve(&g, nv)?;
        self.keep.reserve(&g, nt)?;
        g.fill(&mut self.keep.buf, &[1u32], nt)?;
        let e_clear = launch(
            &g,
            &self.clear,
            nv,
            &[Arg::U32(nv as u32), buf(&self.referenced.buf)],
        )?;
        let e_mark = launch(
            &g,
            &self.mark,
            nt,
            &[
                Arg::U32(nt as u32),
                Arg::U32(nv as u32),
                buf(faces),
                buf(&self.keep.buf),
                buf(&self.referenced.buf),
            ],
        )?;
        let used = self.scan.sum(&self.referenced.buf, nv)? as usize;
        // `fuse_clear` is counted in the marking it prepares.
        for e in [&e_clear, &e_mark].into_iter().flatten() {
            t.add(Step::FuseMark, event_ms(e));
        }
        t.add(Step::ScanExclusive, self.scan.last_ms());
        Ok((used, t))
    }

    /// After [`Fuser::count_referenced`] on the same `faces`: every triangle
    /// kept, the vertices some triangle uses compacted in index order into
    /// [`Fuser::out_pos`] and the faces renumbered into
    /// [`Fuser::out_faces`] (`fuse_compact_vertices`, `fuse_compact_faces`).
    /// The same result as [`Fuser::finish`] where no triangle repeats a
    /// corner and none has an opposite twin, without their search.
    pub(crate) fn compact_referenced(
        &mut self,
        faces: &Buffer<u32>,
        pos: &Buffer<f32>,
        nv: usize,
        nt: usize,
        used: usize,
    ) -> Result<(FusionCounts, Timing)> {
        let g = self.gpu.clone();
        let mut t = Timing::default();
        if nt == 0 {
            return Ok((FusionCounts::default(), t));
        }
        // The used vertices' new indices (the check only summed the marks).
        self.vert_id.reserve(&g, nv)?;
        self.scan
            .exclusive(&self.referenced.buf, &self.vert_id.buf, nv)?;
        t.add(Step::ScanExclusive, self.scan.last_ms());
        self.face_off.reserve(&g, nt)?;
        // Every triangle is kept: the face offsets are 0, 1, 2, ... (nt
        // itself the total, so no wait for it).
        let e_scan = self.scan.enqueue(&self.keep.buf, &self.face_off.buf, nt)?;
        self.out_pos.reserve(&g, 3 * used)?;
        self.out_faces.reserve(&g, 3 * nt)?;
        self.compact(faces, pos, nv, nt, e_scan, &mut t)?;
        Ok((
            FusionCounts {
                vertices: used,
                faces: nt,
                dropped: 0,
            },
            t,
        ))
    }

    /// The steps after `fuse_index`, shared with direct numbering
    /// ([`crate::stages::marching_cubes`]): `rep` holds `nt` triangles (3
    /// indices each) into `pos` (`nv` vertex slots, 3 floats each).
    /// Triangles whose corners repeat are dropped, opposite twins in grid
    /// planes cancelled, and the vertices still used compacted in index
    /// order into [`Fuser::out_pos`] / [`Fuser::out_faces`].
    pub(crate) fn finish(
        &mut self,
        rep: &Buffer<u32>,
        pos: &Buffer<f32>,
        nv: usize,
        nt: usize,
    ) -> Result<(FusionCounts, Timing)> {
        self.finish_inner(Some(rep), pos, nv, nt, None)
    }

    /// [`Fuser::finish`] on `rep` (the fuser's own buffer where `None`),
    /// after `fuse_index`'s launch `e_index` where it ran.
    fn finish_inner(
        &mut self,
        rep: Option<&Buffer<u32>>,
        pos: &Buffer<f32>,
        n: usize,
        nt: usize,
        e_index: Option<Event>,
    ) -> Result<(FusionCounts, Timing)> {
        let g = self.gpu.clone();
        let mut t = Timing::default();
        if nt == 0 {
            return Ok((FusionCounts::default(), t));
        }
        self.reserve_finish(n, nt)?;
        let r = buf(rep.unwrap_or(&self.rep.buf));
        let mut times = FinishTimes {
            e_index,
            ..Default::default()
        };
        (times.e_clear, times.e_tri) = self.fuse_triangles(r, pos, n, nt)?;
        let n_cand = self
            .scan
            .exclusive(&self.cand.buf, &self.cand_off.buf, nt)? as usize;
        debug_assert!(n_cand <= nt);
        // Steps in execution order; the kernel events are read once done.
        times.cand_scan = self.scan.last_ms();
        if n_cand > 0 {
            times.cancel = self.cancel_twins(r, nt, n_cand)?;
        }
        let (faces, vertices) = self.fuse_mark(r, n, nt, &mut times)?;
        times.add_to(&mut t);
        // Sized from the scans, within the bounds the memory check assumed.
        debug_assert!(vertices <= n && faces <= nt);
        self.out_pos.reserve(&g, 3 * vertices)?;
        self.out_faces.reserve(&g, 3 * faces)?;
        let rep = rep.unwrap_or(&self.rep.buf);
        self.compact(rep, pos, n, nt, Vec::new(), &mut t)?;
        Ok((
            FusionCounts {
                vertices,
                faces,
                dropped: nt - faces,
            },
            t,
        ))
    }

    /// The scratch of [`Fuser::finish`] for `n` vertex slots and `nt`
    /// triangles.
    fn reserve_finish(&mut self, n: usize, nt: usize) -> Result<()> {
        let g = self.gpu.clone();
        for b in [&mut self.referenced, &mut self.vert_id] {
            b.reserve(&g, n)?;
        }
        for b in [
            &mut self.keep,
            &mut self.face_off,
            &mut self.cand,
            &mut self.cand_off,
        ] {
            b.reserve(&g, nt)?;
        }
        Ok(())
    }

    /// `fuse_clear` and `fuse_triangles`: the marks of the `n` slots
    /// cleared; of the `nt` triangles of `rep` (positions `pos`), those
    /// whose corners repeat dropped and the twin candidates flagged.
    fn fuse_triangles(
        &mut self,
        rep: Arg,
        pos: &Buffer<f32>,
        n: usize,
        nt: usize,
    ) -> Result<(Option<Event>, Option<Event>)> {
        let g = &*self.gpu;
        let n32 = n as u32;
        let e_clear = launch(
            g,
            &self.clear,
            n,
            &[Arg::U32(n32), buf(&self.referenced.buf)],
        )?;
        let e_tri = launch(
            g,
            &self.triangles,
            nt,
            &[
                Arg::U32(nt as u32),
                Arg::U32(n as u32),
                rep,
                buf(pos),
                buf(&self.keep.buf),
                buf(&self.cand.buf),
            ],
        )?;
        Ok((e_clear, e_tri))
    }

    /// `fuse_candidates`, their sort and `fuse_cancel`: the `n_cand`
    /// candidates among the `nt` triangles of `rep` listed by key, and
    /// opposite twins cancelled; waits, and returns the steps' times.
    fn cancel_twins(&mut self, rep: Arg, nt: usize, n_cand: usize) -> Result<Timing> {
        let g = self.gpu.clone();
        let mut cancel = Timing::default();
        self.ckeys.reserve(&g, n_cand)?;
        self.cvals.reserve(&g, n_cand)?;
        let e = launch(
            &g,
            &self.candidates,
            nt,
            &[
                Arg::U32(nt as u32),
                rep,
                buf(&self.cand.buf),
                buf(&self.cand_off.buf),
                buf(&self.ckeys.buf),
                buf(&self.cvals.buf),
            ],
        )?;
        self.sort
            .sort_pairs(&mut self.ckeys.buf, &mut self.cvals.buf, n_cand, 32)?;
        let sort_ms = self.sort.last_ms();
        let e2 = launch(
            &g,
            &self.cancel,
            n_cand,
            &[
                Arg::U32(n_cand as u32),
                buf(&self.ckeys.buf),
                buf(&self.cvals.buf),
                rep,
                buf(&self.keep.buf),
            ],
        )?;
        g.finish()?;
        if let Some(e) = &e {
            cancel.add(Step::FuseCandidates, event_ms(e));
        }
        cancel.add(Step::RadixSortPairs, sort_ms);
        if let Some(e) = &e2 {
            cancel.add(Step::FuseCancel, event_ms(e));
        }
        Ok(cancel)
    }

    /// `fuse_mark` and the scans of the keep flags and the marks: the slots
    /// the kept triangles of `rep` use; returns (faces, vertices) kept.
    fn fuse_mark(
        &mut self,
        rep: Arg,
        n: usize,
        nt: usize,
        times: &mut FinishTimes,
    ) -> Result<(usize, usize)> {
        times.e_mark = launch(
            &self.gpu,
            &self.mark,
            nt,
            &[
                Arg::U32(nt as u32),
                Arg::U32(n as u32),
                rep,
                buf(&self.keep.buf),
                buf(&self.referenced.buf),
            ],
        )?;
        let faces = self
            .scan
            .exclusive(&self.keep.buf, &self.face_off.buf, nt)? as usize;
        times.face_scan = self.scan.last_ms();
        let vertices = self
            .scan
            .exclusive(&self.referenced.buf, &self.vert_id.buf, n)? as usize;
        times.vertex_scan = self.scan.last_ms();
        Ok((faces, vertices))
    }

    /// The last two steps of [`Fuser::finish`] and
    /// [`Fuser::compact_referenced`]: the marked vertices of `pos` (`n`
    /// slots) into [`Fuser::out_pos`] and the kept triangles of
    /// `rep` (`nt`) renumbered into [`Fuser::out_faces`], from the marks,
    /// new indices, keep flags and face offsets already on the device (the
    /// outputs reserved by the caller); waits, then adds to `t` the time of
    /// `scans` (scans enqueued for this step and not yet counted) and of
    /// the two kernels.
    fn compact(
        &self,
        rep: &Buffer<u32>,
        pos: &Buffer<f32>,
        n: usize,
        nt: usize,
        scans: Vec<opencl3::event::Event>,
        t: &mut Timing,
    ) -> Result<()> {
        let g = &*self.gpu;
        let e_v = launch(
            g,
            &self.compact_vertices,
            n,
            &[
                Arg::U32(n as u32),
                buf(&self.referenced.buf),
                buf(&self.vert_id.buf),
                buf(pos),
                buf(&self.out_pos.buf),
            ],
        )?;
        let e_f = launch(
            g,
            &self.compact_faces,
            nt,
            &[
                Arg::U32(nt as u32),
                Arg::U32(n as u32),
                buf(rep),
                buf(&self.keep.buf),
                buf(&self.face_off.buf),
                buf(&self.vert_id.buf),
                buf(&self.out_faces.buf),
            ],
        )?;
        g.finish()?;
        if !scans.is_empty() {
            t.add(Step::ScanExclusive, scans.iter().map(event_ms).sum());
        }
        if let Some(e) = &e_v {
            t.add(Step::FuseCompactVertices, event_ms(e));
        }
        if let Some(e) = &e_f {
            t.add(Step::FuseCompactFaces, event_ms(e));
        }
        Ok(())
    }
}

/// The launches and scan times of [`Fuser::finish`], added to its timing
/// in execution order once the queue is done.
#[derive(Default)]
struct FinishTimes {
    e_index: Option<Event>,
    e_clear: Option<Event>,
    e_tri: Option<Event>,
    cand_scan: f64,
    cancel: Timing,
    e_mark: Option<Event>,
    face_scan: f64,
    vertex_scan: f64,
}

impl FinishTimes {
    /// Adds the steps to `t`, in the order they ran.
    fn add_to(&self, t: &mut Timing) {
        if let Some(e) = &self.e_index {
            t.add(Step::FuseIndex, event_ms(e));
        }
        // `fuse_clear` is counted in the triangles step it prepares.
        for e in [&self.e_clear, &self.e_tri].into_iter().flatten() {
            t.add(Step::FuseTriangles, event_ms(e));
        }
        t.add(Step::ScanExclusive, self.cand_scan);
        t.extend(&self.cancel);
        if let Some(e) = &self.e_mark {
            t.add(Step::FuseMark, event_ms(e));
        }
        t.add(Step::ScanExclusive, self.face_scan);
        t.add(Step::ScanExclusive, self.vertex_scan);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Faces from a broken producer (a corner past the vertices) are never
    /// followed as indices (no write or read out of bounds): the corner
    /// comes out of range, for the caller's check of the faces to report,
    /// through the whole clean-up and through the compaction alone.
    #[test]
    fn a_corner_past_the_vertices_comes_out_of_range_and_is_not_followed() {
        let gpu = crate::gpu::test_gpu();
        let pos_host: [f32; 12] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let mut pos = gpu.buffer::<f32>(12).unwrap();
        gpu.write(&mut pos, &pos_host).unwrap();
        for bad in [1000u32, 4, u32::MAX] {
            let faces_host = [0, 1, 2, 0, bad, 3, 2, 1, 3];
            let mut faces = gpu.buffer::<u32>(9).unwrap();
            gpu.write(&mut faces, &faces_host).unwrap();
            let mut f = Fuser::new(gpu.clone()).unwrap();
            let (c, _) = f.finish(&faces, &pos, 4, 3).unwrap();
            assert_eq!(c.faces, 3, "corner {bad}");
            let mut out = vec![0u32; 9];
            gpu.read(&f.out_faces.buf, &mut out).unwrap();
            assert_eq!(out[4], u32::MAX, "corner {bad}: {out:?}");
            assert!(
                out.iter().enumerate().all(|(i, &v)| i == 4 || v < 4),
                "{out:?}"
            );
            let (used, _) = f.count_referenced(&faces, 4, 3).unwrap();
            assert_eq!(used, 4, "corner {bad}");
            let (c, _) = f.compact_referenced(&faces, &pos, 4, 3, used).unwrap();
            assert_eq!(c.faces, 3);
            gpu.read(&f.out_faces.buf, &mut out).unwrap();
            assert_eq!(out[4], u32::MAX, "corner {bad}: {out:?}");
        }
    }
}
