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
//! `cap_mh0`, `cap_mh1 float4[3E]`, and for adjacency caps `cap_slot uint[C]`
//! and `cap_adj float4[4K]` for the K caps a view draws. One work-item
//! handles one edge (`edges_detect`, `caps_mh`) or one cap pair
//! (`caps_adjacency_flags`, `caps_adjacency`). Edge outputs are indexed by
//! edge, never appended; adjacency caps are flagged, the flags scanned into
//! slots, and only the drawn caps written, in pair order, so that a mesh's
//! cap-out takes 4 bytes per pair plus the caps drawn instead of House & Li's
//! 64 bytes per pair (1.5 GB on a 2M-vertex torus). [`EdgeStage::read`]
//! gives every output indexed by edge or cap pair (undrawn caps as the
//! marker), so device and CPU ([`crate::cpu::edges`]) results compare
//! element by element. Edge outputs persist between runs: an edge undrawn in
//! this run and the last one keeps its marker and is not rewritten (`kind`
//! remembers what the last run drew), which removes most of the output traffic.
//! The stage takes a [`crate::spec::view::View`] (inside [`EdgeParams`]) and
//! knows no screen: framing and drawing live in `render::{camera, edges}`,
//! and the cap-quality evaluation in `report::caps`. Detection's conventions
//! (contour, crease, width, near plane, the marker) are on [`EdgeStage`].

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::mesh::Mesh;
use crate::mesh::edges::EdgeTopology;
use crate::mesh::topology::vertex_normals;
use crate::spec::edges::EdgesKernel;
use crate::spec::edges::{MARKER, PARAMS_LEN, cap_adjacency_bound, cap_mh_bound, edge_out_bound};
use crate::spec::timing::{Step, Timing};
use crate::stages::kernel_files;
use crate::stages::scan::Scan;
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use std::sync::Arc;
use std::time::Instant;

use crate::spec::edges::{CapMode, EdgeOutput, EdgeParams};

/// Device buffers and kernels of the edges stage for one mesh topology.
///
/// Conventions:
/// - **Contour**: the two face normals face opposite ways seen from the eye
///   (per-edge eye vector `eye − p0` in perspective, the view direction in
///   orthographic views). Faces must be consistently oriented.
/// - **Crease**: the angle between the two face normals is larger than the
///   user angle θ (degrees, in (0, 180]): `na·nb < cos θ |na||nb|`. A flat
///   region has 0°, a cube's edges 90°: θ = 30 finds the cube's 12 edges and
///   none of its face diagonals. (House & Li write `na·nb < −cos θ'`, i.e.
///   θ' = 180° − θ is the dihedral angle between the faces.)
/// - **Boundary and marked**: `i3 == i0`.
/// - **Half quads** (`half_contours`): contour-only edges extend from the edge
///   outward by the full width; their quad-end midpoints lie on the stroke's
///   centre line, so adjacency caps join them (McGuire-Hughes caps stay
///   centred on the edge).
/// - **Width**: `line_width` pixels across, times max(1, k/w) with depth scale
///   k (House & Li's appendix; k = 0 or `None`: constant screen width).
/// - **Near plane**: an edge with an end at clip w ≤ near (perspective) is not
///   drawn, so an eye inside the mesh gives no screen-spanning quads.
/// - **Degenerate output** is House & Li's marker `(NaN, 0, −1, 1)` on every
///   vertex of the quad, triangle or cap.
pub struct EdgeStage {
    gpu: Arc<Gpu>,
    n_vertices: usize,
    n_edges: usize,
    n_caps: usize,
    k_detect: Kernel,
    k_mh: Kernel,
    k_adj_flags: Kernel,
    k_adj: Kernel,
    params: Buffer<f32>,
    pos: Buffer<f32>,
    nrm: Buffer<f32>,
    edges: Buffer<u32>,
    caps: Buffer<u32>,
    edge_out: Buffer<f32>,
    kind: Buffer<u32>,
    /// The cap outputs, allocated by the first run of their variant: a
    /// stage that never draws McGuire-Hughes caps never holds their buffers.
    cap_mh: Option<[Buffer<f32>; 2]>,
    cap_adj: Option<AdjacencyCaps>,
    last_mode: CapMode,
    /// The scan of the adjacency cap flags and of the read-back compaction.
    scan: Option<Scan>,
    /// The read-back compaction, made by the first [`EdgeStage::read_drawn`].
    compact: Option<Compactor>,
}

/// The adjacency caps: a slot per cap pair, and the quads of the drawn ones.
struct AdjacencyCaps {
    /// Flags, then (scanned) each pair's slot among the drawn caps.
    slots: Buffer<u32>,
    /// The drawn caps' quads, in pair order; grown as needed.
    out: Buffer<f32>,
    /// Caps `out` holds room for.
    room: usize,
    /// Caps the last run drew.
    drawn: usize,
}

/// What [`EdgeStage::compact_into`] wrote into a shared buffer.
#[derive(Clone, Debug, Default)]
pub struct SharedDrawn {
    /// Kind bits per edge (read back: counts and stats).
    pub kind: Vec<u32>,
    /// Drawn edges: quads at vertices `0..4 * edges`.
    pub edges: usize,
    /// McGuire-Hughes half-caps follow: `4e..7e` and `7e..10e`.
    pub mh: bool,
    /// First vertex of the adjacency caps.
    pub caps_at: usize,
    /// Drawn adjacency caps (4 vertices each) from `caps_at`.
    pub adjacency_caps: usize,
}

/// Kernels and buffers of [`EdgeStage::read_drawn`]'s compaction.
struct Compactor {
    k_flags: Kernel,
    k_edges: Kernel,
    /// Flags, then slots after the scan, per edge entry.
    slots: Buffer<u32>,
    /// Edge entries.
    ne: usize,
    /// The compacted vertices: edge-out, then the half-caps; grown as needed.
    dst: Buffer<f32>,
    /// float4 vertices `dst` holds.
    dst_len: usize,
    /// Kernel time of the last compaction, ms.
    last_ms: f64,
}

/// Room for `need` elements in a buffer that holds `room`: `need` grown by
/// half again over `room`, so that a view drawing a few more than the last
/// does not reallocate every frame.
fn grown(need: usize, room: usize) -> usize {
    need.max(room + room / 2)
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
        let file = kernel_files::EDGES;
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
            k_detect: gpu.entry(&prog, EdgesKernel::Detect)?,
            k_mh: gpu.entry(&prog, EdgesKernel::CapsMh)?,
            k_adj_flags: gpu.entry(&prog, EdgesKernel::CapsAdjacencyFlags)?,
            k_adj: gpu.entry(&prog, EdgesKernel::CapsAdjacency)?,
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
            scan: None,
            compact: None,
            gpu: gpu.clone(),
        };
        // Edge outputs persist between runs (undrawn-then-undrawn edges are not
        // rewritten): start from markers everywhere, filled on the device.
        gpu.fill(&mut s.edge_out, &MARKER, 4 * n_out)?;
        gpu.zero(&mut s.kind, ne)?;
        gpu.write(&mut s.edges, bytemuck::cast_slice(&topo.edges))?;
        gpu.write(&mut s.caps, bytemuck::cast_slice(&topo.caps))?;
        s.set_positions(pos, nrm)?;
        Ok(s)
    }

    /// Allocates the cap outputs of `mode` on its first run: the half-cap
    /// buffers filled with markers, as `caps_mh` expects; the adjacency
    /// cap slots and room for one cap (grown by the runs).
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
                self.cap_adj = Some(AdjacencyCaps {
                    slots: g.buffer(self.n_caps.max(1))?,
                    out: g.buffer(16)?,
                    room: 1,
                    drawn: 0,
                });
            }
            _ => {}
        }
        if mode == CapMode::Adjacency {
            self.ensure_scan()?;
        }
        Ok(())
    }

    /// Makes the scan of the adjacency cap flags and of the read-back
    /// compaction on first use.
    fn ensure_scan(&mut self) -> Result<()> {
        if self.scan.is_none() {
            self.scan = Some(Scan::new(self.gpu.clone())?);
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
        let ev_d = self.edges_detect()?;
        // The cap kernels' events, and the scan's kernel time (adjacency).
        let (cap_events, scan_ms) = match mode {
            CapMode::None => (Vec::new(), 0.0),
            CapMode::Mh => (self.caps_mh()?.into_iter().collect(), 0.0),
            CapMode::Adjacency => self.caps_adjacency()?,
        };
        g.finish()?;
        // The flags, their scan and the drawn caps for adjacency caps.
        let cap_ms = cap_events.iter().map(event_ms).sum::<f64>() + scan_ms;
        self.last_mode = mode;
        let mut t = Timing::default();
        if let Some(e) = &ev_d {
            t.add(Step::EdgesDetect, event_ms(e));
        }
        match mode {
            CapMode::None => {}
            CapMode::Mh => t.add(Step::CapsMh, cap_ms),
            CapMode::Adjacency => t.add(Step::CapsAdjacency, cap_ms),
        }
        t.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(t)
    }

    /// `edges_detect`: each edge's kind and quad (or the marker).
    fn edges_detect(&self) -> Result<Option<Event>> {
        launch(
            &self.gpu,
            &self.k_detect,
            self.n_edges,
            &[
                Arg::U32(self.n_edges as u32),
                buf(&self.params),
                buf(&self.pos),
                buf(&self.nrm),
                buf(&self.edges),
                buf(&self.edge_out),
                buf(&self.kind),
            ],
        )
    }

    /// `caps_mh`: McGuire-Hughes half-caps at both ends of each drawn edge.
    fn caps_mh(&self) -> Result<Option<Event>> {
        let [mh0, mh1] = self.cap_mh.as_ref().expect("allocated above");
        launch(
            &self.gpu,
            &self.k_mh,
            self.n_edges,
            &[
                Arg::U32(self.n_edges as u32),
                buf(&self.params),
                buf(&self.pos),
                buf(&self.nrm),
                buf(&self.edges),
                buf(&self.kind),
                buf(mh0),
                buf(mh1),
            ],
        )
    }

    /// `caps_adjacency_flags`, their scan (the one wait) and
    /// `caps_adjacency`: the drawn caps written at their slots, the output
    /// grown first where they do not fit; returns the kernels' events and
    /// the scan's ms.
    fn caps_adjacency(&mut self) -> Result<(Vec<Event>, f64)> {
        let (g, nc) = (&*self.gpu, self.n_caps);
        let caps = self.cap_adj.as_mut().expect("allocated above");
        let scan = self.scan.as_mut().expect("made with the caps");
        let common = [
            Arg::U32(nc as u32),
            buf(&self.params),
            buf(&self.edges),
            buf(&self.caps),
            buf(&self.kind),
            buf(&self.edge_out),
        ];
        let mut args = common.to_vec();
        args.push(buf(&caps.slots));
        let mut events: Vec<_> = launch(g, &self.k_adj_flags, nc, &args)?
            .into_iter()
            .collect();
        // The scan's total read is the one wait before the caps.
        let (total, _) = scan.exclusive_at(&caps.slots, &caps.slots, nc, &[])?;
        let total = total as usize;
        if total > caps.room {
            let room = grown(total, caps.room);
            caps.out = g.buffer(16 * room)?;
            caps.room = room;
        }
        caps.drawn = total;
        if total > 0 {
            let mut args = common.to_vec();
            args.extend([buf(&caps.slots), Arg::U32(total as u32), buf(&caps.out)]);
            events.extend(launch(g, &self.k_adj, nc, &args)?);
        }
        Ok((events, scan.last_ms()))
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
            (CapMode::Adjacency, _, Some(c)) => {
                // Back to one quad per cap pair: the drawn ones at their
                // slots, the marker elsewhere.
                let nc = self.n_caps;
                let mut slots = vec![0u32; nc];
                g.read(&c.slots, &mut slots)?;
                let drawn = read4(&c.out, 4 * c.drawn)?;
                let mut all = vec![MARKER; cap_adjacency_bound(nc)];
                for i in 0..nc {
                    let (s, next) = (
                        slots[i] as usize,
                        slots.get(i + 1).map_or(c.drawn, |&n| n as usize),
                    );
                    if next > s {
                        all[4 * i..4 * i + 4].copy_from_slice(&drawn[4 * s..4 * s + 4]);
                    }
                }
                out.cap_adj = all;
            }
            _ => {}
        }
        Ok(out)
    }

    /// Reads back what the last run drew, for drawing and SVG: `kind` in
    /// full, and of edge-out and the caps of the last run's mode only the
    /// primitives that hold geometry (a drawn edge, `KIND_DRAWN`; a drawn
    /// adjacency cap), **compacted** in index order on the device
    /// (`drawn_flags`, one scan, `compact_edges`; adjacency caps are written
    /// compacted by their kernel already; CPU twin
    /// [`crate::cpu::edges::compact_drawn`]). Drawing the result draws
    /// exactly what drawing [`read`](Self::read)'s would (the renderer skips
    /// markers and keeps order), from a few percent of the bytes. Two
    /// waits: the scan's total, then the reads.
    pub fn read_drawn(&mut self) -> Result<EdgeOutput> {
        let g = self.gpu.clone();
        let ne = self.n_edges;
        self.ensure_compactor()?;
        let c = self.compact.as_mut().expect("made above");
        let scan = self.scan.as_mut().expect("made above");
        let mut kind = vec![0u32; ne];
        let mut events = Vec::new();
        let (drawn_edges, mut ms) = c.drawn_flags(&g, scan, &self.kind, &mut events)?;
        let mh = half_caps(self.last_mode, &self.cap_mh);
        let adj = match (self.last_mode, &self.cap_adj) {
            (CapMode::Adjacency, Some(a)) => Some(a),
            _ => None,
        };
        // Vertices: edge-out (4 per edge) and the half-caps (3 + 3).
        let per_edge = if mh.is_some() { 10 } else { 4 };
        let need = per_edge * drawn_edges;
        if need > c.dst_len {
            let len = grown(need, c.dst_len);
            c.dst = g.buffer(4 * len)?;
            c.dst_len = len;
        }
        let srcs = drawn_sources(&self.edge_out, mh);
        let dst = buf(&c.dst);
        let parts = c.compact_edges(&g, &self.kind, &srcs, drawn_edges, dst, &mut events)?;
        let (vecs, caps) = read_compacted(&g, (&self.kind, &mut kind), &c.dst, &parts, adj)?;
        ms += events.iter().map(event_ms).sum::<f64>();
        c.last_ms = ms;
        let mut vecs = vecs.into_iter();
        let mut out = EdgeOutput {
            kind,
            cap_adj: caps,
            ..EdgeOutput::default()
        };
        if drawn_edges > 0 {
            out.edge_out = vecs.next().unwrap_or_default();
            if mh.is_some() {
                out.cap_mh0 = vecs.next().unwrap_or_default();
                out.cap_mh1 = vecs.next().unwrap_or_default();
            }
        }
        Ok(out)
    }

    /// Makes the read-back compaction's kernels and flags, and the scan,
    /// on first use.
    fn ensure_compactor(&mut self) -> Result<()> {
        if self.compact.is_none() {
            self.compact = Some(Compactor::new(&self.gpu, self.n_edges)?);
        }
        self.ensure_scan()
    }

    /// Vertices [`compact_into`](Self::compact_into) may write for `mode`:
    /// edge-out and the half-caps (10 per edge) for McGuire-Hughes caps,
    /// else edge-out (4 per edge) and the adjacency caps (4 per pair).
    pub fn shared_vertices(&self, mode: CapMode) -> usize {
        match mode {
            CapMode::Mh => 10 * self.n_edges,
            CapMode::None => 4 * self.n_edges,
            CapMode::Adjacency => 4 * self.n_edges + 4 * self.n_caps,
        }
    }

    /// What [`read_drawn`](Self::read_drawn) reads back, written instead
    /// into `dst` on the device (a buffer GL draws from: the external-memory
    /// route), with `kind` alone read back: edge-out compacted from vertex
    /// 0, then for McGuire-Hughes caps both half-cap lists, then the drawn
    /// adjacency caps (copied on the device). `dst` holds at least
    /// [`shared_vertices`](Self::shared_vertices) vertices of the last
    /// run's mode. Returns `kind` and the drawn edges and caps.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a `dst` too small; device failures.
    pub fn compact_into(
        &mut self,
        dst: &mut Buffer<f32>,
        dst_vertices: usize,
    ) -> Result<SharedDrawn> {
        let need = self.shared_vertices(self.last_mode);
        if dst_vertices < need {
            return Err(Error::InvalidArgument(format!(
                "edges: a shared buffer of {dst_vertices} vertices is smaller than the {need} \
                 this topology may draw"
            )));
        }
        // The read-back compaction's kernels and flags, made once.
        self.ensure_compactor()?;
        let g = self.gpu.clone();
        let ne = self.n_edges;
        let c = self.compact.as_mut().expect("made above");
        let scan = self.scan.as_mut().expect("made above");
        let mut out = SharedDrawn::default();
        let mut events = Vec::new();
        let ms;
        (out.edges, ms) = c.drawn_flags(&g, scan, &self.kind, &mut events)?;
        let mh = half_caps(self.last_mode, &self.cap_mh);
        out.mh = mh.is_some();
        let srcs = drawn_sources(&self.edge_out, mh);
        let parts = c.compact_edges(&g, &self.kind, &srcs, out.edges, buf(&*dst), &mut events)?;
        out.caps_at = parts.last().map_or(0, |&(at, n)| at + n);
        if let (CapMode::Adjacency, Some(a)) = (self.last_mode, &self.cap_adj)
            && a.drawn > 0
        {
            out.adjacency_caps = a.drawn;
            // SAFETY: both ranges lie inside their buffers (the caps' room,
            // and `dst` holds `need` ≥ 4E + 4C vertices).
            unsafe {
                g.queue()
                    .enqueue_copy_buffer(&a.out, dst, 0, 16 * out.caps_at, 16 * 4 * a.drawn, &[])
                    .map_err(|e| Error::cl("clEnqueueCopyBuffer (adjacency caps)", e))?;
            }
        }
        out.kind = vec![0u32; ne];
        g.read(&self.kind, &mut out.kind)?;
        c.last_ms = ms + events.iter().map(event_ms).sum::<f64>();
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

impl Compactor {
    /// The compaction's kernels (of `kernels/edges.cl`), the flags of `ne`
    /// edge entries and room for one vertex.
    fn new(g: &Gpu, ne: usize) -> Result<Self> {
        let prog = g.program(&kernel_files::EDGES, "")?;
        Ok(Compactor {
            k_flags: g.entry(&prog, EdgesKernel::DrawnFlags)?,
            k_edges: g.entry(&prog, EdgesKernel::CompactEdges)?,
            slots: g.buffer(ne.max(1))?,
            ne,
            dst: g.buffer(4)?,
            dst_len: 1,
            last_ms: 0.0,
        })
    }

    /// `drawn_flags` and their scan into slots (where there are edges):
    /// returns the drawn edges and the scan's ms.
    fn drawn_flags(
        &self,
        g: &Gpu,
        scan: &mut Scan,
        kind: &Buffer<u32>,
        events: &mut Vec<Event>,
    ) -> Result<(usize, f64)> {
        let ne = self.ne;
        if ne == 0 {
            return Ok((0, 0.0));
        }
        let a = [Arg::U32(ne as u32), buf(kind), buf(&self.slots)];
        events.extend(launch(g, &self.k_flags, ne, &a)?);
        let drawn = scan.exclusive_at(&self.slots, &self.slots, ne, &[])?.0 as usize;
        Ok((drawn, scan.last_ms()))
    }

    /// `compact_edges` per source (`per` vertices per edge), each after the
    /// last in `dst`, when `drawn` edges were drawn: returns each source's
    /// first vertex and vertex count (none when nothing was drawn).
    fn compact_edges(
        &self,
        g: &Gpu,
        kind: &Buffer<u32>,
        srcs: &[(&Buffer<f32>, u32)],
        drawn: usize,
        dst: Arg,
        events: &mut Vec<Event>,
    ) -> Result<Vec<(usize, usize)>> {
        let ne = self.ne;
        let mut parts = Vec::new();
        if drawn == 0 {
            return Ok(parts);
        }
        let mut at_v = 0usize;
        for &(src, per) in srcs {
            events.extend(launch(
                g,
                &self.k_edges,
                ne,
                &[
                    Arg::U32(ne as u32),
                    Arg::U32(per),
                    buf(src),
                    buf(kind),
                    buf(&self.slots),
                    Arg::U32(at_v as u32),
                    dst,
                ],
            )?);
            parts.push((at_v, per as usize * drawn));
            at_v += per as usize * drawn;
        }
        Ok(parts)
    }
}

/// The half-cap buffers when the last run (`mode`) drew McGuire-Hughes caps.
fn half_caps(
    mode: CapMode,
    cap_mh: &Option<[Buffer<f32>; 2]>,
) -> Option<(&Buffer<f32>, &Buffer<f32>)> {
    match (mode, cap_mh) {
        (CapMode::Mh, Some([m0, m1])) => Some((m0, m1)),
        _ => None,
    }
}

/// What the compaction copies, with its vertices per edge: edge-out, then
/// the half-caps `mh` where there are some.
fn drawn_sources<'a>(
    edge_out: &'a Buffer<f32>,
    mh: Option<(&'a Buffer<f32>, &'a Buffer<f32>)>,
) -> Vec<(&'a Buffer<f32>, u32)> {
    let mut srcs = vec![(edge_out, 4)];
    if let Some((m0, m1)) = mh {
        srcs.push((m0, 3));
        srcs.push((m1, 3));
    }
    srcs
}

/// Vertices read back, 4 floats each.
type Float4s = Vec<[f32; 4]>;

/// Reads `kind` (device buffer, host slice) and the compacted `parts` of
/// `dst` (first vertex, vertices) back, with the drawn adjacency caps of
/// `adj`; all reads are enqueued, then one wait.
fn read_compacted(
    g: &Gpu,
    kind: (&Buffer<u32>, &mut [u32]),
    dst: &Buffer<f32>,
    parts: &[(usize, usize)],
    adj: Option<&AdjacencyCaps>,
) -> Result<(Vec<Float4s>, Float4s)> {
    let mut vecs: Vec<Vec<[f32; 4]>> = parts.iter().map(|p| vec![[0f32; 4]; p.1]).collect();
    let mut caps = vec![[0f32; 4]; adj.map_or(0, |a| 4 * a.drawn)];
    // SAFETY: `kind`, `vecs` and `caps` are neither moved nor read until
    // `finish` below, which also runs on the error path; the ranges lie
    // inside the buffers (parts are within the vertices `dst` holds, the
    // caps within the drawn caps' room).
    let failed = unsafe {
        let mut reads = vec![g.read_at_async(kind.0, 0, kind.1)];
        for (v, p) in vecs.iter_mut().zip(parts) {
            reads.push(g.read_at_async(dst, 4 * p.0, bytemuck::cast_slice_mut(v)));
        }
        if let Some(a) = adj {
            reads.push(g.read_at_async(&a.out, 0, bytemuck::cast_slice_mut(&mut caps)));
        }
        reads.into_iter().find_map(|r| r.err())
    };
    let done = g.finish();
    if let Some(e) = failed {
        return Err(e);
    }
    done?;
    Ok((vecs, caps))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::edges::EdgeParamBlock;

    /// The kernel's `EdgeParams` has the layout of [`EdgeParamBlock`]: a probe
    /// kernel appended to `kernels/edges.cl` writes `sizeof` and every
    /// `offsetof` as the device compiler sees them.
    #[test]
    fn param_block_layout_matches_the_kernel() {
        let fields = EdgeParamBlock::field_offsets();
        let exprs: Vec<String> = (fields.iter())
            .map(|(name, _)| match name.starts_with('(') {
                true => "sizeof(EdgeParams)".to_string(),
                false => format!("__builtin_offsetof(EdgeParams, {name})"),
            })
            .collect();
        let got =
            crate::gpu::probe_layout(&kernel_files::EDGES, "", EdgesKernel::ProbeLayout, &exprs);
        for ((name, want), got) in fields.iter().zip(got) {
            assert_eq!(got as usize, *want, "{name}: device vs Rust");
        }
    }
}
