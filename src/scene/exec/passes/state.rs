//! The executor's state, one value per lifetime (geometry-central's way of
//! keeping quantities): what lives for the whole run (the stages built for
//! it, the framing and the totals), per topology ([`super::TopologyState`]), per
//! pose and per view. A new pose or view replaces its value whole, so
//! nothing is reset field by field; and what a run keeps for its caller is
//! a set of outputs the caller gives ([`Keep`]), not flags on the executor.

use super::super::draw::PoseData;
use super::super::vector::VisibleLines;
use super::Framing;
use crate::spec::curvature::CurvatureOptions;
use crate::spec::edges::EdgeOutput;
use crate::spec::feature_lines::{Segment, ViewFields};
use crate::spec::interop::{InteropDecision, InteropOffer};
use crate::spec::sdf_lines::SdfLinesOutput;
use crate::spec::timing::Timing;
use crate::stages::ao::AoStage;
use crate::stages::edges::SharedDrawn;
use crate::stages::feature_lines::LineOptions;
use crate::stages::marching_cubes::Isosurfacer;
use crate::stages::pipeline::PosePipeline;
use crate::stages::sdf_lines::SdfLines;
use std::path::PathBuf;

/// The stages and options built once for the run (only those the plan
/// needs).
pub(super) struct RunStages {
    pub(super) curv_opts: CurvatureOptions,
    pub(super) line_opts: LineOptions,
    /// Skinning, curvature and AO of a skinned input.
    pub(super) pipe: Option<PosePipeline>,
    pub(super) iso: Option<Isosurfacer>,
    /// AO of an unskinned input.
    pub(super) ao: Option<AoStage>,
    /// Curvature-directed strokes of a volume input, and its voxel size.
    pub(super) sdf_lines: Option<(SdfLines, f64)>,
    /// How the edges frame's buffers reach GL, and what was offered
    /// (decided once, when feature edges are planned).
    pub(super) interop: Option<(InteropDecision, InteropOffer)>,
}

/// What the run fixes on its first pose and counts over all of them.
#[derive(Default)]
pub(in crate::scene::exec) struct RunState {
    pub(super) framing: Option<Framing>,
    pub(super) color_scale: Option<f32>,
    /// Strokes over all poses.
    pub(in crate::scene::exec) stroke_count: usize,
    /// What the line families' thresholds were scaled by, for the run's
    /// notes (the first topology's).
    pub(in crate::scene::exec) feature_size_note: Option<String>,
    /// Visible chains and their pieces over all views.
    pub(in crate::scene::exec) chains: [usize; 2],
    /// Contour and suggestive-contour segments over all views.
    pub(in crate::scene::exec) segments: [usize; 2],
    /// Segments of each curvature line cue's family over all views.
    pub(in crate::scene::exec) line_segments: std::collections::BTreeMap<&'static str, usize>,
    /// Files written.
    pub(in crate::scene::exec) outputs: Vec<PathBuf>,
    /// The hysteresis' lower threshold where the lines were held over the
    /// frames.
    pub(in crate::scene::exec) held_low: Option<f32>,
    /// Per camera, the chain ids of its last frame, where the lines are
    /// held over the frames.
    pub(in crate::scene::exec) chain_ids:
        std::collections::HashMap<usize, crate::spec::coherence::ChainIds>,
}

/// One pose: its host copies and what its passes made.
#[derive(Default)]
pub(super) struct PoseState {
    /// The host copies (positions, normals, curvature, AO).
    pub(super) host: PoseData,
    /// A flipbook frame's positions.
    pub(super) frame_pos: Option<Vec<[f64; 3]>>,
    /// The curvature run (normals, curvature, dcurv steps).
    pub(super) curv: Option<Timing>,
    /// Whether the host copies are made.
    pub(super) ready: bool,
    /// Whether the renderer holds this pose's positions, normals and
    /// colours (uploaded by the first view).
    pub(super) gl: bool,
    /// The strokes run (seeds, strokes in world units, stats).
    pub(super) strokes: SdfLinesOutput,
    /// An isosurface's unit normals from the volume gradient (when normals
    /// are planned without curvature).
    pub(super) iso_normals: Option<Vec<[f32; 3]>>,
    /// Its intersection lines (scene frame).
    pub(super) isect_segs: Vec<Segment>,
}

/// One view: its lines, their visibility and what was drawn.
#[derive(Default)]
pub(super) struct ViewState {
    /// What the edge stage compacted into the shared buffer.
    pub(super) shared_drawn: Option<SharedDrawn>,
    /// Its lines classified and chained (exact visibility).
    pub(super) vis: Option<VisibleLines>,
    /// Its per-vertex fields, where the plan keeps them.
    pub(super) fields: Option<ViewFields>,
    /// The frame drawn.
    pub(super) frame: Option<crate::render::Frame>,
    /// The SVG groups found.
    pub(super) layers: Option<Vec<crate::export::svg::SvgLayer>>,
    /// The lines.
    pub(super) segs: Vec<Segment>,
    /// The line stage's run.
    pub(super) lines_ran: Option<Timing>,
    /// The edge stage's run and outputs.
    pub(super) edges_ran: Option<(Timing, EdgeOutput)>,
    /// The pieces as NPZ arrays (world coordinates), where the NPZ pass ran.
    pub(super) npz: Option<super::super::draw::PosedPieces>,
}

/// What a caller keeps of each view in memory instead of (or besides) the
/// files the plan writes: the outputs it asks for.
#[derive(Clone, Copy, Debug, Default)]
pub(in crate::scene::exec) struct Keep {
    /// The view's outputs in [`super::Executor::kept`] (a live scene or a
    /// picture hands them to its caller instead of writing a PNG).
    pub(in crate::scene::exec) image: bool,
    /// Also the view's surface (world coordinates).
    pub(in crate::scene::exec) mesh: bool,
    /// Also the view's SVG groups.
    pub(in crate::scene::exec) layers: bool,
}
