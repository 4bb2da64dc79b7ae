//! What the viewer shows: the scene it was opened on, the cues switched on,
//! the sliders and choices, the frame and the camera; and the scene one
//! request hands to the executor. Cue toggles come from [`Cue::ALL`] (the
//! cues the input accepts), so a new cue appears here without an edit.

use super::camera::Orbit;
use shapecue::scene::file::{Scene, Source};
use shapecue::scene::planner::Cue;
use shapecue::spec::Choice;
use shapecue::spec::ao::AoMode;
use shapecue::spec::edges::CapMode;

/// A slider: a number of the scene, shown while its cue is on.
pub struct Slider {
    /// Name in scripts (`set NAME VALUE`).
    pub key: &'static str,
    /// Label in the window.
    pub label: &'static str,
    /// The cue it belongs to (`None`: always shown when it applies).
    pub cue: Option<Cue>,
    /// Range.
    pub min: f64,
    pub max: f64,
    /// Reads it from a scene (`None`: it does not apply to this input).
    pub get: fn(&Scene) -> Option<f64>,
    /// Writes it into a scene.
    pub set: fn(&mut Scene, f64),
}

fn iso_of(s: &Scene) -> Option<f64> {
    match s.source {
        Source::Volume(_, iso, _) | Source::Sdf(_, _, iso, _) => Some(f64::from(iso)),
        _ => None,
    }
}

fn set_iso(s: &mut Scene, v: f64) {
    match &mut s.source {
        Source::Volume(_, iso, _) | Source::Sdf(_, _, iso, _) => *iso = v as f32,
        _ => {}
    }
}

/// Every slider (the iso value's range is the volume's, set at start).
pub fn sliders() -> Vec<Slider> {
    let mut all = surface_sliders();
    all.extend(line_sliders());
    all
}

/// The surface's sliders: iso value, ambient term and AO radius.
fn surface_sliders() -> Vec<Slider> {
    vec![
        Slider {
            key: "iso",
            label: "iso value",
            cue: None,
            min: 0.0,
            max: 1.0,
            get: iso_of,
            set: set_iso,
        },
        Slider {
            key: "ambient",
            label: "ambient",
            cue: Some(Cue::Shading),
            min: 0.0,
            max: 1.0,
            get: |s| Some(f64::from(s.effects.ambient)),
            set: |s, v| s.effects.ambient = v as f32,
        },
        Slider {
            key: "ao_radius",
            label: "AO radius (of the diagonal)",
            cue: Some(Cue::AmbientOcclusion),
            min: 0.002,
            max: 0.2,
            get: |s| Some(f64::from(s.effects.ao_radius)),
            set: |s, v| s.effects.ao_radius = v as f32,
        },
    ]
}

/// The lines' sliders: contour, suggestive contour and feature edge widths,
/// the suggestive threshold and fade, and the crease angle.
fn line_sliders() -> Vec<Slider> {
    vec![
        Slider {
            key: "contour_width",
            label: "contour width (px)",
            cue: Some(Cue::Contours),
            min: 0.25,
            max: 8.0,
            get: |s| Some(f64::from(s.effects.contour.0)),
            set: |s, v| s.effects.contour.0 = v as f32,
        },
        Slider {
            key: "suggestive_width",
            label: "suggestive width (px)",
            cue: Some(Cue::SuggestiveContours),
            min: 0.25,
            max: 8.0,
            get: |s| Some(f64::from(s.effects.suggestive.0)),
            set: |s, v| s.effects.suggestive.0 = v as f32,
        },
        Slider {
            key: "suggestive_threshold",
            label: "suggestive threshold",
            cue: Some(Cue::SuggestiveContours),
            min: 0.0,
            max: 0.1,
            get: |s| Some(f64::from(s.effects.suggestive_threshold)),
            set: |s, v| s.effects.suggestive_threshold = v as f32,
        },
        Slider {
            key: "suggestive_fade",
            label: "suggestive fade",
            cue: Some(Cue::SuggestiveContours),
            min: 0.0,
            max: 0.2,
            get: |s| Some(f64::from(s.effects.suggestive_fade)),
            set: |s, v| s.effects.suggestive_fade = v as f32,
        },
        Slider {
            key: "edge_width",
            label: "edge width (px)",
            cue: Some(Cue::FeatureEdges),
            min: 0.25,
            max: 8.0,
            get: |s| Some(f64::from(s.effects.edge.0)),
            set: |s, v| s.effects.edge.0 = v as f32,
        },
        Slider {
            key: "crease",
            label: "crease angle (°, 180 off)",
            cue: Some(Cue::FeatureEdges),
            min: 1.0,
            max: 180.0,
            get: |s| Some(f64::from(s.effects.crease.unwrap_or(180.0))),
            set: |s, v| s.effects.crease = (v < 180.0).then_some(v.max(1.0) as f32),
        },
    ]
}

/// The viewer's state.
pub struct State {
    /// The scene as opened (cues, sliders and source change in a copy).
    pub scene: Scene,
    /// The cues this input accepts, in [`Cue::ALL`] order, and whether each is on.
    pub cues: Vec<(Cue, bool)>,
    /// The sliders that apply to this input.
    pub sliders: Vec<Slider>,
    /// The scene's frame indices and the position in them.
    pub frames: Vec<usize>,
    pub frame: usize,
    pub playing: bool,
    pub camera: Orbit,
    /// Image size.
    pub size: [u32; 2],
}

impl State {
    /// The state of a scene opened with `frames` and `camera`; `values`: a
    /// volume's value range (for the iso slider).
    pub fn new(
        scene: Scene,
        frames: Vec<usize>,
        camera: Orbit,
        values: Option<(f32, f32)>,
    ) -> State {
        let input = scene.source.input();
        let cues = Cue::ALL
            .iter()
            .filter(|c| c.accepts(input))
            .map(|&c| (c, scene.effects.cues.contains(&c)))
            .collect();
        let sliders = sliders()
            .into_iter()
            .filter(|s| (s.get)(&scene).is_some())
            .map(|mut s| {
                if s.key == "iso"
                    && let Some((lo, hi)) = values
                {
                    // At the extreme values the surface is empty: the
                    // slider stops 1 % of the range inside them.
                    let (lo, hi) = (f64::from(lo), f64::from(hi));
                    let pad = 0.01 * (hi - lo);
                    (s.min, s.max) = (lo + pad, hi - pad);
                }
                s
            })
            .collect();
        State {
            size: scene.size,
            scene,
            cues,
            sliders,
            frames,
            frame: 0,
            playing: false,
            camera,
        }
    }

    /// The cues switched on.
    pub fn enabled(&self) -> Vec<Cue> {
        self.cues.iter().filter(|c| c.1).map(|c| c.0).collect()
    }

    /// Switches a cue (by its scene-file name) on or off (`None`: toggles).
    pub fn set_cue(&mut self, key: &str, on: Option<bool>) -> Result<(), String> {
        let names: Vec<&str> = self.cues.iter().map(|c| c.0.key()).collect();
        let c = self
            .cues
            .iter_mut()
            .find(|c| c.0.key() == key)
            .ok_or_else(|| format!("no cue {key} for this input (cues: {})", names.join(", ")))?;
        c.1 = on.unwrap_or(!c.1);
        Ok(())
    }

    /// Sets a slider, clamped to its range, or a choice (`ao_level`, `caps`)
    /// by name.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), String> {
        match key {
            "ao_level" => {
                self.scene.effects.ao_mode = choice::<AoMode>(key, value)?;
                return Ok(());
            }
            "caps" => {
                self.scene.effects.caps = choice::<CapMode>(key, value)?;
                return Ok(());
            }
            _ => {}
        }
        let names: Vec<&str> = self.sliders.iter().map(|s| s.key).collect();
        let s = self.sliders.iter().find(|s| s.key == key).ok_or_else(|| {
            format!(
                "no slider {key} for this input (sliders: {}, ao_level, caps)",
                names.join(", ")
            )
        })?;
        let v: f64 = value
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| format!("{key}: {value} is not a number"))?;
        (s.set)(&mut self.scene, v.clamp(s.min, s.max));
        Ok(())
    }

    /// Steps the frame by `delta`, wrapping around.
    pub fn step(&mut self, delta: i64) {
        let n = self.frames.len().max(1) as i64;
        self.frame = (self.frame as i64 + delta).rem_euclid(n) as usize;
    }

    /// The scene of one request: this camera, this frame, the cues on.
    pub fn request_scene(&self) -> Scene {
        let mut s = self.scene.clone();
        s.views = vec![self.camera.view()];
        let f = self.frames.get(self.frame).copied().unwrap_or(0);
        s.frames = (f, Some(f + 1), 1);
        s.effects.cues = self.enabled();
        s.size = self.size;
        s.prefix = "view".into();
        s
    }
}

/// A choice of an option enum by name.
fn choice<T: Choice>(key: &str, value: &str) -> Result<T, String> {
    T::all()
        .iter()
        .copied()
        .find(|c| c.label() == value)
        .ok_or_else(|| {
            let names: Vec<&str> = T::all().iter().map(|c| c.label()).collect();
            format!("{key}: {value} is not one of {}", names.join(", "))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use shapecue::scene::file::CameraKind;

    fn state(input: &str) -> State {
        let text = format!("[input]\n{input}\n\n[effects]\nshading = {{}}\ncontours = {{}}\n");
        let scene = Scene::from_str(std::path::Path::new("t.toml"), &text).unwrap();
        let view = scene.views[0].clone();
        assert!(matches!(view.kind, CameraKind::Fit(_)));
        let cam = Orbit::new(view, ([-1.0; 3], [1.0; 3]), 1.0).unwrap();
        State::new(scene, vec![0], cam, Some((-2.0, 2.0)))
    }

    #[test]
    fn cues_and_sliders_follow_the_input() {
        let mut s = state("generate = \"torus\"");
        let keys: Vec<Cue> = s.cues.iter().map(|c| c.0).collect();
        let want: Vec<Cue> = Cue::ALL
            .into_iter()
            .filter(|c| c.accepts(s.scene.source.input()))
            .collect();
        assert_eq!(keys, want);
        assert_eq!(s.enabled(), vec![Cue::Shading, Cue::Contours]);
        assert!(s.set("iso", "0.5").is_err(), "no iso on a mesh");
        s.set("contour_width", "100").unwrap();
        assert_eq!(
            s.scene.effects.contour.0, 8.0,
            "clamped to the slider's range"
        );
        s.set("crease", "180").unwrap();
        assert_eq!(s.scene.effects.crease, None);
        s.set("caps", "mh").unwrap();
        assert!(s.set("caps", "round").is_err());
        s.set_cue("contours", Some(false)).unwrap();
        s.set_cue("ao", None).unwrap();
        assert_eq!(s.enabled(), vec![Cue::Shading, Cue::AmbientOcclusion]);
        assert!(s.set_cue("curvature_strokes", Some(true)).is_err());
        let r = s.request_scene();
        assert_eq!(r.effects.cues, s.enabled());
        assert_eq!((r.views.len(), r.frames), (1, (0, Some(1), 1)));

        let mut v = state("sdf = \"sphere\"\nresolution = 24");
        assert!(v.cues.iter().any(|c| c.0 == Cue::CurvatureStrokes));
        v.set("iso", "0.25").unwrap();
        assert!(matches!(v.scene.source, Source::Sdf(_, _, iso, _) if iso == 0.25));
        // Clamped inside the field's values, where the surface is not empty.
        v.set("iso", "9").unwrap();
        let Source::Sdf(_, _, iso, _) = v.scene.source else {
            unreachable!()
        };
        let (lo, hi) = v
            .sliders
            .iter()
            .find(|s| s.key == "iso")
            .map(|s| (s.min, s.max))
            .unwrap();
        assert!(
            (lo + 1.96).abs() < 1e-12 && (hi - 1.96).abs() < 1e-12,
            "{lo}..{hi}"
        );
        assert_eq!(f64::from(iso), f64::from(hi as f32));
    }
}
