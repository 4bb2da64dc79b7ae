//! Which kernel entry point each timing step is ([`Step::kernel`]): the
//! one place that names every family's kernel enum. It sits apart from
//! `timing.rs` so that the families, whose outputs carry a
//! [`Timing`](super::timing::Timing), and the timing type do not import
//! each other.

use super::ao::AoKernel;
use super::bvh::BvhKernel;
use super::curvature::CurvKernel;
use super::edges::EdgesKernel;
use super::feature_lines::{LinesCurvesKernel, LinesKernel};
use super::intersections::IsectKernel;
use super::marching_cubes::McKernel;
use super::mesh_sdf::MsdfKernel;
use super::sdf_lines::SdflKernel;
use super::skinning::SkinKernel;
use super::timing::Step;
use super::vertex_fusion::FuseKernel;

impl Step {
    /// The kernel entry point (`<prefix>_<step>`), or for a sub-stage call
    /// the host entry point (`scan_exclusive`, `radix_sort_pairs`).
    pub fn kernel(self) -> &'static str {
        match self {
            Step::CurvMaxFace => CurvKernel::MaxFace.name(),
            Step::CurvClear => CurvKernel::Clear.name(),
            Step::CurvNormalsAreas => CurvKernel::NormalsAreas.name(),
            Step::CurvFrames => CurvKernel::Frames.name(),
            Step::CurvTensor => CurvKernel::Tensor.name(),
            Step::CurvPrincipal => CurvKernel::Principal.name(),
            Step::CurvDcurv => CurvKernel::Dcurv.name(),
            Step::McClassify => McKernel::Classify.name(),
            Step::McTriangles => McKernel::Triangles.name(),
            Step::McIota => McKernel::Iota.name(),
            Step::McDirectRows => McKernel::DirectRows.name(),
            Step::McDirectCount => McKernel::DirectCount.name(),
            Step::McDirectHits => McKernel::DirectHits.name(),
            Step::McDirectTriangles => McKernel::DirectTriangles.name(),
            Step::McDirectPoints => McKernel::DirectPoints.name(),
            Step::McDirectRecount => McKernel::DirectRecount.name(),
            Step::McDirectUnused => McKernel::DirectUnusedMark.name(),
            Step::McGradientNormals => McKernel::GradientNormals.name(),
            Step::FuseIndex => FuseKernel::Index.name(),
            Step::FuseTriangles => FuseKernel::Triangles.name(),
            Step::FuseCandidates => FuseKernel::Candidates.name(),
            Step::FuseCancel => FuseKernel::Cancel.name(),
            Step::FuseMark => FuseKernel::Mark.name(),
            Step::FuseCompactVertices => FuseKernel::CompactVertices.name(),
            Step::FuseCompactFaces => FuseKernel::CompactFaces.name(),
            Step::ScanExclusive => "scan_exclusive",
            Step::RadixSortPairs => "radix_sort_pairs",
            Step::EdgesDetect => EdgesKernel::Detect.name(),
            Step::CapsMh => EdgesKernel::CapsMh.name(),
            Step::CapsAdjacency => EdgesKernel::CapsAdjacency.name(),
            Step::EdgesCompact => "edges_compact",
            Step::SkinLbs => SkinKernel::Lbs.name(),
            Step::LinesVertex => LinesKernel::Vertex.name(),
            Step::LinesFace => LinesKernel::Face.name(),
            Step::LinesPose => LinesCurvesKernel::Pose.name(),
            Step::LinesView => LinesCurvesKernel::View.name(),
            Step::LinesDt1q1 => LinesCurvesKernel::Dt1q1.name(),
            Step::LinesCurves => LinesCurvesKernel::Curves.name(),
            Step::AoVertex => AoKernel::Vertex.name(),
            Step::SdflDense => SdflKernel::Dense.name(),
            Step::SdflThin => SdflKernel::ThinPhase.name(),
            Step::SdflGradient => SdflKernel::Gradient.name(),
            Step::SdflCurvature => SdflKernel::Curvature.name(),
            Step::SdflRange => SdflKernel::Range.name(),
            Step::SdflTrace => SdflKernel::Trace.name(),
            Step::SdflStrips => SdflKernel::Strips.name(),
            Step::SdflSweep => "sdfl_sweep",
            Step::MsdfBand => MsdfKernel::BandMin.name(),
            Step::MsdfJfa => MsdfKernel::Jfa.name(),
            Step::MsdfRefine => MsdfKernel::Refine.name(),
            Step::MsdfSign => MsdfKernel::Wind.name(),
            Step::MsdfFinish => MsdfKernel::Finish.name(),
            Step::BvhMorton => BvhKernel::Morton.name(),
            Step::BvhBuild => BvhKernel::Build.name(),
            Step::BvhRefit => BvhKernel::Refit.name(),
            Step::BvhOccluded => BvhKernel::Occluded.name(),
            Step::IsectFind => IsectKernel::Find.name(),
        }
    }
}
