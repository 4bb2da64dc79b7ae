//! Shared types of the `edges` family (House & Li, "Real-Time Object-Space
//! Edge Detection using OpenCL", after McGuire & Hughes 2004): the cap
//! variants, the kind bits, the per-frame parameter block that crosses to
//! `kernels/edges.cl`, the output type, the `*_bound` sizes of every output
//! and the memory each variant uses. Used by the host wiring
//! (`stages::edges`), the CPU twin (`cpu::edges`), the
//! scene planner and file, the renderer's edge drawing and the CLI.
//!
//! The conventions of detection (contour, crease, boundary, half quads,
//! width, near plane, marker) are documented in `stages::edges`.

use bytemuck::{Pod, Zeroable};
use serde::Serialize;

use crate::error::{Error, Result};
use crate::spec::view::View;

/// Kind bit: contour edge.
pub const KIND_CONTOUR: u32 = 1;
/// Kind bit: crease edge.
pub const KIND_CREASE: u32 = 2;
/// Kind bit: boundary or marked edge.
pub const KIND_BOUNDARY: u32 = 4;
/// Kind bit: the edge was detected and written as a quad.
pub const KIND_DRAWN: u32 = 8;

/// The degenerate vertex `(NaN, 0, −1, 1)` written for every vertex of an
/// undrawn quad, triangle or cap.
pub const MARKER: [f32; 4] = [f32::NAN, 0.0, -1.0, 1.0];

/// Number of floats in the per-frame parameter block ([`EdgeParamBlock`]).
pub const PARAMS_LEN: usize = 32;

/// How the gaps between thick edges are filled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CapMode {
    /// No caps.
    None,
    /// McGuire-Hughes half-caps from the projected vertex normals.
    Mh,
    /// House & Li adjacency caps from the middle vector of connected edges.
    Adjacency,
}

impl CapMode {
    /// All variants, in the order of tables and benches.
    pub const ALL: [CapMode; 3] = [CapMode::None, CapMode::Mh, CapMode::Adjacency];

    /// The name used on the command line, in stats and bench groups.
    pub fn name(self) -> &'static str {
        match self {
            CapMode::None => "none",
            CapMode::Mh => "mh",
            CapMode::Adjacency => "adjacency",
        }
    }
}

crate::spec::choice!(CapMode);

impl std::str::FromStr for CapMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<CapMode> {
        CapMode::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                Error::InvalidArgument(format!(
                    "unknown cap mode {s:?}: expected none, mh or adjacency"
                ))
            })
    }
}

// The interop option and decision live in `spec::interop`; the edges
// frame is the first path that uses them, so they are named here too.
pub use crate::spec::interop::{
    InteropDecision, InteropMode, InteropOffer, InteropRoute, decide_interop,
};

/// The crease angle of a user's `degrees`: 180 or more finds no crease
/// (`None`), otherwise it must be in (0, 180).
///
/// # Errors
/// [`Error::InvalidArgument`] for 0, a negative angle or NaN.
pub fn crease_from_degrees(degrees: f32) -> Result<Option<f32>> {
    if degrees >= 180.0 {
        Ok(None)
    } else if degrees > 0.0 {
        Ok(Some(degrees))
    } else {
        Err(Error::InvalidArgument(format!(
            "edges: crease angle {degrees}° must be in (0, 180]"
        )))
    }
}

/// What `shapecue::feature_edges` (and its CPU twin `cpu::edges::feature_edges`)
/// detects and how wide it makes the quads: everything of [`EdgeParams`] but
/// the view, plus the cap variant and the marked edges.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeOptions {
    /// Cap variant.
    pub caps: CapMode,
    /// Line width in pixels (> 0).
    pub line_width: f32,
    /// Crease angle in degrees; 180 or more finds none ([`crease_from_degrees`]).
    pub crease_deg: f32,
    /// Detect contour edges.
    pub contours: bool,
    /// Draw boundary and marked edges.
    pub boundaries: bool,
    /// Depth scale k of the width factor max(1, k/w); `None`: constant width.
    pub depth_scale: Option<f32>,
    /// Contour-only edges as half quads, outward from the silhouette.
    pub half_contours: bool,
    /// Marked edges (vertex-index pairs), drawn like boundaries.
    pub marked: Vec<[u32; 2]>,
}

impl Default for EdgeOptions {
    fn default() -> Self {
        EdgeOptions {
            caps: CapMode::Adjacency,
            line_width: 4.0,
            crease_deg: 30.0,
            contours: true,
            boundaries: true,
            depth_scale: None,
            half_contours: false,
            marked: Vec::new(),
        }
    }
}

impl EdgeOptions {
    /// The per-frame parameters of these options seen through `view`.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a crease angle outside (0, 180].
    pub fn params(&self, view: View) -> Result<EdgeParams> {
        Ok(EdgeParams {
            view,
            line_width: self.line_width,
            crease_deg: crease_from_degrees(self.crease_deg)?,
            contours: self.contours,
            boundaries: self.boundaries,
            depth_scale: self.depth_scale,
            half_contours: self.half_contours,
        })
    }
}

/// The per-frame parameter block of `kernels/edges.cl`, mirrored there field
/// by field by `typedef struct { ... } EdgeParams` (same names, same order,
/// all 4-byte floats, so no padding on either side). A unit test in
/// `stages::edges` builds a probe kernel that reports `sizeof` and every
/// `offsetof` on the device and compares them with this struct.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EdgeParamBlock {
    /// World-to-clip matrix, column-major.
    pub view_proj: [f32; 16],
    /// Eye position.
    pub eye: [f32; 3],
    /// Unit view direction (eye towards target).
    pub view_dir: [f32; 3],
    /// 1 for an orthographic view, 0 for perspective.
    pub ortho: f32,
    /// Half the viewport width, pixels.
    pub half_vw: f32,
    /// Half the viewport height, pixels.
    pub half_vh: f32,
    /// Half the line width, pixels.
    pub half_width: f32,
    /// cos θ of the crease angle θ; −2 (never) without creases.
    pub cos_crease: f32,
    /// Depth scale k of the width factor max(1, k/w); 0: constant width.
    pub depth_k: f32,
    /// Clip w at or below which an edge end is behind the near plane (0 for
    /// orthographic views).
    pub w_min: f32,
    /// 1: detect contours.
    pub contours: f32,
    /// 1: draw boundary and marked edges.
    pub boundaries: f32,
    /// 1: contour-only edges as half quads.
    pub half_contours: f32,
}

const _: () = assert!(std::mem::size_of::<EdgeParamBlock>() == 4 * PARAMS_LEN);
const _: () = assert!(std::mem::align_of::<EdgeParamBlock>() == 4);

impl EdgeParamBlock {
    /// The block as the kernel's float buffer sees it.
    pub fn as_floats(&self) -> &[f32] {
        bytemuck::cast_slice(std::slice::from_ref(self))
    }

    /// Every `(name, byte offset)` of the block, in field order: what the
    /// probe kernel test compares with the device's `offsetof`.
    pub fn field_offsets() -> [(&'static str, usize); 14] {
        use std::mem::offset_of;
        [
            ("view_proj", offset_of!(Self, view_proj)),
            ("eye", offset_of!(Self, eye)),
            ("view_dir", offset_of!(Self, view_dir)),
            ("ortho", offset_of!(Self, ortho)),
            ("half_vw", offset_of!(Self, half_vw)),
            ("half_vh", offset_of!(Self, half_vh)),
            ("half_width", offset_of!(Self, half_width)),
            ("cos_crease", offset_of!(Self, cos_crease)),
            ("depth_k", offset_of!(Self, depth_k)),
            ("w_min", offset_of!(Self, w_min)),
            ("contours", offset_of!(Self, contours)),
            ("boundaries", offset_of!(Self, boundaries)),
            ("half_contours", offset_of!(Self, half_contours)),
            ("(size)", std::mem::size_of::<Self>()),
        ]
    }
}

/// What to detect and how to draw it, for one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeParams {
    /// The view (camera and viewport).
    pub view: View,
    /// Line width in pixels (> 0).
    pub line_width: f32,
    /// Crease angle θ in degrees, in (0, 180]; `None`: no crease edges.
    pub crease_deg: Option<f32>,
    /// Detect contour edges.
    pub contours: bool,
    /// Draw boundary and marked edges.
    pub boundaries: bool,
    /// Depth scale k of the width factor max(1, k/w); `None`: constant width.
    pub depth_scale: Option<f32>,
    /// Draw contour-only edges as half quads, from the edge outward by the
    /// full width (outward: the side of the projected vertex normal).
    pub half_contours: bool,
}

impl EdgeParams {
    /// Defaults for a view: width 4, crease 30°, contours and boundaries on.
    pub fn new(view: View) -> EdgeParams {
        EdgeParams {
            view,
            line_width: 4.0,
            crease_deg: Some(30.0),
            contours: true,
            boundaries: true,
            depth_scale: None,
            half_contours: false,
        }
    }

    /// Checks the parameters and packs the kernel's parameter block.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a bad view (NaN, eye == target, an
    /// empty viewport, ...; see [`View::check`]), a width that is not a
    /// positive finite number, a crease angle outside (0, 180] or a negative
    /// or non-finite depth scale.
    pub fn pack(&self) -> Result<EdgeParamBlock> {
        let v = &self.view;
        v.check("edges")?;
        if !(self.line_width.is_finite() && self.line_width > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "edges: line width {} must be a positive number of pixels",
                self.line_width
            )));
        }
        let cos_crease = match self.crease_deg {
            None => -2.0, // never: na·nb ≥ −|na||nb|
            Some(d) if d > 0.0 && d <= 180.0 => d.to_radians().cos(),
            Some(d) => {
                return Err(Error::InvalidArgument(format!(
                    "edges: crease angle {d}° must be in (0, 180]"
                )));
            }
        };
        let depth_k = match self.depth_scale {
            None => 0.0,
            Some(k) if k >= 0.0 && k.is_finite() => k,
            Some(k) => {
                return Err(Error::InvalidArgument(format!(
                    "edges: depth scale {k} must be a finite number ≥ 0"
                )));
            }
        };
        let flag = |b: bool| b as u32 as f32;
        let p = EdgeParamBlock {
            view_proj: v.view_proj.to_cols_array(),
            eye: v.eye.to_array(),
            view_dir: v.unit_dir().to_array(),
            ortho: flag(v.ortho),
            half_vw: 0.5 * v.width as f32,
            half_vh: 0.5 * v.height as f32,
            half_width: 0.5 * self.line_width,
            cos_crease,
            depth_k,
            w_min: if v.ortho { 0.0 } else { v.near },
            contours: flag(self.contours),
            boundaries: flag(self.boundaries),
            half_contours: flag(self.half_contours),
        };
        if p.as_floats().iter().any(|x| !x.is_finite()) {
            return Err(Error::InvalidArgument(
                "edges: the camera gives a non-finite view-projection matrix".into(),
            ));
        }
        Ok(p)
    }
}

/// The stage's outputs read back to the host.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EdgeOutput {
    /// 4 vertices per edge (House & Li's edge-out buffer).
    pub edge_out: Vec<[f32; 4]>,
    /// Kind bits per edge (`KIND_*`).
    pub kind: Vec<u32>,
    /// McGuire-Hughes half-caps at the i0 end (3 vertices per edge); empty unless `Mh`.
    pub cap_mh0: Vec<[f32; 4]>,
    /// McGuire-Hughes half-caps at the i1 end; empty unless `Mh`.
    pub cap_mh1: Vec<[f32; 4]>,
    /// Adjacency caps (4 vertices per cap pair); empty unless `Adjacency`.
    pub cap_adj: Vec<[f32; 4]>,
}

impl EdgeOutput {
    /// Edges whose kind has `bit` set.
    pub fn count(&self, bit: u32) -> usize {
        self.kind.iter().filter(|&&k| k & bit != 0).count()
    }
}

/// Vertices (float4) of the edge-out buffer for `edges` edge entries: one
/// quad per edge, indexed by edge (never appended).
pub fn edge_out_bound(edges: usize) -> usize {
    4 * edges
}

/// Vertices (float4) of *each* McGuire-Hughes cap-out buffer (one per edge
/// end) for `edges` edge entries: one triangle per edge.
pub fn cap_mh_bound(edges: usize) -> usize {
    3 * edges
}

/// Vertices (float4) of the adjacency cap-out for `caps` cap pairs when
/// every pair draws a cap: one quad per pair. The device holds only the caps
/// a view draws (in pair order); [`EdgeOutput`] from a full read has this
/// many, undrawn pairs as the marker.
pub fn cap_adjacency_bound(caps: usize) -> usize {
    4 * caps
}

/// Bits of device memory the edges stage uses for one mesh, from the actual
/// buffer sizes (House & Li's memory table; inputs already on the GPU for
/// rendering, positions and normals, are not counted).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct MemoryUse {
    /// Edge entries.
    pub edges: usize,
    /// Cap pairs.
    pub caps: usize,
    /// Edge buffer + edge-out + kind bits.
    pub edge_bits: u64,
    /// Cap-related bits of the variant: the half-cap buffers; or the cap
    /// buffer, the slot per cap pair and the cap-out of the drawn caps, here
    /// at its bound (every pair drawn; a view draws far fewer).
    pub cap_bits: u64,
}

/// Memory of the variant `mode` for `edges` edge entries and `caps` cap pairs.
pub fn memory_use(mode: CapMode, edges: usize, caps: usize) -> MemoryUse {
    let (e, c) = (edges as u64, caps as u64);
    let f4 = |n: usize| 4 * n as u64; // floats of n float4 vertices
    // edges uint[4E], edge_out float[16E], kind uint[E]
    let edge_bits = 32 * (4 * e + f4(edge_out_bound(edges)) + e);
    let cap_bits = match mode {
        CapMode::None => 0,
        CapMode::Mh => 32 * (2 * f4(cap_mh_bound(edges))),
        // caps uint[2C], cap_slot uint[C], cap_adj float[16K] with K ≤ C
        CapMode::Adjacency => 32 * (3 * c + f4(cap_adjacency_bound(caps))),
    };
    MemoryUse {
        edges,
        caps,
        edge_bits,
        cap_bits,
    }
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/edges.cl`.
    pub enum EdgesKernel {
        /// Contour, crease and boundary tests of each edge into edge-out.
        Detect = "edges_detect",
        /// McGuire-Hughes half-caps.
        CapsMh = "caps_mh",
        /// Which cap pairs a view draws (scanned into slots).
        CapsAdjacencyFlags = "caps_adjacency_flags",
        /// House & Li adjacency caps of the flagged pairs.
        CapsAdjacency = "caps_adjacency",
        /// Which edge-out entries are drawn (for the compacted read-back).
        DrawnFlags = "drawn_flags",
        /// The drawn edges, compacted.
        CompactEdges = "compact_edges",
        /// Sizes and offsets of the parameter struct on the device (a probe source appended by the layout test).
        ProbeLayout = "edges_probe_layout",
    }
}
