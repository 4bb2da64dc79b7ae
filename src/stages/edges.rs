//! Host wiring of `kernels/edges.cl`: object-space feature edges with caps
//! (House & Li, "Real-Time Object-Space Edge Detection using OpenCL", seed
//! 002, after McGuire & Hughes 2004).
//!
//! Buffers (E edge entries, C cap pairs, V vertices), owned by [`EdgeStage`]:
//! `edges uint[4E]` and `caps uint[2C]` (topology, uploaded once, see
//! [`crate::mesh::edges`]); `pos`, `nrm float[3V]` (per pose,
//! [`EdgeStage::set_positions`]); `params` (per frame, one
//! [`crate::spec::edges::EdgeParamBlock`] from [`EdgeParams::pack`], mirrored
//! by `EdgeParams` in the kernel); outputs `edge_out float4[4E]`, `kind uint[E]`,
//! `cap_mh0`, `cap_mh1 float4[3E]` and `cap_adj float4[4C]`. One work-item
//! handles one edge (`edges_detect`, `caps_mh`) or one cap pair
//! (`caps_adjacency`). Outputs are indexed by edge or cap, never appended, so
//! device and CPU ([`crate::cpu::edges`]) results compare element by element.
//! Outputs persist between runs: a primitive undrawn in this run and the last
//! one keeps its marker and is not rewritten (`kind` and `cap_drawn uchar[C]`
//! remember what the last run drew), which removes most of the output traffic.
//! The stage takes a [`crate::spec::view::View`] (inside [`EdgeParams`]) and
//! knows no screen: framing, drawing and the cap-quality evaluation live in
//! `render::{camera, edges, cap_quality}`.
//!
//! Conventions:
//! - **Contour**: the two face normals face opposite ways seen from the eye
//!   (per-edge eye vector `eye − p0` in perspective, the view direction in
//!   orthographic views). Faces must be consistently oriented.
//! - **Crease**: the angle between the two face normals is larger than the
//!   user angle θ (degrees, in (0, 180]): `na·nb < cos θ |na||nb|`. A flat
//!   region has 0°, a cube's edges 90°: θ = 30 finds the cube's 12 edges and
//!   none of its face diagonals. (House & Li write `na·nb < −cos θ'`, i.e.
//!   θ' = 180° − θ is the dihedral angle between the faces.)
//! - **Boundary and marked**: `i3 == i0`.
//! - **Half quads** (`half_contours`): contour-only edges extend from the edge
//!   outward by the full width; their quad-end midpoints lie on the stroke's
//!   centre line, so adjacency caps join them (McGuire-Hughes caps stay
//!   centred on the edge).
//! - **Width**: `line_width` pixels across, times max(1, k/w) with depth scale
//!   k (House & Li's appendix; k = 0 or `None`: constant screen width).
//! - **Near plane**: an edge with an end at clip w ≤ near (perspective) is not
//!   drawn, so an eye inside the mesh gives no screen-spanning quads.
//! - **Degenerate output** is House & Li's marker `(NaN, 0, −1, 1)` on every
//!   vertex of the quad, triangle or cap.

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, kernel_file, launch};
use crate::mesh::Mesh;
use crate::mesh::edges::EdgeTopology;
use crate::mesh::topology::vertex_normals;
use crate::spec::edges::{MARKER, PARAMS_LEN, cap_adjacency_bound, cap_mh_bound, edge_out_bound};
use crate::spec::timing::{Step, Timing};
use crate::stages::scan::Scan;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use std::sync::Arc;
use std::time::Instant;

use crate::spec::edges::{CapMode, EdgeOutput, EdgeParams};

/// Device buffers and kernels of the edges stage for one mesh topology.
pub struct EdgeStage {
    gpu: Arc<Gpu>,
    n_vertices: usize,
    n_edges: usize,
    n_caps: usize,
    k_detect: Kernel,
    k_mh: Kernel,
    k_adj: Kernel,
    params: Buffer<f32>,
    pos: Buffer<f32>,
    nrm: Buffer<f32>,
    edges: Buffer<u32>,
    caps: Buffer<u32>,
    edge_out: Buffer<f32>,
    kind: Buffer<u32>,
    /// The cap outputs, allocated (and filled with markers) by the first run
    /// of their variant: a stage that never draws adjacency caps never holds
    /// their buffer (16 floats per cap pair, 1.9 GB for a 2M-vertex torus).
    cap_mh: Option<[Buffer<f32>; 2]>,
    cap_adj: Option<(Buffer<f32>, Buffer<u8>)>,
    last_mode: CapMode,
    /// The read-back compaction, made by the first [`EdgeStage::read_drawn`].
    compact: Option<Compactor>,
}

/// Kernels and buffers of [`EdgeStage::read_drawn`]'s compaction.
struct Compactor {
    k_flags: Kernel,
    k_edges: Kernel,
    k_caps: Kernel,
    scan: Scan,
    /// Flags, then slots after the scan: E edge entries, then C cap pairs.
    slots: Buffer<u32>,
    /// The compacted vertices: edge-out, then the caps; grown as needed.
    dst: Buffer<f32>,
    /// float4 vertices `dst` holds.
    dst_len: usize,
    /// Kernel time of the last compaction, ms.
    last_ms: f64,
}

impl EdgeStage {
    /// Builds the program, uploads the topology and the mesh's positions and
    /// vertex normals, and allocates the edge outputs (sized by the `*_bound`
    /// functions of [`crate::spec::edges`]; the cap outputs of a variant are
    /// allocated by its first run).
    pub fn new(gpu: Arc<Gpu>, mesh: &Mesh, topo: &EdgeTopology) -> Result<EdgeStage> {
        let pos: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.map(|c| c as f32)).collect();
        Self::with_pose(gpu, topo, &pos, &vertex_normals(mesh))
    }

    /// [`EdgeStage::new`] with the first pose given as f32 positions and unit
    /// vertex normals (those a caller already made for drawing the mesh).
    pub fn with_pose(
        gpu: Arc<Gpu>,
        topo: &EdgeTopology,
        pos: &[[f32; 3]],
        nrm: &[[f32; 3]],
    ) -> Result<EdgeStage> {
        let file = kernel_file("edges").expect("kernels/edges.cl is registered");
        let prog = gpu.program(&file, "")?;
        let (nv, ne, nc) = (pos.len(), topo.edges.len(), topo.caps.len());
        if ne >= (u32::MAX / 16) as usize || nc >= (u32::MAX / 16) as usize {
            return Err(Error::input(
                "mesh",
                "edges",
                format!("{ne} edges / {nc} cap pairs exceed the 32-bit output index range"),
            ));
        }
        let n_out = edge_out_bound(ne);
        let mut s = EdgeStage {
            n_vertices: nv,
            n_edges: ne,
            n_caps: nc,
            k_detect: gpu.kernel(&prog, "edges_detect")?,
            k_mh: gpu.kernel(&prog, "caps_mh")?,
            k_adj: gpu.kernel(&prog, "caps_adjacency")?,
            params: gpu.buffer(PARAMS_LEN)?,
            pos: gpu.buffer(3 * nv)?,
            nrm: gpu.buffer(3 * nv)?,
            edges: gpu.buffer(4 * ne)?,
            caps: gpu.buffer(2 * nc)?,
            edge_out: gpu.buffer(4 * n_out)?,
            kind: gpu.buffer(ne)?,
            cap_mh: None,
            cap_adj: None,
            last_mode: CapMode::None,
            compact: None,
            gpu: gpu.clone(),
        };
        // Outputs persist between runs (undrawn-then-undrawn primitives are not
        // rewritten): start from markers everywhere, filled on the device.
        gpu.fill(&mut s.edge_out, &MARKER, 4 * n_out)?;
        gpu.zero(&mut s.kind, ne)?;
        gpu.write(&mut s.edges, bytemuck::cast_slice(&topo.edges))?;
        gpu.write(&mut s.caps, bytemuck::cast_slice(&topo.caps))?;
        s.set_positions(pos, nrm)?;
        Ok(s)
    }

    /// Allocates the cap outputs of `mode` on its first run, filled with
    /// markers (and `cap_drawn` with 0), as the kernels expect.
    fn ensure_caps(&mut self, mode: CapMode) -> Result<()> {
        let g = &self.gpu;
        match mode {
            CapMode::None => {}
            CapMode::Mh if self.cap_mh.is_none() => {
                let n = 4 * cap_mh_bound(self.n_edges);
                let mut b = [g.buffer(n)?, g.buffer(n)?];
                for b in &mut b {
                    g.fill(b, &MARKER, n)?;
                }
                self.cap_mh = Some(b);
            }
            CapMode::Adjacency if self.cap_adj.is_none() => {
                let n = 4 * cap_adjacency_bound(self.n_caps);
                let mut out = g.buffer(n)?;
                g.fill(&mut out, &MARKER, n)?;
                let mut drawn = g.buffer(self.n_caps)?;
                g.zero(&mut drawn, self.n_caps)?;
                self.cap_adj = Some((out, drawn));
            }
            _ => {}
        }
        Ok(())
    }

    /// Number of edge entries.
    pub fn n_edges(&self) -> usize {
        self.n_edges
    }

    /// Number of cap pairs.
    pub fn n_caps(&self) -> usize {
        self.n_caps
    }

    /// Uploads a new pose (world-space positions and unit vertex normals)
    /// into the existing buffers.
    pub fn set_positions(&mut self, pos: &[[f32; 3]], nrm: &[[f32; 3]]) -> Result<()> {
        if pos.len() != self.n_vertices || nrm.len() != self.n_vertices {
            return Err(Error::InvalidArgument(format!(
                "edges: {} positions and {} normals for a mesh of {} vertices",
                pos.len(),
                nrm.len(),
                self.n_vertices
            )));
        }
        if let Some(i) = pos.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(Error::input(
                "positions",
                format!("vertex {i}"),
                "non-finite coordinate",
            ));
        }
        self.gpu.write(&mut self.pos, bytemuck::cast_slice(pos))?;
        self.gpu.write(&mut self.nrm, bytemuck::cast_slice(nrm))
    }

    /// Runs detection and the caps of `mode` for one frame and waits for it.
    pub fn run(&mut self, params: &EdgeParams, mode: CapMode) -> Result<Timing> {
        let packed = params.pack()?;
        let t0 = Instant::now();
        self.ensure_caps(mode)?;
        let g = self.gpu.clone();
        g.write(&mut self.params, packed.as_floats())?;
        let ne = self.n_edges as u32;
        let ev_d = launch(
            &g,
            &self.k_detect,
            self.n_edges,
            &[
                Arg::U32(ne),
                buf(&self.params),
                buf(&self.pos),
                buf(&self.nrm),
                buf(&self.edges),
                buf(&self.edge_out),
                buf(&self.kind),
            ],
        )?;
        let ev_c = match mode {
            CapMode::None => None,
            CapMode::Mh => {
                let [mh0, mh1] = self.cap_mh.as_ref().expect("allocated above");
                launch(
                    &g,
                    &self.k_mh,
                    self.n_edges,
                    &[
                        Arg::U32(ne),
                        buf(&self.params),
                        buf(&self.pos),
                        buf(&self.nrm),
                        buf(&self.edges),
                        buf(&self.kind),
                        buf(mh0),
                        buf(mh1),
                    ],
                )?
            }
            CapMode::Adjacency => {
                let (adj, drawn) = self.cap_adj.as_ref().expect("allocated above");
                launch(
                    &g,
                    &self.k_adj,
                    self.n_caps,
                    &[
                        Arg::U32(self.n_caps as u32),
                        buf(&self.params),
                        buf(&self.edges),
                        buf(&self.caps),
                        buf(&self.kind),
                        buf(&self.edge_out),
                        buf(adj),
                        buf(drawn),
                    ],
                )?
            }
        };
        g.finish()?;
        self.last_mode = mode;
        let mut t = Timing::default();
        if let Some(e) = &ev_d {
            t.add(Step::EdgesDetect, event_ms(e));
        }
        if let Some(e) = &ev_c {
            let step = match mode {
                CapMode::Mh => Step::CapsMh,
                _ => Step::CapsAdjacency,
            };
            t.add(step, event_ms(e));
        }
        t.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(t)
    }

    /// Reads back the outputs of the last run (caps of the last run's mode only).
    pub fn read(&self) -> Result<EdgeOutput> {
        let g = &self.gpu;
        let read4 = |b: &Buffer<f32>, n: usize| -> Result<Vec<[f32; 4]>> {
            let mut v = vec![[0f32; 4]; n];
            g.read(b, bytemuck::cast_slice_mut(&mut v))?;
            Ok(v)
        };
        let mut kind = vec![0u32; self.n_edges];
        g.read(&self.kind, &mut kind)?;
        let mut out = EdgeOutput {
            edge_out: read4(&self.edge_out, edge_out_bound(self.n_edges))?,
            kind,
            ..Default::default()
        };
        match (self.last_mode, &self.cap_mh, &self.cap_adj) {
            (CapMode::Mh, Some([mh0, mh1]), _) => {
                out.cap_mh0 = read4(mh0, cap_mh_bound(self.n_edges))?;
                out.cap_mh1 = read4(mh1, cap_mh_bound(self.n_edges))?;
            }
            (CapMode::Adjacency, _, Some((adj, _))) => {
                out.cap_adj = read4(adj, cap_adjacency_bound(self.n_caps))?
            }
            _ => {}
        }
        Ok(out)
    }

    /// Reads back what the last run drew, for drawing and SVG: `kind` in
    /// full, and of edge-out and the caps of the last run's mode only the
    /// primitives that hold geometry (a drawn edge, `KIND_DRAWN`; a drawn
    /// adjacency cap, `cap_drawn`), **compacted** in index order on the
    /// device (`drawn_flags`, one scan, `compact_edges`, `compact_caps`;
    /// CPU twin [`crate::cpu::edges::compact_drawn`]). Drawing the result
    /// draws exactly what drawing [`read`](Self::read)'s would (the renderer
    /// skips markers and keeps order), from a few percent of the bytes: on a
    /// 2M-vertex torus seen whole, 5,202 of 6M edges. Two waits: the scan's
    /// totals, then the reads.
    pub fn read_drawn(&mut self) -> Result<EdgeOutput> {
        let g = self.gpu.clone();
        let (ne, nc) = (self.n_edges, self.n_caps);
        let adj = match (self.last_mode, &self.cap_adj) {
            (CapMode::Adjacency, Some((out, drawn))) => Some((out, drawn)),
            _ => None,
        };
        let caps_n = if adj.is_some() { nc } else { 0 };
        if self.compact.is_none() {
            let file = kernel_file("edges").expect("kernels/edges.cl is registered");
            let prog = g.program(&file, "")?;
            self.compact = Some(Compactor {
                k_flags: g.kernel(&prog, "drawn_flags")?,
                k_edges: g.kernel(&prog, "compact_edges")?,
                k_caps: g.kernel(&prog, "compact_caps")?,
                scan: Scan::new(g.clone())?,
                slots: g.buffer((ne + nc).max(1))?,
                dst: g.buffer(4)?,
                dst_len: 1,
                last_ms: 0.0,
            });
        }
        let c = self.compact.as_mut().expect("made above");
        let n = ne + caps_n;
        let mut kind = vec![0u32; ne];
        let mut out = EdgeOutput::default();
        if n == 0 {
            out.kind = kind;
            return Ok(out);
        }
        // With no adjacency caps, the kind buffer stands in for the unread
        // cap flags (any buffer will do: no work-item reads it).
        let cap_flags = adj.map_or_else(|| buf(&self.kind), |(_, d)| buf(d));
        let mut events = Vec::new();
        events.extend(launch(
            &g,
            &c.k_flags,
            n,
            &[
                Arg::U32(ne as u32),
                Arg::U32(caps_n as u32),
                buf(&self.kind),
                cap_flags,
                buf(&c.slots),
            ],
        )?);
        let at: &[usize] = if caps_n > 0 && ne > 0 { &[ne] } else { &[] };
        let (total, before) = c.scan.exclusive_at(&c.slots, &c.slots, n, at)?;
        let mut ms = c.scan.last_ms();
        let total = total as usize;
        let drawn_edges = match (caps_n, ne) {
            (0, _) => total,
            (_, 0) => 0,
            _ => before[0] as usize,
        };
        let drawn_caps = total - drawn_edges;
        let mh = match (self.last_mode, &self.cap_mh) {
            (CapMode::Mh, Some([m0, m1])) => Some((m0, m1)),
            _ => None,
        };
        // Vertices: edge-out (4 per edge), the half-caps (3 + 3), the caps (4).
        let per_edge = if mh.is_some() { 10 } else { 4 };
        let need = per_edge * drawn_edges + 4 * drawn_caps;
        if need > c.dst_len {
            // Grown by half again, so that a view drawing a few more edges
            // than the last does not reallocate every frame.
            let len = need.max(c.dst_len + c.dst_len / 2);
            c.dst = g.buffer(4 * len)?;
            c.dst_len = len;
        }
        let mut at_v = 0usize;
        let mut parts: Vec<(usize, usize)> = Vec::new();
        if drawn_edges > 0 {
            let mut srcs: Vec<(&Buffer<f32>, u32)> = vec![(&self.edge_out, 4)];
            if let Some((m0, m1)) = mh {
                srcs.push((m0, 3));
                srcs.push((m1, 3));
            }
            for (src, per) in srcs {
                events.extend(launch(
                    &g,
                    &c.k_edges,
                    ne,
                    &[
                        Arg::U32(ne as u32),
                        Arg::U32(per),
                        buf(src),
                        buf(&self.kind),
                        buf(&c.slots),
                        Arg::U32(at_v as u32),
                        buf(&c.dst),
                    ],
                )?);
                parts.push((at_v, per as usize * drawn_edges));
                at_v += per as usize * drawn_edges;
            }
        }
        if let Some((src, drawn)) = adj.filter(|_| drawn_caps > 0) {
            events.extend(launch(
                &g,
                &c.k_caps,
                nc,
                &[
                    Arg::U32(nc as u32),
                    buf(src),
                    buf(drawn),
                    buf(&c.slots),
                    Arg::U32(ne as u32),
                    Arg::U32(drawn_edges as u32),
                    Arg::U32(at_v as u32),
                    buf(&c.dst),
                ],
            )?);
            parts.push((at_v, 4 * drawn_caps));
        }
        let mut vecs: Vec<Vec<[f32; 4]>> = parts.iter().map(|p| vec![[0f32; 4]; p.1]).collect();
        let mut failed = None;
        // SAFETY: `kind` and `vecs` are neither moved nor read until `finish`
        // below, which also runs on the error path; the ranges lie inside
        // the buffers (parts are within `need` ≤ dst_len vertices).
        unsafe {
            if let Err(e) = g.read_at_async(&self.kind, 0, &mut kind) {
                failed = Some(e);
            }
            for (v, p) in vecs.iter_mut().zip(&parts) {
                if failed.is_some() {
                    break;
                }
                if let Err(e) = g.read_at_async(&c.dst, 4 * p.0, bytemuck::cast_slice_mut(v)) {
                    failed = Some(e);
                }
            }
        }
        let done = g.finish();
        if let Some(e) = failed {
            return Err(e);
        }
        done?;
        ms += events.iter().map(event_ms).sum::<f64>();
        c.last_ms = ms;
        let mut vecs = vecs.into_iter();
        out.kind = kind;
        if drawn_edges > 0 {
            out.edge_out = vecs.next().unwrap_or_default();
            if mh.is_some() {
                out.cap_mh0 = vecs.next().unwrap_or_default();
                out.cap_mh1 = vecs.next().unwrap_or_default();
            }
        }
        if drawn_caps > 0 {
            out.cap_adj = vecs.next().unwrap_or_default();
        }
        Ok(out)
    }

    /// Kernel time of the last [`read_drawn`](Self::read_drawn)'s
    /// compaction ([`Step::EdgesCompact`]).
    pub fn compact_timing(&self) -> Timing {
        let mut t = Timing::default();
        if let Some(c) = &self.compact {
            t.add(Step::EdgesCompact, c.last_ms);
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::{COMMON_HEADERS, KernelFile};
    use crate::spec::edges::EdgeParamBlock;

    /// The kernel's `EdgeParams` has the layout of [`EdgeParamBlock`]: a probe
    /// kernel appended to `kernels/edges.cl` writes `sizeof` and every
    /// `offsetof` as the device compiler sees them.
    #[test]
    fn param_block_layout_matches_the_kernel() {
        let gpu = match Gpu::new(None) {
            Ok(g) => g,
            Err(e) => panic!("this test needs an OpenCL device (PoCL on CPU is enough): {e}"),
        };
        let fields = EdgeParamBlock::field_offsets();
        let mut probe = String::from("\n__kernel void edges_probe_layout(__global uint* out) {\n");
        for (i, (name, _)) in fields.iter().enumerate() {
            let expr = if name.starts_with('(') {
                "sizeof(EdgeParams)".to_string()
            } else {
                format!("__builtin_offsetof(EdgeParams, {name})")
            };
            probe += &format!("    out[{i}] = (uint)({expr});\n");
        }
        probe += "}\n";
        let file = KernelFile {
            name: "kernels/edges.cl (layout probe)",
            source: Box::leak(
                (kernel_file("edges").unwrap().source.to_string() + &probe).into_boxed_str(),
            ),
            headers: COMMON_HEADERS,
        };
        let prog = gpu.program(&file, "").unwrap();
        let k = gpu.kernel(&prog, "edges_probe_layout").unwrap();
        let mut out: Buffer<u32> = gpu.buffer(fields.len()).unwrap();
        gpu.write(&mut out, &vec![u32::MAX; fields.len()]).unwrap();
        launch(&gpu, &k, 1, &[buf(&out)]).unwrap();
        gpu.finish().unwrap();
        let mut got = vec![0u32; fields.len()];
        gpu.read(&out, &mut got).unwrap();
        for ((name, want), got) in fields.iter().zip(got) {
            assert_eq!(got as usize, *want, "{name}: device vs Rust");
        }
    }
}
