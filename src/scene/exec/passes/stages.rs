//! The stages a run builds once, each only where the plan holds its
//! passes: the line extractor's options, the skinning pipeline, the
//! isosurfacer and the curvature-directed strokes.

use super::super::load::Loaded;
use crate::error::Result;
use crate::gpu::Gpu;
use crate::scene::file::Scene;
use crate::scene::planner::{Pass, Plan};
use crate::spec::curvature::CurvatureOptions;
use crate::spec::sdf_lines::{Inside, SdfLineOptions};
use crate::stages::feature_lines::LineOptions;
use crate::stages::marching_cubes::Isosurfacer;
use crate::stages::pipeline::{PipelineOptions, PipelineStages, PosePipeline};
use crate::stages::sdf_lines::SdfLines;
use std::sync::Arc;

/// The line extractor's options: the contour families and the curvature
/// line cues' families and controls the plan holds.
pub(super) fn line_options(scene: &Scene, plan: &Plan) -> LineOptions {
    let fx = &scene.effects;
    LineOptions {
        contours: plan.contains(Pass::Contours),
        suggestive: plan.contains(Pass::SuggestiveContours),
        threshold: fx.suggestive_threshold,
        fade: fx.suggestive_fade,
        // The curvature line cues' families and controls.
        curves: fx.lines.curves_for(&fx.cues),
    }
}

/// The skinning pipeline of a skinned input (skinning, and curvature and
/// AO where planned); none for other inputs.
pub(super) fn skinning_pipeline(
    loaded: &Loaded,
    plan: &Plan,
    gpu: &Arc<Gpu>,
    scene: &Scene,
    curv_opts: CurvatureOptions,
) -> Result<Option<PosePipeline>> {
    let has = |p: Pass| plan.contains(p);
    Ok(match loaded {
        Loaded::Skinned { mesh, .. } if has(Pass::Skinning) => Some(PosePipeline::with_stages(
            gpu.clone(),
            mesh,
            PipelineOptions {
                curvature: curv_opts,
                ao_mode: scene.effects.ao_mode,
                ..PipelineOptions::default()
            },
            PipelineStages {
                curvature: has(Pass::OneRings),
                ao: has(Pass::Ao),
                // The lines are per topology for every input (contours
                // alone are found from host normals, without curvature).
                lines: false,
            },
        )?),
        _ => None,
    })
}

/// The isosurfacer of a volume input, when the isosurface is planned.
pub(super) fn isosurfacer(
    loaded: &Loaded,
    plan: &Plan,
    gpu: &Arc<Gpu>,
) -> Result<Option<Isosurfacer>> {
    Ok(match loaded {
        Loaded::Volume(v, ..) if plan.contains(Pass::Isosurface) => {
            Some(Isosurfacer::new(gpu.clone(), v)?)
        }
        _ => None,
    })
}

/// The curvature-directed strokes stage of a volume input and its voxel
/// size, when the strokes are planned.
pub(super) fn strokes_stage(
    loaded: &Loaded,
    plan: &Plan,
    gpu: &Arc<Gpu>,
    scene: &Scene,
) -> Result<Option<(SdfLines, f64)>> {
    Ok(match loaded {
        Loaded::Volume(v, iso, _) if plan.contains(Pass::SdfLines) => {
            let st = &scene.effects.strokes;
            // The loader negated an `above` volume: inside is below iso.
            let opts = SdfLineOptions {
                iso: *iso,
                inside: Inside::Below,
                sampling: st.sampling.clone(),
                spacing: st.spacing,
                width: st.width,
                ..SdfLineOptions::default()
            };
            let voxel = crate::spec::sdf_lines::voxel_size(v.spacing);
            Some((SdfLines::new(gpu.clone(), v, &opts)?, voxel))
        }
        _ => None,
    })
}
