//! The curvature line cues of `[effects]` (every line family of rtsc beside
//! the contours): their tables (as written, in `raw`) resolved into the
//! feature-line stage's options and each family's stroke style.
//!
//! ```toml
//! [effects]
//! ridges = { threshold = 0.1, width = 1.5, color = [0.3, 0, 0.3] }
//! valleys = {}
//! apparent_ridges = { threshold = 0.1 }
//! suggestive_highlights = { threshold = 0.02 }
//! principal_highlights = { threshold = 0.04 }
//! isophotes = { count = 20, light = [0, 0, 1] }
//! k_zero = {}                  # parabolic lines
//! h_zero = {}                  # zero mean curvature
//! dwkr_zero = {}
//! boundaries = { hidden = "dashed" }
//! ```
//!
//! Every table takes `width`, `color`, `hidden` (`remove`, `faded` or
//! `dashed`: the hidden parts in the SVG), `fade` and `cull`. One launch
//! finds every family, so `fade` and `cull` are shared: tables that give
//! them must agree, and so must the thresholds of ridges and valleys.

use super::raw::{IsophoteSpec, PlainLineSpec, ThresholdLineSpec};
use crate::scene::planner::Cue;
use crate::spec::coherence::Coherence;
use crate::spec::feature_lines::{CurveOptions, FamilySet, Hidden, LineFamily, family_style};

/// One curvature line cue's stroke.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineStyle {
    /// The family.
    pub family: LineFamily,
    /// Width in pixels.
    pub width: f32,
    /// RGB.
    pub color: [f32; 3],
    /// Hidden parts in the SVG.
    pub hidden: Hidden,
}

/// The curvature line cues of a scene, resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct LineEffects {
    /// One style per asked family, in family order.
    pub styles: Vec<LineStyle>,
    /// The feature-line stage's options (families, thresholds, isophotes,
    /// light, culling, fading).
    pub curves: CurveOptions,
    /// Hysteresis over an animation's frames (`[lines] coherence`).
    pub coherence: Coherence,
    /// Its lower threshold, a fraction of each family's (`[lines]
    /// coherence_low`, default [`Coherence::DEFAULT_LOW`]).
    pub coherence_low: f32,
    /// The delay of births in frames (`[lines] coherence_birth`, default
    /// [`Coherence::DEFAULT_BIRTH`]).
    pub coherence_birth: u32,
    /// The band of the Schmitt trigger on the signs of K and H, in units
    /// of the feature size (`[lines] coherence_band`, default
    /// [`Coherence::DEFAULT_BAND`]; 0: none).
    pub coherence_band: f32,
}

impl Default for LineEffects {
    fn default() -> Self {
        LineEffects {
            styles: Vec::new(),
            curves: CurveOptions::default(),
            coherence: Coherence::default(),
            coherence_low: Coherence::DEFAULT_LOW,
            coherence_birth: Coherence::DEFAULT_BIRTH,
            coherence_band: Coherence::DEFAULT_BAND,
        }
    }
}

impl LineStyle {
    /// A family's default stroke (that of `shapecue lines`, 1.5 px wide).
    pub fn default_for(family: LineFamily) -> LineStyle {
        let (color, factor) = family_style(family);
        LineStyle {
            family,
            width: 1.5 * factor,
            color,
            hidden: Hidden::Remove,
        }
    }
}

impl LineEffects {
    /// The strokes of the line family cues among `cues`, in family order:
    /// the scene's own, or the default for a cue switched on that the
    /// scene file did not give (as the viewer does).
    pub fn styles_for(&self, cues: &[Cue]) -> Vec<LineStyle> {
        let mut fams: Vec<LineFamily> = cues.iter().filter_map(|c| c.family()).collect();
        fams.sort();
        fams.dedup();
        fams.into_iter()
            .map(|f| {
                self.styles
                    .iter()
                    .find(|s| s.family == f)
                    .copied()
                    .unwrap_or_else(|| LineStyle::default_for(f))
            })
            .collect()
    }

    /// The feature-line stage's options for the line family cues among `cues`.
    pub fn curves_for(&self, cues: &[Cue]) -> CurveOptions {
        let fams: Vec<LineFamily> = cues.iter().filter_map(|c| c.family()).collect();
        CurveOptions {
            families: FamilySet::of(&fams),
            ..self.curves
        }
    }
}

/// What every table has in common.
struct Common<'a> {
    width: Option<f32>,
    color: Option<[f32; 3]>,
    fade: Option<bool>,
    cull: Option<bool>,
    hidden: &'a Option<String>,
}

/// A shared switch: the first table that sets it decides, a later one must agree.
fn shared(
    slot: &mut Option<(bool, &'static str)>,
    v: Option<bool>,
    key: &'static str,
    what: &str,
) -> Result<(), String> {
    match (v, *slot) {
        (Some(v), Some((w, by))) if v != w => Err(format!(
            "{key}.{what} = {v} but {by}.{what} = {w}: every curvature line cue is found in one \
             pass, so {what} must be the same for all of them"
        )),
        (Some(v), None) => {
            *slot = Some((v, key));
            Ok(())
        }
        _ => Ok(()),
    }
}

/// Resolves the curvature line cues of `fx`, pushing them onto `cues`.
/// Errors name the key (`ridges.threshold`) and the problem; the caller
/// adds the scene file and line.
pub(super) fn resolve(fx: &super::EffectsSpec, cues: &mut Vec<Cue>) -> Result<LineEffects, String> {
    let mut curves = CurveOptions::default();
    let mut styles = Vec::new();
    let mut shared_by = Shared::default();
    let mut families = Vec::new();
    for (cue, table) in tables(fx) {
        let Some((c, threshold)) = table else {
            continue;
        };
        let key = cue.key();
        let family = cue.family().expect("a line family cue");
        cues.push(cue);
        families.push(family);
        let d = LineStyle::default_for(family);
        let width = super::positive(c.width, d.width, &format!("{key}.width"))?;
        let color = super::color(c.color, d.color, &format!("{key}.color"))?;
        let hidden = hidden(c.hidden, key)?;
        shared(&mut shared_by.fade, c.fade, key, "fade")?;
        shared(&mut shared_by.cull, c.cull, key, "cull")?;
        if let Some(x) = threshold {
            set_threshold(&mut curves, &mut shared_by.ridge_threshold, cue, x)?;
        }
        styles.push(LineStyle {
            family,
            width,
            color,
            hidden,
        });
    }
    if let Some(s) = &fx.isophotes {
        isophotes(s, &mut curves)?;
    }
    curves.families = FamilySet::of(&families);
    curves.fade = shared_by.fade.is_none_or(|f| f.0);
    curves.cull = shared_by.cull.is_none_or(|c| c.0);
    Ok(LineEffects {
        styles,
        curves,
        ..LineEffects::default()
    })
}

/// The settings every family shares, each with the first table that set it.
#[derive(Default)]
struct Shared {
    /// `fade`.
    fade: Option<(bool, &'static str)>,
    /// `cull`.
    cull: Option<(bool, &'static str)>,
    /// The threshold of ridges and valleys.
    ridge_threshold: Option<(f32, &'static str)>,
}

/// A line family table: what every table has, and its threshold if it takes one.
type LineTable<'a> = Option<(Common<'a>, Option<f32>)>;

/// Each line family cue with its table in `fx` (`None`: not asked), in
/// family order.
fn tables(fx: &super::EffectsSpec) -> [(Cue, LineTable<'_>); 10] {
    fn t(s: &Option<ThresholdLineSpec>) -> LineTable<'_> {
        s.as_ref().map(|s| {
            (
                Common {
                    width: s.width,
                    color: s.color,
                    fade: s.fade,
                    cull: s.cull,
                    hidden: &s.hidden,
                },
                s.threshold,
            )
        })
    }
    fn p(s: &Option<PlainLineSpec>) -> LineTable<'_> {
        s.as_ref().map(|s| {
            (
                Common {
                    width: s.width,
                    color: s.color,
                    fade: s.fade,
                    cull: s.cull,
                    hidden: &s.hidden,
                },
                None,
            )
        })
    }
    let iso = fx.isophotes.as_ref().map(|s| {
        (
            Common {
                width: s.width,
                color: s.color,
                fade: s.fade,
                cull: s.cull,
                hidden: &s.hidden,
            },
            None,
        )
    });
    [
        (Cue::Ridges, t(&fx.ridges)),
        (Cue::Valleys, t(&fx.valleys)),
        (Cue::ApparentRidges, t(&fx.apparent_ridges)),
        (Cue::SuggestiveHighlights, t(&fx.suggestive_highlights)),
        (Cue::PrincipalHighlights, t(&fx.principal_highlights)),
        (Cue::Isophotes, iso),
        (Cue::KZero, p(&fx.k_zero)),
        (Cue::HZero, p(&fx.h_zero)),
        (Cue::DwkrZero, p(&fx.dwkr_zero)),
        (Cue::Boundaries, p(&fx.boundaries)),
    ]
}

/// `{key}.hidden`: the hidden parts in the SVG (default: removed).
fn hidden(h: &Option<String>, key: &str) -> Result<Hidden, String> {
    match h {
        None => Ok(Hidden::Remove),
        Some(h) => h
            .parse::<Hidden>()
            .map_err(|_| format!("{key}.hidden {h:?}: expected remove, faded or dashed")),
    }
}

/// `{key}.threshold` = `x` into `curves`; ridges and valleys must agree.
fn set_threshold(
    curves: &mut CurveOptions,
    ridge_threshold: &mut Option<(f32, &'static str)>,
    cue: Cue,
    x: f32,
) -> Result<(), String> {
    let key = cue.key();
    if !(x.is_finite() && x >= 0.0) {
        return Err(format!("{key}.threshold {x} must be a finite number ≥ 0"));
    }
    match cue {
        Cue::Ridges | Cue::Valleys => match *ridge_threshold {
            Some((y, by)) if y != x => {
                return Err(format!(
                    "{key}.threshold = {x} but {by}.threshold = {y}: ridges and valleys \
                     share one threshold"
                ));
            }
            _ => {
                *ridge_threshold = Some((x, key));
                curves.ridge_threshold = x;
            }
        },
        Cue::ApparentRidges => curves.apparent_threshold = x,
        Cue::SuggestiveHighlights => curves.highlight_threshold = x,
        _ => curves.principal_threshold = x,
    }
    Ok(())
}

/// `isophotes.count` and `isophotes.light` into `curves`.
fn isophotes(s: &IsophoteSpec, curves: &mut CurveOptions) -> Result<(), String> {
    if let Some(n) = s.count {
        if !(1..=1000).contains(&n) {
            return Err(format!("isophotes.count {n} must be 1 to 1000"));
        }
        curves.isophotes = n;
    }
    if let Some(l) = s.light {
        let n = l.iter().map(|c| c * c).sum::<f32>().sqrt();
        if !(n.is_finite() && n > 0.0) {
            return Err(format!(
                "isophotes.light [{}, {}, {}] must be a finite, non-zero direction",
                l[0], l[1], l[2]
            ));
        }
        curves.light = l;
    }
    Ok(())
}
