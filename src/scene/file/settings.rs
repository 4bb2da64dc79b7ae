//! The scene tables that set how things are computed rather than which cues
//! run: `[curvature]` (the estimator's scheme, precision and least squares)
//! and `[lines]` (the feature size, tests and Hermite placement every line
//! family shares).
//!
//! ```toml
//! [curvature]
//! accumulate = "gather"      # atomic | atomic-native | gather
//! precision = "f32"          # f32 | f64
//! compat = "trimesh2"        # exact | trimesh2 (default: trimesh2's where
//!                            # one of rtsc's line families is drawn, as rtsc)
//!
//! [lines]
//! feature_size = "rtsc"      # rtsc | edge | a length
//! test = true                # rtsc's tests
//! hermite = false            # rtsc's Hermite placement of suggestive lines
//! hermite_kh = false         # the same for K = 0 and H = 0
//! coherence = "auto"         # auto | on | off: hysteresis over an
//!                            # animation's frames (auto: on for more than one)
//! coherence_low = 0.5        # its lower threshold, a fraction of each threshold
//! coherence_birth = 1        # frames a new line waits before it is drawn
//! coherence_band = 0.1       # K, H and emax keep their sign within band/s², band/s
//! ```

use super::raw::{CurvatureSpec, LinesSpec};
use super::{Checker, Effects};
use crate::error::{Error, Result};
use crate::spec::curvature::CurvatureOptions;
use toml::Spanned;

/// `[curvature]`, over the defaults (the least squares by
/// [`crate::spec::curvature::Compat::default_for`]: trimesh2's where the
/// scene draws one of rtsc's line families, `rtsc_lines`).
pub(super) fn curvature(
    ck: &Checker<'_>,
    c: &CurvatureSpec,
    rtsc_lines: bool,
) -> Result<CurvatureOptions> {
    fn pick<T: std::str::FromStr<Err = Error>>(
        ck: &Checker<'_>,
        v: &Option<Spanned<String>>,
        into: &mut T,
    ) -> Result<()> {
        if let Some(v) = v {
            *into = v
                .get_ref()
                .parse()
                .map_err(|x: Error| ck.err(v.span(), format!("curvature: {x}")))?;
        }
        Ok(())
    }
    let mut o = CurvatureOptions {
        compat: crate::spec::curvature::Compat::default_for(rtsc_lines),
        ..CurvatureOptions::default()
    };
    pick(ck, &c.accumulate, &mut o.accumulate)?;
    pick(ck, &c.precision, &mut o.precision)?;
    pick(ck, &c.compat, &mut o.compat)?;
    Ok(o)
}

/// Refuses `[curvature] precision = "f64"` (at `span`) where a cue reads
/// the curvature on the device: the line families and ambient occlusion
/// take the estimator's buffers as they are, in f32.
pub(super) fn check_precision(
    ck: &Checker<'_>,
    span: std::ops::Range<usize>,
    o: &CurvatureOptions,
    fx: &Effects,
    input: crate::scene::planner::Input,
) -> Result<()> {
    use crate::scene::planner::{Outputs, Pass, plan_for};
    use crate::spec::curvature::Precision;
    if o.precision != Precision::F64 {
        return Ok(());
    }
    let plan = plan_for(&fx.cues, input, fx.caps, Outputs::RASTER);
    let chained = [
        Pass::Ao,
        Pass::Contours,
        Pass::SuggestiveContours,
        Pass::LinesPose,
        Pass::LinesView,
        Pass::LinesCurves,
    ];
    if plan.contains(Pass::Curvature) && chained.iter().any(|&p| plan.contains(p)) {
        return Err(ck.err(
            span,
            "curvature.precision = \"f64\": the line families and ambient occlusion read the \
             curvature on the device in f32; give precision = \"f32\" (the default) for these \
             cues",
        ));
    }
    Ok(())
}

/// `[lines]`, into the effects.
pub(super) fn lines(ck: &Checker<'_>, l: &Spanned<LinesSpec>, fx: &mut Effects) -> Result<()> {
    let span = l.span();
    let l = l.get_ref();
    if let Some(v) = &l.feature_size {
        let text = match v {
            toml::Value::String(s) => s.clone(),
            toml::Value::Float(x) => x.to_string(),
            toml::Value::Integer(i) => i.to_string(),
            other => other.to_string(),
        };
        fx.feature_size = text
            .parse()
            .map_err(|x: Error| ck.err(span.clone(), format!("lines.feature_size: {x}")))?;
    }
    let c = &mut fx.lines.curves;
    c.test = l.test.unwrap_or(c.test);
    c.hermite = l.hermite.unwrap_or(c.hermite);
    c.hermite_kh = l.hermite_kh.unwrap_or(c.hermite_kh);
    if let Some(m) = &l.coherence {
        fx.lines.coherence = (m.get_ref().parse())
            .map_err(|e: Error| ck.err(m.span(), format!("lines.coherence: {e}")))?;
    }
    let fl = &mut fx.lines;
    fl.coherence_low = l.coherence_low.unwrap_or(fl.coherence_low);
    fl.coherence_birth = l.coherence_birth.unwrap_or(fl.coherence_birth);
    fl.coherence_band = l.coherence_band.unwrap_or(fl.coherence_band);
    crate::spec::coherence::check(fl.coherence_low, fl.coherence_birth, fl.coherence_band)
        .map_err(|e| ck.err(span, format!("lines.{e}")))?;
    Ok(())
}
