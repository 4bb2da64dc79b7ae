//! `[effects]` checked: each cue's table resolved into [`Effects`] with its
//! defaults, the cues collected in table order, and checked against the
//! input. Errors without a key of their own name the `[effects]` line.

use super::raw::{EdgeSpec, EffectsSpec, SamplingSpec, StrokeSpec};
use super::{Checker, Effects, StrokeEffect, Table, color, lines, positive};
use crate::error::{Error, Result};
use crate::scene::planner::{Cue, Input};
use crate::spec::ao::AoMode;
use crate::spec::edges::CapMode;
use crate::spec::feature_lines::FeatureSize;
use crate::spec::sdf_lines::Sampling;
use toml::Spanned;

/// Checks `[effects]` for an `input` source whose key is `kind`.
pub(super) fn resolve(
    ck: &Checker<'_>,
    effects: Spanned<EffectsSpec>,
    input: Input,
    kind: &str,
) -> Result<Effects> {
    let span = effects.span();
    let fx = effects.into_inner();
    let t = Table { ck, span };
    let mut cues = Vec::new();
    let (base_color, ambient) = t.shading(&fx, &mut cues)?;
    let curvature_scale = t.curvature_colors(&fx, &mut cues)?;
    let (ao_mode, ao_radius) = t.ao(&fx, &mut cues)?;
    let contour = t.contours(&fx, &mut cues)?;
    let sc = t.suggestive(&fx, &mut cues)?;
    let fe = t.feature_edges(&fx, &mut cues)?;
    let intersection = t.intersection_lines(&fx, &mut cues)?;
    let strokes = t.strokes(&fx, &mut cues)?;
    let lines = lines::resolve(&fx, &mut cues).map_err(|p| t.err(p))?;
    t.check_cues(&cues, input, kind)?;
    Ok(Effects {
        cues,
        base_color,
        ambient,
        curvature_scale,
        ao_mode,
        ao_radius,
        contour,
        suggestive: sc.style,
        intersection,
        suggestive_threshold: sc.threshold,
        suggestive_fade: sc.fade,
        edge: fe.style,
        crease: fe.crease,
        caps: fe.caps,
        edge_contours: fe.contours,
        edge_boundaries: fe.boundaries,
        edge_depth_scale: fe.depth_scale,
        edge_half_contours: fe.half_contours,
        edge_marked: fe.marked,
        strokes,
        lines,
        feature_size: FeatureSize::default(),
    })
}

/// A stroke's width and colour.
type Style = (f32, [f32; 3]);

/// `suggestive_contours`, resolved.
struct Suggestive {
    /// Width and colour.
    style: Style,
    /// rtsc's `sug_thresh`.
    threshold: f32,
    /// rtsc's fade (0: none).
    fade: f32,
}

/// `feature_edges`, resolved.
struct FeatureEdges {
    /// Width and colour.
    style: Style,
    /// Crease angle in degrees (`None`: off).
    crease: Option<f32>,
    /// Caps.
    caps: CapMode,
    /// Edge contours.
    contours: bool,
    /// Edge boundaries.
    boundaries: bool,
    /// Depth scale of the width.
    depth_scale: Option<f32>,
    /// Half-quad contours.
    half_contours: bool,
    /// The marked edges' file.
    marked: Option<std::path::PathBuf>,
}

impl Table<'_> {
    /// `shading`: the base colour and ambient term.
    fn shading(&self, fx: &EffectsSpec, cues: &mut Vec<Cue>) -> Result<([f32; 3], f32)> {
        let shading = fx.shading.clone().unwrap_or_default();
        if fx.shading.is_some() {
            cues.push(Cue::Shading);
        }
        let base_color =
            color(shading.color, [0.82, 0.82, 0.8], "shading.color").map_err(|p| self.err(p))?;
        let ambient = shading.ambient.unwrap_or(0.15);
        if !(0.0..=1.0).contains(&ambient) {
            return Err(self.err(format!("shading.ambient {ambient} must be in [0, 1]")));
        }
        Ok((base_color, ambient))
    }

    /// `curvature_colors`: the colour scale (`None`: from the first pose).
    fn curvature_colors(&self, fx: &EffectsSpec, cues: &mut Vec<Cue>) -> Result<Option<f32>> {
        let Some(c) = &fx.curvature_colors else {
            return Ok(None);
        };
        cues.push(Cue::CurvatureColors);
        c.scale
            .map(|s| positive(Some(s), 1.0, "curvature_colors.scale").map_err(|p| self.err(p)))
            .transpose()
    }

    /// `ao`: the level and radius.
    fn ao(&self, fx: &EffectsSpec, cues: &mut Vec<Cue>) -> Result<(AoMode, f32)> {
        let Some(a) = &fx.ao else {
            return Ok((AoMode::Lut, 0.02));
        };
        cues.push(Cue::AmbientOcclusion);
        let mut mode = AoMode::Lut;
        if let Some(l) = &a.level {
            mode = match l.get_ref().as_str() {
                "poly" => AoMode::Poly,
                "lut" => AoMode::Lut,
                "exact" => AoMode::Exact,
                other => {
                    return Err(self.ck.err(
                        l.span(),
                        format!("ao.level {other:?}: expected poly, lut or exact"),
                    ));
                }
            };
        }
        let radius = positive(a.radius, 0.02, "ao.radius").map_err(|p| self.err(p))?;
        Ok((mode, radius))
    }

    /// `contours`: their width and colour.
    fn contours(&self, fx: &EffectsSpec, cues: &mut Vec<Cue>) -> Result<Style> {
        let c = fx.contours.clone().unwrap_or_default();
        if fx.contours.is_some() {
            cues.push(Cue::Contours);
        }
        Ok((
            positive(c.width, 2.0, "contours.width").map_err(|p| self.err(p))?,
            color(c.color, [0.0; 3], "contours.color").map_err(|p| self.err(p))?,
        ))
    }

    /// `intersection_lines`: their width and colour.
    fn intersection_lines(&self, fx: &EffectsSpec, cues: &mut Vec<Cue>) -> Result<Style> {
        let c = fx.intersection_lines.clone().unwrap_or_default();
        if fx.intersection_lines.is_some() {
            cues.push(Cue::IntersectionLines);
        }
        Ok((
            positive(c.width, 2.0, "intersection_lines.width").map_err(|p| self.err(p))?,
            color(c.color, [0.0; 3], "intersection_lines.color").map_err(|p| self.err(p))?,
        ))
    }

    /// `suggestive_contours`: width, colour, threshold and fade.
    fn suggestive(&self, fx: &EffectsSpec, cues: &mut Vec<Cue>) -> Result<Suggestive> {
        let sc = fx.suggestive_contours.clone().unwrap_or_default();
        if fx.suggestive_contours.is_some() {
            cues.push(Cue::SuggestiveContours);
        }
        let style = (
            positive(sc.width, 1.5, "suggestive_contours.width").map_err(|p| self.err(p))?,
            color(sc.color, [0.15; 3], "suggestive_contours.color").map_err(|p| self.err(p))?,
        );
        let threshold = sc.threshold.unwrap_or(0.01);
        if !(threshold.is_finite() && threshold >= 0.0) {
            return Err(self.err(format!(
                "suggestive_contours.threshold {threshold} must be ≥ 0"
            )));
        }
        let fade = sc.fade.unwrap_or(0.03);
        if !(fade.is_finite() && fade >= 0.0) {
            return Err(self.err(format!(
                "suggestive_contours.fade {fade} must be ≥ 0 (0: no fade)"
            )));
        }
        Ok(Suggestive {
            style,
            threshold,
            fade,
        })
    }

    /// `feature_edges`: width, colour, crease angle, caps and which edges.
    fn feature_edges(&self, fx: &EffectsSpec, cues: &mut Vec<Cue>) -> Result<FeatureEdges> {
        let fe: EdgeSpec = fx.feature_edges.clone().unwrap_or_default();
        if fx.feature_edges.is_some() {
            cues.push(Cue::FeatureEdges);
        }
        let style = (
            positive(fe.width, 3.0, "feature_edges.width").map_err(|p| self.err(p))?,
            color(fe.color, [0.0; 3], "feature_edges.color").map_err(|p| self.err(p))?,
        );
        let crease_deg = fe.crease.unwrap_or(30.0);
        if !(crease_deg > 0.0 && crease_deg <= 180.0) {
            return Err(self.err(format!(
                "feature_edges.crease {crease_deg} must be in (0, 180] degrees"
            )));
        }
        let caps = match &fe.caps {
            None => CapMode::Adjacency,
            Some(c) => c
                .get_ref()
                .parse()
                .map_err(|x: Error| self.ck.err(c.span(), x.to_string()))?,
        };
        Ok(FeatureEdges {
            style,
            crease: (crease_deg < 180.0).then_some(crease_deg),
            caps,
            contours: fe.contours.unwrap_or(true),
            boundaries: fe.boundaries.unwrap_or(true),
            depth_scale: match fe.depth_scale {
                Some(k) if !(k.is_finite() && k > 0.0) => {
                    return Err(self.err(format!(
                        "feature_edges.depth_scale {k} must be a positive number"
                    )));
                }
                k => k,
            },
            half_contours: fe.half_contours.unwrap_or(false),
            marked: fe
                .marked
                .as_ref()
                .map(|m| self.ck.existing(m))
                .transpose()?,
        })
    }

    /// `curvature_strokes`: spacing, sampling, colour and width.
    fn strokes(&self, fx: &EffectsSpec, cues: &mut Vec<Cue>) -> Result<StrokeEffect> {
        let st: StrokeSpec = fx.curvature_strokes.clone().unwrap_or_default();
        if fx.curvature_strokes.is_some() {
            cues.push(Cue::CurvatureStrokes);
        }
        let world = |v: Option<f64>, what: &str| -> Result<Option<f64>> {
            match v {
                Some(x) if !(x.is_finite() && x > 0.0) => Err(self.err(format!(
                    "curvature_strokes.{what} {x} must be a positive number of world units"
                ))),
                _ => Ok(v),
            }
        };
        let sampling = self.sampling(&st)?;
        Ok(StrokeEffect {
            spacing: world(st.spacing, "spacing")?,
            sampling,
            color: color(st.color, [0.05, 0.05, 0.1], "curvature_strokes.color")
                .map_err(|p| self.err(p))?,
            width: world(st.width, "width")?,
        })
    }

    /// `curvature_strokes.sampling`: `"auto"` (the default candidates) or a
    /// positive distance.
    fn sampling(&self, st: &StrokeSpec) -> Result<Sampling> {
        let Some(s) = &st.sampling else {
            return Ok(Sampling::Auto(Vec::new()));
        };
        match s.get_ref() {
            SamplingSpec::Word(w) if w == "auto" => Ok(Sampling::Auto(Vec::new())),
            SamplingSpec::Distance(h) if h.is_finite() && *h > 0.0 => Ok(Sampling::Fixed(*h)),
            other => Err(self.ck.err(
                s.span(),
                format!(
                    "curvature_strokes.sampling {}: expected \"auto\" or a positive \
                     distance in world units",
                    match other {
                        SamplingSpec::Word(w) => format!("{w:?}"),
                        SamplingSpec::Distance(h) => h.to_string(),
                    }
                ),
            )),
        }
    }

    /// Checks that some cue is asked for and that each accepts the input.
    fn check_cues(&self, cues: &[Cue], input: Input, kind: &str) -> Result<()> {
        if cues.is_empty() {
            return Err(self.err(
                "[effects] asks for no cue: add shading, curvature_colors, ao, contours, \
                 suggestive_contours, feature_edges, curvature_strokes or a line family \
                 (ridges, valleys, isophotes, ...)"
                    .into(),
            ));
        }
        if let Some(c) = cues.iter().find(|c| !c.accepts(input)) {
            return Err(self.err(format!(
                "{}: curvature-directed strokes are traced on a signed distance field; they \
                 need a volume or sdf input, not a {} input",
                c.key(),
                kind
            )));
        }
        Ok(())
    }
}
