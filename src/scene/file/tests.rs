//! Scene-file parsing and checks.

use super::*;
use crate::scene::planner::Cue;
use crate::spec::ao::AoMode;
use crate::spec::edges::CapMode;
use crate::spec::feature_lines::FeatureSize;

fn parse(text: &str) -> Result<Scene> {
    Scene::from_str(Path::new("/nonexistent/dir/test.toml"), text)
}

fn err(text: &str) -> String {
    parse(text).expect_err("must fail").to_string()
}

const MIN: &str = "[input]\ngenerate = \"torus\"\n[effects]\nshading = {}\n";

#[test]
fn a_minimal_scene_gets_defaults() {
    let s = parse(MIN).unwrap();
    assert_eq!(s.source, Source::Generate("torus".into(), 40_000));
    assert_eq!(s.effects.cues, vec![Cue::Shading]);
    assert_eq!(s.views.len(), 1);
    assert_eq!(s.size, [640, 480]);
    assert!(s.png && !s.svg);
    assert_eq!(s.out_dir, Path::new("out/test"));
    assert_eq!(s.prefix, "test");
}

#[test]
fn unknown_keys_and_wrong_types_name_the_line() {
    let e =
        err("[input]\ngenerate = \"torus\"\n[effects]\nshading = {}\nao = { levle = \"lut\" }\n");
    assert!(e.contains("test.toml") && e.contains("line 5"), "{e}");
    assert!(e.contains("levle"), "{e}");
    let e =
        err("[input]\ngenerate = \"torus\"\n\n[effects]\nshading = {}\n[output]\nsize = \"big\"\n");
    assert!(e.contains("line 7"), "{e}");
    let e = err("[input]\ngenerate = \"torus\"\ncolour = 1\n[effects]\nshading = {}\n");
    assert!(e.contains("line 3") && e.contains("colour"), "{e}");
    let e =
        err("[input]\ngenerate = \"torus\"\n[effects]\nshading = {}\n[[camera]]\nfov = \"wide\"\n");
    assert!(e.contains("line 6"), "{e}");
    let e = err("[input\n");
    assert!(e.contains("line 1"), "{e}");
}

#[test]
fn sources_must_be_exactly_one_and_files_must_exist() {
    let e = err("[input]\n[effects]\nshading = {}\n");
    assert!(e.contains("exactly one") && e.contains("none"), "{e}");
    let e = err("[input]\ngenerate = \"torus\"\nsdf = \"torus\"\n[effects]\nshading = {}\n");
    assert!(e.contains("generate, sdf"), "{e}");
    let e = err("[input]\nmesh = \"missing.obj\"\n[effects]\nshading = {}\n");
    assert!(
        e.contains("/nonexistent/dir/missing.obj") && e.contains("line 2"),
        "{e}"
    );
    let e = err("[input]\nvolume = \"v.nrrd\"\n[effects]\nshading = {}\n");
    assert!(e.contains("iso"), "{e}");
    let e = err("[input]\ngenerate = \"torus\"\nclip = 2\n[effects]\nshading = {}\n");
    assert!(e.contains("clip"), "{e}");
    let e = err("[input]\ngenerate = \"cube\"\n[effects]\nshading = {}\n");
    assert!(e.contains("line 2") && e.contains("cube"), "{e}");
    // The choices in words, not a Rust list.
    assert!(e.contains("torus") && !e.contains("[\""), "{e}");
    let e = err("[input]\nsdf = \"cube\"\n[effects]\nshading = {}\n");
    assert!(e.contains("expected sphere, torus or gyroid"), "{e}");
}

#[test]
fn bad_values_are_errors_with_lines() {
    for (snippet, word) in [
        ("[effects]\nao = { level = \"fast\" }\n", "fast"),
        ("[effects]\nao = { radius = -1.0 }\n", "radius"),
        ("[effects]\nfeature_edges = { caps = \"round\" }\n", "round"),
        ("[effects]\nfeature_edges = { crease = 0.0 }\n", "crease"),
        (
            "[effects]\ncontours = { color = [2.0, 0.0, 0.0] }\n",
            "color",
        ),
        ("[effects]\n", "no cue"),
    ] {
        let e = err(&format!("[input]\ngenerate = \"torus\"\n{snippet}"));
        assert!(e.contains(word) && e.contains("line"), "{snippet}: {e}");
    }
    for (snippet, word) in [
        ("[[camera]]\norbit = 0\n", "orbit"),
        ("[[camera]]\neye = [0.0, 0.0, 1.0]\norbit = 4\n", "one of"),
        (
            "[[camera]]\neye = [1.0, 0.0, 0.0]\ntarget = [1.0, 0.0, 0.0]\n",
            "differ",
        ),
        ("[[camera]]\nfov = 180.0\n", "fov"),
        ("[frames]\nstep = 0\n", "step"),
        ("[frames]\nend = 5\n", "static"),
        ("[output]\nsize = [0, 10]\n", "size"),
        ("[output]\nformats = [\"jpg\"]\n", "jpg"),
        ("[output]\nmsaa = 3\n", "msaa"),
    ] {
        let e = err(&format!("{MIN}{snippet}"));
        assert!(e.contains(word) && e.contains("line"), "{snippet}: {e}");
    }
}

#[test]
fn orbits_expand_to_evenly_spaced_unit_directions() {
    let s = parse(&format!("{MIN}[[camera]]\norbit = 8\nelevation = 30\n[[camera]]\neye = [0.0, 0.0, 3.0]\northo = true\n")).unwrap();
    assert_eq!(s.views.len(), 9);
    let dirs: Vec<glam::Vec3> = s.views[..8]
        .iter()
        .map(|v| match v.kind {
            CameraKind::Fit(d) => glam::Vec3::from(d),
            _ => panic!("orbit views are fitted"),
        })
        .collect();
    for (i, d) in dirs.iter().enumerate() {
        assert!((d.length() - 1.0).abs() < 1e-5);
        assert!((d.y - 30f32.to_radians().sin()).abs() < 1e-5, "elevation");
        let next = dirs[(i + 1) % 8];
        let flat = |v: glam::Vec3| glam::Vec2::new(v.x, v.z).normalize();
        let ang = flat(*d).angle_to(flat(next)).abs().to_degrees();
        assert!((ang - 45.0).abs() < 1e-3, "{ang}");
    }
    assert!(dirs[0].z > 0.8, "azimuth 0 looks from +Z: {:?}", dirs[0]);
    assert!(s.views[8].ortho);
}

#[test]
fn effects_resolve_cues_and_parameters() {
    let s = parse("[input]\nsdf = \"gyroid\"\nresolution = 64\n[effects]\ncurvature_colors = {}\nao = { level = \"exact\", radius = 0.1 }\nsuggestive_contours = { threshold = 0.1 }\nfeature_edges = { crease = 180, caps = \"mh\" }\n[output]\nformats = [\"svg\"]\n").unwrap();
    assert_eq!(s.source, Source::Sdf("gyroid".into(), 64, 0.0, false));
    assert_eq!(
        s.effects.cues,
        vec![
            Cue::CurvatureColors,
            Cue::AmbientOcclusion,
            Cue::SuggestiveContours,
            Cue::FeatureEdges
        ]
    );
    assert_eq!(s.effects.ao_mode, AoMode::Exact);
    assert_eq!(s.effects.ao_radius, 0.1);
    assert_eq!(s.effects.crease, None);
    assert_eq!(s.effects.caps, CapMode::Mh);
    assert!(!s.png && s.svg);
    assert_eq!(s.source.input(), Input::Volume);
}

#[test]
fn curvature_strokes_resolve_and_need_a_volume() {
    let s = parse(
        "[input]\nsdf = \"torus\"\n[effects]\nshading = {}\ncurvature_strokes = { spacing = 0.05, sampling = 0.03, color = [1, 0, 0], width = 0.01 }\n",
    )
    .unwrap();
    assert_eq!(s.effects.cues, vec![Cue::Shading, Cue::CurvatureStrokes]);
    let st = &s.effects.strokes;
    assert_eq!(
        (st.spacing, st.sampling.clone(), st.color, st.width),
        (
            Some(0.05),
            crate::spec::sdf_lines::Sampling::Fixed(0.03),
            [1.0, 0.0, 0.0],
            Some(0.01)
        )
    );
    let s =
        parse("[input]\nsdf = \"torus\"\n[effects]\ncurvature_strokes = { sampling = \"auto\" }\n")
            .unwrap();
    assert_eq!(
        s.effects.strokes.sampling,
        crate::spec::sdf_lines::Sampling::Auto(Vec::new())
    );
    let e =
        err("[input]\nsdf = \"torus\"\n[effects]\ncurvature_strokes = { sampling = \"often\" }\n");
    assert!(
        e.contains("test.toml") && e.contains("line 4") && e.contains("auto"),
        "{e}"
    );
    let e = err("[input]\nsdf = \"torus\"\n[effects]\ncurvature_strokes = { spacing = -1 }\n");
    assert!(e.contains("spacing"), "{e}");
    // A mesh input: refused when the file is read, naming the file and the cue.
    for input in ["generate = \"torus\"", "flipbook = \"f_*.obj\""] {
        let e = err(&format!(
            "[input]\n{input}\n[effects]\nshading = {{}}\ncurvature_strokes = {{}}\n"
        ));
        assert!(
            e.contains("test.toml") && e.contains("curvature_strokes") && e.contains("volume"),
            "{e}"
        );
    }
}

#[test]
fn a_view_parallel_to_up_is_refused_with_its_line() {
    let e = err(&format!(
        "{MIN}[[camera]]\ndirection = [0, 2, 0]\nup = [0, 1, 0]\n"
    ));
    assert!(
        e.contains("test.toml") && e.contains("line 5") && e.contains("parallel"),
        "{e}"
    );
    let e = err(&format!(
        "{MIN}[[camera]]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nup = [0, 0, 1]\n"
    ));
    assert!(e.contains("parallel"), "{e}");
    parse(&format!(
        "{MIN}[[camera]]\ndirection = [0, 2, 1]\nup = [0, 1, 0]\n"
    ))
    .unwrap();
}

#[test]
fn fixed_length_arrays_need_exactly_their_length() {
    let e = err(&format!("{MIN}[output]\nsize = [64, 64, 64]\n"));
    assert!(
        e.contains("line 6") && e.contains("expected 2 numbers, found 3"),
        "{e}"
    );
    let e = err(&format!("{MIN}[[camera]]\ndirection = [1.0, 0.0]\n"));
    assert!(
        e.contains("line 6") && e.contains("expected 3 numbers, found 2"),
        "{e}"
    );
    let e = err(&format!("{MIN}[output]\nbackground = [1, 1, 1, 1]\n"));
    assert!(e.contains("expected 3 numbers, found 4"), "{e}");
    let s = parse(&format!("{MIN}[output]\nsize = [64, 48]\n")).unwrap();
    assert_eq!(s.size, [64, 48]);
}

#[test]
fn curvature_and_lines_tables_choose_the_estimator_and_feature_size() {
    use crate::spec::curvature::{Accumulate, Compat, Precision};
    let s = parse(MIN).unwrap();
    // rtsc's defaults, and the one curvature default (gather).
    assert_eq!(s.curvature, CurvatureOptions::default());
    assert_eq!(s.curvature.accumulate, Accumulate::Gather);
    assert_eq!(s.effects.feature_size, FeatureSize::Rtsc);
    assert_eq!(s.effects.suggestive_threshold, 0.01);
    assert_eq!(s.effects.suggestive_fade, 0.03);
    assert!(s.effects.lines.curves.test && !s.effects.lines.curves.hermite);
    let s = parse(&format!(
        "{MIN}[curvature]\naccumulate = \"atomic\"\nprecision = \"f64\"\ncompat = \"trimesh2\"\n\
         [lines]\nfeature_size = 0.5\ntest = false\nhermite = true\nhermite_kh = true\n"
    ))
    .unwrap();
    assert_eq!(
        (
            s.curvature.accumulate,
            s.curvature.precision,
            s.curvature.compat
        ),
        (Accumulate::Atomic, Precision::F64, Compat::Trimesh2)
    );
    assert_eq!(s.effects.feature_size, FeatureSize::Value(0.5));
    let c = s.effects.lines.curves;
    assert!(!c.test && c.hermite && c.hermite_kh);
    assert_eq!(
        parse(&format!("{MIN}[lines]\nfeature_size = \"edge\"\n"))
            .unwrap()
            .effects
            .feature_size,
        FeatureSize::Edge
    );
    let e = err(&format!("{MIN}[curvature]\naccumulate = \"sum\"\n"));
    assert!(e.contains("line 6") && e.contains("gather"), "{e}");
    let e = err(&format!("{MIN}[lines]\nfeature_size = \"median\"\n"));
    assert!(
        e.contains("line 5") && e.contains("rtsc, edge or a positive length"),
        "{e}"
    );
    let e = err(&format!("{MIN}[lines]\nfeature_size = -2\n"));
    assert!(e.contains("positive length"), "{e}");
}

#[test]
fn the_lines_table_sets_coherence_over_frames() {
    use crate::spec::coherence::Coherence;
    let settings = |s: Scene| {
        let l = s.effects.lines;
        (
            l.coherence,
            l.coherence_low,
            l.coherence_birth,
            l.coherence_band,
        )
    };
    assert_eq!(
        settings(parse(MIN).unwrap()),
        (
            Coherence::Auto,
            Coherence::DEFAULT_LOW,
            Coherence::DEFAULT_BIRTH,
            Coherence::DEFAULT_BAND
        )
    );
    let s = parse(&format!(
        "{MIN}[lines]\ncoherence = \"off\"\ncoherence_low = 0.8\ncoherence_birth = 1\n\
         coherence_band = 0\n"
    ))
    .unwrap();
    assert_eq!(settings(s), (Coherence::Off, 0.8, 1, 0.0));
    for (bad, says) in [
        ("coherence = \"always\"", "auto, on, off"),
        ("coherence_low = 0", "(0, 1]"),
        ("coherence_low = 1.5", "(0, 1]"),
        ("coherence_birth = 3", "0, 1 or 2"),
        ("coherence_band = -1", "at least 0"),
    ] {
        let e = err(&format!("{MIN}[lines]\n{bad}\n"));
        assert!(
            e.contains(says) && e.contains("lines.coherence"),
            "{bad}: {e}"
        );
    }
    // Auto holds over more than one frame only.
    assert!(!Coherence::Auto.holds(1) && Coherence::Auto.holds(2));
    assert!(!Coherence::Off.holds(60));
}

#[test]
fn a_bad_clip_reads_as_toml_words() {
    let fox = concat!(env!("CARGO_MANIFEST_DIR"), "/data/Fox.glb");
    for (clip, bad) in [("-1", "-1"), ("1.5", "1.5"), ("true", "true")] {
        let e = err(&format!(
            "[input]\ngltf = {fox:?}\nclip = {clip}\n[effects]\nshading = {{}}\n"
        ));
        assert!(
            e.contains("line 3") && e.contains(&format!("clip = {bad}")) && e.contains("index"),
            "{e}"
        );
        assert!(!e.contains("untagged") && !e.contains("variant"), "{e}");
    }
    let s = parse(&format!(
        "[input]\ngltf = {fox:?}\nclip = \"Walk\"\n[effects]\nshading = {{}}\n"
    ))
    .unwrap();
    assert_eq!(
        s.source,
        Source::Gltf(fox.into(), Some(ClipRef::Name("Walk".into())))
    );
}

#[test]
fn output_interop_is_a_mode() {
    use crate::spec::interop::InteropMode;
    let s = parse("[input]\ngenerate = \"torus\"\n[effects]\nshading = {}\n").unwrap();
    assert_eq!(s.interop, InteropMode::Off);
    let s = parse(
        "[input]\ngenerate = \"torus\"\n[effects]\nshading = {}\n[output]\ninterop = \"auto\"\n",
    )
    .unwrap();
    assert_eq!(s.interop, InteropMode::Auto);
    let e = err(
        "[input]\ngenerate = \"torus\"\n[effects]\nshading = {}\n[output]\ninterop = \"maybe\"\n",
    );
    assert!(e.contains("line 6") && e.contains("output.interop"), "{e}");
}

#[test]
fn normals_choose_the_file_s_or_computed_ones_for_mesh_inputs() {
    let spot = concat!(env!("CARGO_MANIFEST_DIR"), "/data/spot.obj");
    let with =
        |extra: &str| format!("[input]\nmesh = \"{spot}\"\n{extra}[effects]\nshading = {{}}\n");
    let s = parse(&with("")).unwrap();
    assert_eq!(s.normals, crate::mesh::NormalsSource::File);
    let s = parse(&with("normals = \"computed\"\n")).unwrap();
    assert_eq!(s.normals, crate::mesh::NormalsSource::Computed);
    let e = err(&with("normals = \"stored\"\n"));
    assert!(e.contains("line 3") && e.contains("file, computed"), "{e}");
    let e = err("[input]\ngenerate = \"torus\"\nnormals = \"file\"\n[effects]\nshading = {}\n");
    assert!(
        e.contains("`normals` does not apply to a generate input"),
        "{e}"
    );
}
