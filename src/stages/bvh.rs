//! Host wiring of `kernels/bvh.cl`: a linear BVH over a mesh's faces
//! (Karras 2012), built once from the first pose and refitted per pose, and
//! segment occlusion queries over it. Layout and constants:
//! [`crate::spec::bvh`]; CPU twin: [`crate::cpu::bvh`] (same steps, same
//! tree, same boxes bit for bit).
//!
//! [`Bvh::new`] uploads the faces (topology once). [`Bvh::build`] (first
//! pose): `bvh_morton` (codes of the face centroids in the box of the
//! positions), the project's [`RadixSort`] of the (code, face) pairs (30-bit
//! keys, stable: ties keep face order), `bvh_build` (internal nodes and
//! parents), then [`Bvh::refit`]. Morton codes depend on positions, but the
//! tree is kept: a later pose only reruns `bvh_refit` (leaf boxes and
//! internal boxes bottom-up, one visit counter per node, zeroed first, and
//! each node's two children's boxes padded for the queries), so
//! the tree stays valid (boxes contain their subtrees) but may loosen when a
//! pose moves far from the first.
//!
//! Buffers ([`bvh_bound`]): positions `f32[3·V]`, faces `u32[3·F]`, keys and
//! faces_sorted `u32[F]`, nodes `BvhNode[F−1]`, leaf_parent `u32[F]`,
//! boxes `BvhBox[F−1]` and `BvhBox[F]`, padded child boxes `BvhBox[2(F−1)]`,
//! visits `u32[F−1]`, counters `u32[1]`
//! (stack overflows of the last query batch). An empty face list is an empty
//! tree: nothing is launched and every query is visible.

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::bvh::{
    BOX_PAD, BvhBox, BvhKernel, BvhNode, BvhQuery, EDGE_EPS, END_EPS, MORTON_BITS, MortonFrame,
    NONE, STACK_DEPTH, bvh_bound,
};
use crate::spec::bvh::{Tree, check_faces, check_positions};
use crate::spec::timing::{Step, Timing};
use crate::stages::kernel_files;
use crate::stages::radix_sort::RadixSort;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use std::sync::Arc;

/// The build options of `kernels/bvh.cl`: the spec's constants.
pub fn build_options() -> String {
    build_options_with(STACK_DEPTH)
}

/// [`build_options`] with a traversal stack of `stack` entries (tests
/// exercise the overflow path with a short one).
pub fn build_options_with(stack: usize) -> String {
    format!(
        "-DBVH_STACK={stack} -DBVH_EDGE_EPS={EDGE_EPS:e}f -DBVH_END_EPS={END_EPS:e}f \
         -DBVH_BOX_PAD={BOX_PAD:e}f"
    )
}

/// A BVH of one mesh's faces on the device.
pub struct Bvh {
    gpu: Arc<Gpu>,
    kernels: [Kernel; 4],
    sort: RadixSort,
    n_vertices: usize,
    faces_host: Vec<[u32; 3]>,
    pos: Buffer<f32>,
    faces: Buffer<u32>,
    keys: Buffer<u32>,
    faces_sorted: Buffer<u32>,
    nodes: Buffer<BvhNode>,
    leaf_parent: Buffer<u32>,
    node_boxes: Buffer<BvhBox>,
    leaf_boxes: Buffer<BvhBox>,
    child_boxes: Buffer<BvhBox>,
    visits: Buffer<u32>,
    counters: Buffer<u32>,
    built: bool,
    timing: Timing,
}

impl Bvh {
    /// Checks and uploads the faces of a mesh of `n_vertices` vertices;
    /// allocates the tree. Nothing is built until [`Bvh::build`].
    pub fn new(gpu: Arc<Gpu>, n_vertices: usize, faces: &[[u32; 3]]) -> Result<Bvh> {
        Bvh::with_stack(gpu, n_vertices, faces, STACK_DEPTH)
    }

    /// [`Bvh::new`] with a query stack of `stack` entries (1 to
    /// [`STACK_DEPTH`]) instead of [`STACK_DEPTH`]: for tests of the overflow
    /// path ([`Tree::occluded_with_stack`] is its twin).
    pub fn with_stack(
        gpu: Arc<Gpu>,
        n_vertices: usize,
        faces: &[[u32; 3]],
        stack: usize,
    ) -> Result<Bvh> {
        if !(1..=STACK_DEPTH).contains(&stack) {
            return Err(Error::InvalidArgument(format!(
                "bvh: a query stack of {stack} entries, 1 to {STACK_DEPTH} expected"
            )));
        }
        check_faces("bvh mesh", n_vertices, faces)?;
        let program = gpu.program(&kernel_files::BVH, &build_options_with(stack))?;
        let entry = |k| gpu.entry(&program, k);
        let kernels = [
            entry(BvhKernel::Morton)?,
            entry(BvhKernel::Build)?,
            entry(BvhKernel::Refit)?,
            entry(BvhKernel::Occluded)?,
        ];
        let (leaves, internal) = bvh_bound(faces.len());
        let (l1, i1) = (leaves.max(1), internal.max(1));
        let mut face_buf = gpu.buffer::<u32>(3 * l1)?;
        if !faces.is_empty() {
            gpu.write(&mut face_buf, faces.as_flattened())?;
        }
        Ok(Bvh {
            sort: RadixSort::new(gpu.clone())?,
            kernels,
            n_vertices,
            faces_host: faces.to_vec(),
            pos: gpu.buffer::<f32>(3 * n_vertices.max(1))?,
            faces: face_buf,
            keys: gpu.buffer(l1)?,
            faces_sorted: gpu.buffer(l1)?,
            nodes: gpu.buffer(i1)?,
            leaf_parent: gpu.buffer(l1)?,
            node_boxes: gpu.buffer(i1)?,
            leaf_boxes: gpu.buffer(l1)?,
            child_boxes: gpu.buffer(2 * i1)?,
            visits: gpu.buffer(i1)?,
            counters: gpu.buffer(1)?,
            built: false,
            timing: Timing::default(),
            gpu,
        })
    }

    /// Faces in the tree.
    pub fn n_faces(&self) -> usize {
        self.faces_host.len()
    }

    /// Builds the tree from the first pose: Morton codes, sort, Karras's
    /// internal nodes, boxes. Calling it again rebuilds from `positions`.
    pub fn build(&mut self, positions: &[[f32; 3]]) -> Result<()> {
        self.upload(positions)?;
        self.timing = Timing::default();
        let n = self.n_faces();
        if n == 0 {
            self.built = true;
            return Ok(());
        }
        let f = MortonFrame::of(positions);
        let args = [
            Arg::U32(n as u32),
            buf(&self.pos),
            buf(&self.faces),
            Arg::F32(f.lo3[0]),
            Arg::F32(f.lo3[1]),
            Arg::F32(f.lo3[2]),
            Arg::F32(f.scale[0]),
            Arg::F32(f.scale[1]),
            Arg::F32(f.scale[2]),
            buf(&self.keys),
            buf(&self.faces_sorted),
        ];
        self.run(Step::BvhMorton, 0, n, &args)?;
        self.sort
            .sort_pairs(&mut self.keys, &mut self.faces_sorted, n, MORTON_BITS)?;
        self.timing.add(Step::RadixSortPairs, self.sort.last_ms());
        self.gpu.write(&mut self.leaf_parent, &vec![NONE; n])?;
        let args = [
            Arg::U32(n as u32),
            buf(&self.keys),
            buf(&self.nodes),
            buf(&self.leaf_parent),
        ];
        self.run(Step::BvhBuild, 1, n - 1, &args)?;
        self.built = true;
        self.refit_uploaded()
    }

    /// Refits the boxes to a new pose (same tree). Errors before
    /// [`Bvh::build`].
    pub fn refit(&mut self, positions: &[[f32; 3]]) -> Result<()> {
        if !self.built {
            return Err(Error::InvalidArgument(
                "bvh refit: the tree is not built yet (call build with the first pose)".into(),
            ));
        }
        self.upload(positions)?;
        self.timing = Timing::default();
        self.refit_uploaded()
    }

    /// Checks and uploads positions.
    fn upload(&mut self, positions: &[[f32; 3]]) -> Result<()> {
        check_positions("bvh mesh", self.n_vertices, positions)?;
        if !positions.is_empty() {
            self.gpu.write(&mut self.pos, positions.as_flattened())?;
        }
        Ok(())
    }

    /// `bvh_refit` over the uploaded positions.
    fn refit_uploaded(&mut self) -> Result<()> {
        let (n, internal) = bvh_bound(self.n_faces());
        if n == 0 {
            return Ok(());
        }
        if internal > 0 {
            self.gpu.zero(&mut self.visits, internal)?;
        }
        let args = [
            Arg::U32(n as u32),
            buf(&self.pos),
            buf(&self.faces),
            buf(&self.faces_sorted),
            buf(&self.nodes),
            buf(&self.leaf_parent),
            buf(&self.leaf_boxes),
            buf(&self.node_boxes),
            buf(&self.child_boxes),
            buf(&self.visits),
        ];
        self.run(Step::BvhRefit, 2, n, &args)
    }

    /// Launches kernel `k` over `n` items, waits, and times it as `step`.
    fn run(&mut self, step: Step, k: usize, n: usize, args: &[Arg]) -> Result<()> {
        if let Some(ev) = launch(&self.gpu, &self.kernels[k], n, args)? {
            ev.wait().map_err(|e| Error::cl("clWaitForEvents", e))?;
            self.timing.add(step, event_ms(&ev));
        }
        Ok(())
    }

    /// Runs the queries over the tree: per query
    /// [`VISIBLE`](crate::spec::bvh::VISIBLE), `OCCLUDED` or `OVERFLOW`, and
    /// the number of stack overflows. Errors before [`Bvh::build`].
    pub fn occluded(&mut self, queries: &[BvhQuery]) -> Result<(Vec<u32>, u32)> {
        if !self.built {
            return Err(Error::InvalidArgument(
                "bvh queries: the tree is not built yet (call build with the first pose)".into(),
            ));
        }
        if let Some(i) =
            (queries.iter()).position(|q| q.origin.iter().chain(&q.target).any(|c| !c.is_finite()))
        {
            return Err(Error::InvalidArgument(format!(
                "bvh query {i}: origin or target is not finite"
            )));
        }
        let nq = queries.len();
        if nq == 0 {
            return Ok((Vec::new(), 0));
        }
        let mut qbuf = self.gpu.buffer::<BvhQuery>(nq)?;
        self.gpu.write(&mut qbuf, queries)?;
        let out = self.gpu.buffer::<u32>(nq)?;
        self.gpu.zero(&mut self.counters, 1)?;
        let mut args = vec![
            Arg::U32(nq as u32),
            Arg::U32(self.n_faces() as u32),
            buf(&qbuf),
        ];
        args.extend(self.tree_bufs());
        args.extend([buf(&self.child_boxes), buf(&out), buf(&self.counters)]);
        self.timing = Timing::default();
        self.run(Step::BvhOccluded, 3, nq, &args)?;
        let mut result = vec![0u32; nq];
        self.gpu.read(&out, &mut result)?;
        let mut overflows = [0u32];
        self.gpu.read(&self.counters, &mut overflows)?;
        Ok((result, overflows[0]))
    }

    /// The built tree's device buffers as kernel arguments, for the kernels
    /// of other families that traverse it (`kernels/intersections.cl`):
    /// positions `f32[3·V]` (of the last build or refit), faces `u32[3·F]`,
    /// faces_sorted `u32[F]`, nodes, node boxes, leaf boxes (the layout of
    /// `kernels/common/bvh_tree.h`). Errors before [`Bvh::build`] and when
    /// `gpu` is not the device the tree lives on.
    pub fn tree_args(&self, gpu: &Gpu) -> Result<[Arg; 6]> {
        if !self.built {
            return Err(Error::InvalidArgument(
                "bvh tree: not built yet (call build with the first pose)".into(),
            ));
        }
        if !std::ptr::eq(gpu, &*self.gpu) {
            return Err(Error::InvalidArgument(
                "bvh tree: it lives on another Gpu (open one Gpu and share it)".into(),
            ));
        }
        Ok(self.tree_bufs())
    }

    /// The tree's buffers in the order of `kernels/common/bvh_tree.h`'s
    /// traversals: positions, faces, faces_sorted, nodes, node boxes, leaf
    /// boxes.
    fn tree_bufs(&self) -> [Arg; 6] {
        [
            buf(&self.pos),
            buf(&self.faces),
            buf(&self.faces_sorted),
            buf(&self.nodes),
            buf(&self.node_boxes),
            buf(&self.leaf_boxes),
        ]
    }

    /// Kernel steps of the last call ([`Bvh::build`], [`Bvh::refit`] or
    /// [`Bvh::occluded`]).
    pub fn timing(&self) -> &Timing {
        &self.timing
    }

    /// Reads the tree back (for tests), in the twin's type.
    pub fn read(&self) -> Result<Tree> {
        let (n, internal) = bvh_bound(self.n_faces());
        let mut t = Tree {
            keys: vec![0; n],
            faces_sorted: vec![0; n],
            nodes: vec![BvhNode::default(); internal],
            leaf_parent: vec![0; n],
            node_boxes: vec![BvhBox::default(); internal],
            leaf_boxes: vec![BvhBox::default(); n],
            child_boxes: vec![BvhBox::default(); 2 * internal],
        };
        if !self.built || n == 0 {
            t.keys.clear();
            t.faces_sorted.clear();
            t.leaf_parent.clear();
            t.leaf_boxes.clear();
            return Ok(t);
        }
        self.gpu.read(&self.keys, &mut t.keys)?;
        self.gpu.read(&self.faces_sorted, &mut t.faces_sorted)?;
        self.gpu.read(&self.leaf_parent, &mut t.leaf_parent)?;
        self.gpu.read(&self.leaf_boxes, &mut t.leaf_boxes)?;
        if internal > 0 {
            self.gpu.read(&self.nodes, &mut t.nodes)?;
            self.gpu.read(&self.node_boxes, &mut t.node_boxes)?;
            self.gpu.read(&self.child_boxes, &mut t.child_boxes)?;
        }
        Ok(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `BvhNode`, `BvhBox` and `BvhQuery` in the kernel have the spec's
    /// layout: a probe kernel reports `sizeof` and every `offsetof`.
    #[test]
    fn structs_match_the_kernel() {
        let fields = crate::spec::bvh::field_offsets();
        crate::gpu::check_layout(
            &kernel_files::BVH,
            &build_options(),
            BvhKernel::ProbeLayout,
            &fields,
        );
    }
}
