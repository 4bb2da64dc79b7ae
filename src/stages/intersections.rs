//! Host wiring of `kernels/intersections.cl`: the curves where faces of a
//! mesh cross each other (Blender Line Art's intersection lines), one
//! segment per crossing face pair, found over the `bvh` family's tree.
//! Types and options: [`crate::spec::intersections`]; CPU twin:
//! [`crate::cpu::intersections`] (same pairs, same f32 arithmetic: equal
//! bits after the canonical sort); method and pair rules there.
//!
//! [`Intersections::new`] uploads what depends on the topology only (the
//! optional per-face groups) and allocates the output. [`Intersections::find`]
//! reads the tree, the positions and the faces from a built (or refitted)
//! [`Bvh`] of the same mesh (nothing is uploaded per call) and launches
//! `isect_find`, one work-item per leaf. Segments are appended through an
//! atomic counter that counts every segment found, also past the buffer's
//! end, where nothing is written: when the count exceeds the room, the
//! buffer grows to the count and the search runs once more. The segments
//! are read back and sorted by face pair ([`sort_canonical`]).
//!
//! Buffers: groups `u32[F]` (one element without groups), out
//! `Segment[cap]` (from [`intersections_estimate`], grown as needed),
//! counters `u32[4]`: segments found, pairs tested (saturating), stack
//! overflows (none can happen: the tree is at most 63 deep), and a flag set
//! when the segment counter wrapped past `u32::MAX` (an error).

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::bvh::{MAX_FACES, STACK_DEPTH};
use crate::spec::intersections::{
    IntersectionOptions, IntersectionStats, IsectKernel, MAX_SEGMENTS, Segment,
    intersections_estimate, sort_canonical,
};
use crate::spec::timing::{Step, Timing};
use crate::stages::bvh::Bvh;
use crate::stages::kernel_files;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use std::sync::Arc;
use std::time::Instant;

/// The build options of `kernels/intersections.cl`: the traversal stack of
/// the bvh family's queries ([`STACK_DEPTH`]).
pub fn build_options() -> String {
    format!("-DISECT_STACK={STACK_DEPTH}")
}

/// The crossings of one mesh's faces on the device.
pub struct Intersections {
    gpu: Arc<Gpu>,
    kernel: Kernel,
    n_faces: usize,
    use_groups: bool,
    groups: Buffer<u32>,
    out: Buffer<Segment>,
    cap: usize,
    counters: Buffer<u32>,
    timing: Timing,
}

impl Intersections {
    /// Checks the options against a mesh of `n_faces` faces, uploads the
    /// groups, and allocates room for [`intersections_estimate`] segments.
    pub fn new(gpu: Arc<Gpu>, n_faces: usize, opts: &IntersectionOptions) -> Result<Intersections> {
        Intersections::with_capacity(gpu, n_faces, opts, intersections_estimate(n_faces))
    }

    /// [`Intersections::new`] with room for `cap` segments at first (at
    /// least 1): tests exercise the grow-and-rerun path with a small one.
    pub fn with_capacity(
        gpu: Arc<Gpu>,
        n_faces: usize,
        opts: &IntersectionOptions,
        cap: usize,
    ) -> Result<Intersections> {
        if n_faces > MAX_FACES {
            return Err(Error::InvalidArgument(format!(
                "intersections: {n_faces} faces, the bvh tree holds at most {MAX_FACES}"
            )));
        }
        opts.check("intersections", n_faces)?;
        let program = gpu.program(&kernel_files::INTERSECTIONS, &build_options())?;
        let kernel = gpu.entry(&program, IsectKernel::Find)?;
        let cap = cap.clamp(1, MAX_SEGMENTS);
        let mut groups = gpu.buffer::<u32>(n_faces.max(1))?;
        if let Some(g) = &opts.groups {
            gpu.write(&mut groups, g)?;
        }
        Ok(Intersections {
            kernel,
            n_faces,
            use_groups: opts.groups.is_some(),
            groups,
            out: gpu.buffer(cap)?,
            cap,
            counters: gpu.buffer(4)?,
            timing: Timing::default(),
            gpu,
        })
    }

    /// Faces of the mesh.
    pub fn n_faces(&self) -> usize {
        self.n_faces
    }

    /// Segments the output holds now (grown by searches that found more).
    pub fn capacity(&self) -> usize {
        self.cap
    }

    /// Every crossing of the faces of `bvh`'s mesh at the positions of its
    /// last [`Bvh::build`] or [`Bvh::refit`], by face pair, and the
    /// search's stats. Errors when the tree is not built, lives on another
    /// device or holds another number of faces.
    pub fn find(&mut self, bvh: &Bvh) -> Result<(Vec<Segment>, IntersectionStats)> {
        let t0 = Instant::now();
        if bvh.n_faces() != self.n_faces {
            return Err(Error::InvalidArgument(format!(
                "intersections: the bvh holds {} faces, this search was made for {}",
                bvh.n_faces(),
                self.n_faces
            )));
        }
        let tree = bvh.tree_args(&self.gpu)?;
        self.timing = Timing::default();
        let mut stats = IntersectionStats::default();
        if self.n_faces == 0 {
            return Ok((Vec::new(), stats));
        }
        let mut counts = self.run(&tree)?;
        if counts[0] as usize > self.cap {
            // the buffer first: a refused allocation leaves the old room
            self.out = self.gpu.buffer(counts[0] as usize)?;
            self.cap = counts[0] as usize;
            stats.reran = true;
            counts = self.run(&tree)?;
        }
        let found = counts[0] as usize;
        if found > self.cap {
            return Err(Error::DeviceResult {
                what: "intersection count".into(),
                detail: format!(
                    "a rerun with room for {} segments found {found}; nothing was written past \
                     the buffer",
                    self.cap
                ),
            });
        }
        let mut segments = vec![Segment::default(); found];
        self.gpu.read(&self.out, &mut segments)?;
        sort_canonical(&mut segments);
        stats.pairs_tested = counts[1];
        stats.segments = found;
        self.timing.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok((segments, stats))
    }

    /// One launch of `isect_find` with room for `self.cap` segments: the
    /// counters (found, tested); errors on a stack overflow or a wrapped
    /// segment counter.
    fn run(&mut self, tree: &[Arg; 6]) -> Result<[u32; 2]> {
        self.gpu.zero(&mut self.counters, 4)?;
        let [pos, faces, faces_sorted, nodes, node_boxes, leaf_boxes] = *tree;
        let args = [
            Arg::U32(self.n_faces as u32),
            pos,
            faces,
            faces_sorted,
            nodes,
            node_boxes,
            leaf_boxes,
            Arg::U32(u32::from(self.use_groups)),
            buf(&self.groups),
            Arg::U32(self.cap as u32),
            buf(&self.out),
            buf(&self.counters),
        ];
        if let Some(ev) = launch(&self.gpu, &self.kernel, self.n_faces, &args)? {
            ev.wait().map_err(|e| Error::cl("clWaitForEvents", e))?;
            self.timing.add(Step::IsectFind, event_ms(&ev));
        }
        let mut c = [0u32; 4];
        self.gpu.read(&self.counters, &mut c)?;
        if c[3] != 0 {
            return Err(Error::InvalidArgument(format!(
                "intersections: more than {MAX_SEGMENTS} crossing face pairs; a search counts \
                 at most that many (split the mesh or give groups)"
            )));
        }
        if c[2] != 0 {
            return Err(Error::DeviceResult {
                what: "intersection traversal".into(),
                detail: format!(
                    "the stack of {STACK_DEPTH} entries overflowed {} times (a Karras tree is \
                     at most 63 deep)",
                    c[2]
                ),
            });
        }
        Ok([c[0], c[1]])
    }

    /// Kernel steps and wall time of the last [`Intersections::find`].
    pub fn timing(&self) -> &Timing {
        &self.timing
    }
}

/// One call: builds the tree of `faces` at `positions` ([`Bvh`]) and finds
/// every crossing, by face pair (for a mesh seen once; keep a [`Bvh`] and
/// an [`Intersections`] to search pose after pose).
pub fn find_once(
    gpu: Arc<Gpu>,
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    opts: &IntersectionOptions,
) -> Result<(Vec<Segment>, IntersectionStats)> {
    let mut bvh = Bvh::new(gpu.clone(), positions.len(), faces)?;
    bvh.build(positions)?;
    Intersections::new(gpu, faces.len(), opts)?.find(&bvh)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `IsectSegment` in the kernel has the spec's layout: a probe kernel
    /// reports `sizeof` and every `offsetof`.
    #[test]
    fn structs_match_the_kernel() {
        let fields = crate::spec::intersections::field_offsets();
        crate::gpu::check_layout(
            &kernel_files::INTERSECTIONS,
            &build_options(),
            IsectKernel::ProbeLayout,
            &fields,
        );
    }
}
