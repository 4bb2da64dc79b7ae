//! The scene executor on real runs: the passes that ran are exactly the
//! plan's, as often as the lifetimes promise (minimality checked on the
//! device, not just in the planner); images and the report are written;
//! nothing is overwritten without `force`; the example scenes parse.
//!
//! Needs OpenCL (PoCL) and headless GL; without libEGL the tests print why
//! and pass, unless `SHAPECUE_REQUIRE_GL=1` (CI).

mod common;

use common::{SHARED_DATA, model_path, scratch, unless_no_gl};

use shapecue::Error;
use shapecue::scene::exec::{self, ExecOptions, RunReport};
use shapecue::scene::file::Scene;
use shapecue::scene::planner::{Cue, Input, Outputs, Pass, plan_for};
use shapecue::spec::visibility::VisibilityMethod;
use std::path::Path;

/// Writes a scene next to its outputs and parses it.
fn scene(dir: &Path, text: &str) -> Scene {
    let p = dir.join("s.toml");
    std::fs::write(&p, text).unwrap();
    Scene::load(&p).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// Runs a scene into `dir/out`; `None` (after a message) without GL.
fn run(s: &Scene, dir: &Path, force: bool) -> Option<Result<RunReport, Error>> {
    let opts = ExecOptions {
        out_dir: Some(dir.join("out")),
        force,
        device: None,
        ..Default::default()
    };
    unless_no_gl(exec::run(s, &opts, &mut |_, _| {}))
}

/// The passes that ran are exactly the planned ones, each as often as
/// `Plan::runs` says.
fn check_minimal(r: &RunReport, what: &str) {
    let ran: Vec<Pass> = r.passes.iter().map(|p| p.pass).collect();
    assert_eq!(ran, r.plan.passes, "{what}: passes that ran vs planned");
    for p in &r.passes {
        assert_eq!(
            p.runs,
            r.plan.runs(p.pass, r.frames.len(), r.views),
            "{what}: runs of {:?}",
            p.pass
        );
        assert!(p.ms().is_finite() && p.ms() >= 0.0, "{what}: {p:?}");
    }
    // The mesh goes to GL once per topology and once per pose, not per view.
    let frames = r.frames.len() as u64;
    let topologies = if r.plan.input == Input::Volume {
        frames
    } else {
        1
    };
    assert_eq!(r.gl_uploads.topology, topologies, "{what}: face uploads");
    assert_eq!(r.gl_uploads.pose, frames, "{what}: pose uploads");
}

const CUES: [(&str, Cue); 6] = [
    ("shading = {}", Cue::Shading),
    ("curvature_colors = {}", Cue::CurvatureColors),
    ("ao = {}", Cue::AmbientOcclusion),
    ("contours = {}", Cue::Contours),
    ("suggestive_contours = {}", Cue::SuggestiveContours),
    ("feature_edges = { crease = 20 }", Cue::FeatureEdges),
];

#[test]
fn static_scenes_run_exactly_their_passes() {
    // Each cue alone, some pairs, and all of them; two views of one static
    // mesh: pose passes once, view passes twice.
    let mut sets: Vec<Vec<usize>> = (0..6).map(|i| vec![i]).collect();
    sets.extend([vec![3, 4], vec![2, 3], vec![0, 5], vec![0, 1, 2, 3, 4, 5]]);
    for set in sets {
        let dir = scratch("static");
        let fx: String = set.iter().map(|&i| format!("{}\n", CUES[i].0)).collect();
        let s = scene(
            &dir,
            &format!(
                "[input]\ngenerate = \"torus\"\nresolution = 3000\n[[camera]]\norbit = 2\n\
                 [effects]\n{fx}[output]\nsize = [96, 72]\nformats = [\"png\", \"svg\"]\n"
            ),
        );
        let Some(r) = run(&s, &dir, false) else {
            return;
        };
        let r = r.unwrap();
        let cues: Vec<Cue> = set.iter().map(|&i| CUES[i].1).collect();
        assert_eq!(
            r.plan,
            plan_for(
                &cues,
                s.source.input(),
                s.effects.caps,
                Outputs {
                    raster: true,
                    vector: true,
                    visibility: VisibilityMethod::Exact,
                    pieces: false,
                    fields: false,
                    npz: false,
                }
            ),
            "{cues:?}"
        );
        check_minimal(&r, &format!("{cues:?}"));
        assert_eq!(r.outputs.len(), 4, "2 views × png + svg");
        for p in &r.outputs {
            assert!(p.exists(), "{}", p.display());
        }
        let report = dir.join("out/s_report.json");
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        assert_eq!(
            j["passes"].as_array().unwrap().len(),
            r.plan.passes.len(),
            "{cues:?}"
        );
        if cues.contains(&Cue::Contours) {
            assert!(r.segments[0] > 0, "a torus from two views has contours");
        }
        if !cues.contains(&Cue::SuggestiveContours) {
            assert_eq!(r.segments[1], 0);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn curvature_colours_show_convex_red_and_saddle_green_on_a_torus() {
    let dir = scratch("colors");
    // Looking down the torus axis (z): the outer half of the ring is convex
    // (red), the inner half saddle-shaped (green).
    let s = scene(
        &dir,
        "[input]\ngenerate = \"torus\"\nresolution = 8000\n[[camera]]\ndirection = [0.0, 0.0, 1.0]\n\
         [effects]\ncurvature_colors = {}\n[output]\nsize = [128, 128]\nmsaa = 0\n",
    );
    let Some(r) = run(&s, &dir, false) else {
        return;
    };
    let r = r.unwrap();
    let img = image::open(&r.outputs[0]).unwrap().to_rgb8();
    let (mut red, mut green) = (0, 0);
    for p in img.pixels() {
        let [pr, pg, pb] = p.0.map(i32::from);
        if pr > pg + 40 && pr > pb + 40 {
            red += 1;
        }
        if pg > pr + 40 && pg > pb + 40 {
            green += 1;
        }
    }
    assert!(red > 200 && green > 100, "red {red}, green {green}");
    // The centre of the image is the hole: background.
    assert_eq!(img.get_pixel(64, 64).0, [255, 255, 255]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn outputs_are_not_overwritten_without_force() {
    let dir = scratch("force");
    let s = scene(
        &dir,
        "[input]\ngenerate = \"sphere\"\nresolution = 500\n[effects]\nshading = {}\n[output]\nsize = [32, 32]\n",
    );
    let Some(r) = run(&s, &dir, false) else {
        return;
    };
    let png = r.unwrap().outputs[0].clone();
    std::fs::write(&png, b"mine").unwrap();
    let e = run(&s, &dir, false).unwrap().expect_err("refuses");
    assert!(e.to_string().contains("force = true"), "{e}");
    assert_eq!(std::fs::read(&png).unwrap(), b"mine", "untouched");
    run(&s, &dir, true).unwrap().unwrap();
    assert_ne!(
        std::fs::read(&png).unwrap(),
        b"mine",
        "overwritten with force"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_isosurface_scene_rebuilds_topology_every_pose() {
    let dir = scratch("volume");
    let s = scene(
        &dir,
        "[input]\nsdf = \"torus\"\nresolution = 40\n[[camera]]\norbit = 3\n[effects]\n\
         curvature_colors = {}\nsuggestive_contours = {}\nfeature_edges = { caps = \"mh\" }\n\
         [output]\nsize = [64, 64]\n",
    );
    let Some(r) = run(&s, &dir, false) else {
        return;
    };
    let r = r.unwrap();
    check_minimal(&r, "volume");
    assert!(r.plan.contains(Pass::Isosurface) && !r.plan.contains(Pass::CapBuffer));
    let _ = std::fs::remove_dir_all(&dir);
    // An empty isosurface is a clear error, not blank images.
    let dir = scratch("volume-empty");
    let s = scene(
        &dir,
        "[input]\nsdf = \"sphere\"\nresolution = 16\niso = 5.0\n[effects]\nshading = {}\n",
    );
    let e = run(&s, &dir, false).unwrap().expect_err("empty");
    assert!(e.to_string().contains("empty"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_skinned_scene_runs_pose_passes_per_frame_and_topology_once() {
    let Some(gltf) = model_path("RiggedSimple.glb") else {
        return;
    };
    let dir = scratch("skinned");
    let s = scene(
        &dir,
        &format!(
            "[input]\ngltf = {:?}\n[frames]\nend = 6\nstep = 2\n[[camera]]\norbit = 2\n[effects]\n\
             ao = {{ level = \"poly\" }}\ncontours = {{}}\nsuggestive_contours = {{}}\n\
             feature_edges = {{}}\n[output]\nsize = [64, 48]\n",
            gltf.display().to_string()
        ),
    );
    let Some(r) = run(&s, &dir, false) else {
        return;
    };
    let r = r.unwrap();
    check_minimal(&r, "skinned");
    assert_eq!(r.frames, vec![0, 2, 4]);
    let runs = |p: Pass| r.passes.iter().find(|x| x.pass == p).map(|x| x.runs);
    assert_eq!(runs(Pass::Skinning), Some(3));
    assert_eq!(runs(Pass::OneRings), Some(1));
    assert_eq!(runs(Pass::Dcurv), Some(3));
    assert_eq!(runs(Pass::Contours), Some(6));
    assert_eq!(r.outputs.len(), 6);
    // Clips that do not exist are named.
    for (clip, word) in [("\"Nope\"", "no such clip"), ("9", "clips")] {
        let s = scene(
            &dir,
            &format!(
                "[input]\ngltf = {:?}\nclip = {clip}\n[effects]\nshading = {{}}\n",
                gltf.display().to_string()
            ),
        );
        let e = run(&s, &dir, true).unwrap().expect_err("bad clip");
        assert!(
            e.to_string().contains(word) && e.to_string().contains("RiggedSimple"),
            "{e}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_example_scene_parses() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&p).unwrap();
        if text.contains("shared/data") && !Path::new(SHARED_DATA).exists() {
            eprintln!("skipping {}: ../shared/data not found", p.display());
            continue;
        }
        Scene::load(&p).unwrap_or_else(|e| panic!("{e}"));
        n += 1;
    }
    assert!(n >= 2, "the bundled scenes at least");
}

#[test]
fn a_flipbook_scene_loads_every_frame_and_builds_topology_once() {
    let dir = scratch("flipbook");
    let m = shapecue::mesh::torus(1.0, 0.4, 24, 12);
    for f in 0..4 {
        // Frame f: the torus squashed along z by a growing amount.
        let s = 1.0 - 0.15 * f as f64;
        let squashed = m.positions.iter().map(|p| [p[0], p[1], p[2] * s]);
        let obj = common::obj_text(squashed, &m.faces);
        std::fs::write(dir.join(format!("frame_{f}.obj")), obj).unwrap();
    }
    let s = scene(
        &dir,
        "[input]\nflipbook = \"frame_*.obj\"\n[frames]\nstart = 1\n[effects]\nshading = {}\n\
         ao = {}\nfeature_edges = { caps = \"mh\" }\n[output]\nsize = [48, 48]\n",
    );
    let Some(r) = run(&s, &dir, false) else {
        return;
    };
    let r = r.unwrap();
    check_minimal(&r, "flipbook");
    assert_eq!(r.frames, vec![1, 2, 3]);
    let runs = |p: Pass| r.passes.iter().find(|x| x.pass == p).map(|x| x.runs);
    assert_eq!(runs(Pass::LoadFrame), Some(3));
    assert_eq!(runs(Pass::EdgeBuffer), Some(1));
    assert_eq!(runs(Pass::CapBuffer), None, "mh caps need no cap buffer");
    assert_eq!(runs(Pass::Caps), Some(3));
    // A frame with another topology is an error naming the file.
    std::fs::write(
        dir.join("frame_9.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let s = scene(
        &dir,
        "[input]\nflipbook = \"frame_*.obj\"\n[effects]\nshading = {}\n[output]\nsize = [48, 48]\n",
    );
    let e = run(&s, &dir, true).unwrap().expect_err("topology changes");
    assert!(e.to_string().contains("frame_9.obj"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn nasty_meshes_render_with_every_cue() {
    // A small torus far from the origin, a zero-area face, a duplicated face
    // and an unreferenced vertex at 1e30: every cue still runs, the camera
    // frames the torus, and the image is not empty.
    let dir = scratch("nasty");
    let m = shapecue::mesh::torus(1.0, 0.4, 32, 16);
    let mut obj = String::new();
    for p in &m.positions {
        obj.push_str(&format!(
            "v {} {} {}\n",
            1e5 + 1e-3 * p[0],
            -2e5 + 1e-3 * p[1],
            1e-3 * p[2]
        ));
    }
    obj.push_str("v 1e30 1e30 1e30\n");
    for t in &m.faces {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    let f0 = m.faces[0];
    obj.push_str(&format!("f {} {} {}\n", f0[0] + 1, f0[1] + 1, f0[2] + 1));
    obj.push_str(&format!("f {} {} {}\n", f0[0] + 1, f0[0] + 1, f0[1] + 1));
    std::fs::write(dir.join("nasty.obj"), obj).unwrap();
    let fx: String = CUES.iter().map(|c| format!("{}\n", c.0)).collect();
    let s = scene(
        &dir,
        &format!(
            "[input]\nmesh = \"nasty.obj\"\n[[camera]]\ndirection = [0.0, 0.3, 1.0]\n[effects]\n{fx}\
             [output]\nsize = [64, 64]\nmsaa = 0\n"
        ),
    );
    let Some(r) = run(&s, &dir, false) else {
        return;
    };
    let r = r.unwrap();
    check_minimal(&r, "nasty");
    let img = image::open(&r.outputs[0]).unwrap().to_rgb8();
    let drawn = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    assert!(
        drawn > 300,
        "the torus covers the middle of the image: {drawn} pixels"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_inside_of_a_volume_decides_convex_or_concave() {
    // A sphere SDF: the ball (below 0) is convex, red; the space around it
    // (above 0) sees the same surface as concave, blue.
    for (inside, want_red) in [("below", true), ("above", false)] {
        let dir = scratch("inside");
        let s = scene(
            &dir,
            &format!(
                "[input]\nsdf = \"sphere\"\nresolution = 48\ninside = \"{inside}\"\n[effects]\n\
                 curvature_colors = {{ scale = 0.5 }}\n[output]\nsize = [64, 64]\nmsaa = 0\n"
            ),
        );
        let Some(r) = run(&s, &dir, false) else {
            return;
        };
        let img = image::open(&r.unwrap().outputs[0]).unwrap().to_rgb8();
        let [pr, _, pb] = img.get_pixel(32, 32).0.map(i32::from);
        assert_eq!(
            pr > pb + 40,
            want_red,
            "{inside}: centre pixel {:?}",
            img.get_pixel(32, 32)
        );
        assert_eq!(
            pb > pr + 40,
            !want_red,
            "{inside}: centre pixel {:?}",
            img.get_pixel(32, 32)
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn curvature_strokes_on_a_volume_run_their_pass_and_draw() {
    // Strokes alone (the isosurface flat, hiding the far side) and over
    // shading, two views: the strokes pass runs once per pose, no mesh
    // curvature pass runs, the PNGs are written.
    for (fx, with_shading) in [
        ("curvature_strokes = {}\n", false),
        (
            "shading = {}\ncurvature_strokes = { color = [0.6, 0.1, 0.1] }\n",
            true,
        ),
    ] {
        let dir = scratch("strokes");
        let s = scene(
            &dir,
            &format!(
                "[input]\nsdf = \"torus\"\nresolution = 48\n[[camera]]\norbit = 2\n\
                 [effects]\n{fx}[output]\nsize = [96, 96]\n"
            ),
        );
        let Some(r) = run(&s, &dir, false) else {
            return;
        };
        let r = r.unwrap();
        check_minimal(&r, fx);
        assert!(r.plan.contains(Pass::SdfLines) && r.plan.contains(Pass::Isosurface));
        assert!(!r.plan.contains(Pass::Curvature) && !r.plan.contains(Pass::OneRings));
        assert_eq!(r.plan.contains(Pass::VertexNormals), with_shading);
        let rec = r.passes.iter().find(|p| p.pass == Pass::SdfLines).unwrap();
        assert_eq!((rec.runs, rec.clock), (1, "kernel"), "{rec:?}");
        assert!(r.strokes > 0, "a torus has strokes");
        assert_eq!(r.outputs.len(), 2);
        for p in &r.outputs {
            let img = image::open(p).unwrap().to_rgb8();
            // Some dark stroke pixels on a white background.
            let dark = img
                .pixels()
                .filter(|q| q.0.iter().all(|&c| c < 160))
                .count();
            assert!(dark > 20, "{}: {dark} dark pixels", p.display());
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn svg_contours_are_joined_by_mesh_edge_into_few_polylines_one_group_per_cue() {
    // An oblique view of a torus: its occluding contour is a few long curves.
    // Segments used to be written one polyline each (hundreds of two-point
    // polylines) in an order that varied from run to run.
    let text = "[input]\ngenerate = \"torus\"\nresolution = 20000\n[[camera]]\n\
                direction = [0.0, -1.0, -1.2]\n[effects]\ncontours = {}\n\
                suggestive_contours = {}\nfeature_edges = { crease = 60 }\n[output]\n\
                size = [240, 180]\nformats = [\"svg\"]\n";
    let mut texts = Vec::new();
    for round in 0..2 {
        let dir = scratch(&format!("svg-join-{round}"));
        let s = scene(&dir, text);
        let Some(r) = run(&s, &dir, false) else {
            return;
        };
        let r = r.unwrap();
        assert!(r.segments[0] > 100, "{:?}", r.segments);
        texts.push(std::fs::read_to_string(&r.outputs[0]).unwrap());
        let _ = std::fs::remove_dir_all(&dir);
    }
    assert_eq!(texts[0], texts[1], "the SVG is the same on every run");
    let t = &texts[0];
    for id in ["contours", "suggestive", "feature-edges"] {
        assert!(
            t.contains(&format!("<g id=\"{id}\" class=\"{id}\"")),
            "group {id} missing:\n{t}"
        );
    }
    let contours = t
        .split("<g id=\"contours\"")
        .nth(1)
        .and_then(|g| g.split("</g>").next())
        .unwrap();
    let lens: Vec<usize> = contours
        .lines()
        .filter(|l| l.starts_with("<polyline"))
        .map(|l| l.matches(',').count())
        .collect();
    let segments: usize = lens.iter().map(|n| n - 1).sum();
    assert!(!lens.is_empty() && lens.iter().all(|&n| n >= 2), "{lens:?}");
    assert!(
        lens.len() * 10 < segments,
        "{} polylines for {segments} visible pieces: {lens:?}",
        lens.len()
    );
}

#[test]
fn a_scene_that_fails_midway_leaves_no_images_and_no_new_folder() {
    // Three good frames, then one with another topology: the first frames
    // render, the fourth fails; the images already written and the output
    // folders the run created are removed, a file that was there stays.
    let dir = scratch("fail-midway");
    let m = shapecue::mesh::torus(1.0, 0.4, 24, 12);
    let obj = common::obj_text(m.positions.iter().copied(), &m.faces);
    for f in 0..3 {
        std::fs::write(dir.join(format!("frame_{f}.obj")), &obj).unwrap();
    }
    std::fs::write(
        dir.join("frame_9.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let s = scene(
        &dir,
        "[input]\nflipbook = \"frame_*.obj\"\n[effects]\nshading = {}\n[output]\nsize = [32, 32]\n",
    );
    let out = dir.join("new/deeper");
    let opts = ExecOptions {
        out_dir: Some(out.clone()),
        force: false,
        device: None,
        ..Default::default()
    };
    let Some(r) = unless_no_gl(exec::run(&s, &opts, &mut |_, _| {})) else {
        return;
    };
    let e = r.expect_err("frame 9 has another topology");
    assert!(e.to_string().contains("frame_9.obj"), "{e}");
    let listing: Vec<_> = walk(&dir.join("new"));
    assert!(
        !dir.join("new").exists(),
        "the run's folders are removed: {listing:?}"
    );
    // Into an existing folder: the run's own images go, the user's file stays.
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let e = exec::run(&s, &opts, &mut |_, _| {}).expect_err("still fails");
    assert!(e.to_string().contains("frame_9.obj"), "{e}");
    let left: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, vec![std::ffi::OsString::from("notes.txt")]);
    let _ = std::fs::remove_dir_all(&dir);
}

fn walk(d: &Path) -> Vec<std::path::PathBuf> {
    let mut v = Vec::new();
    if let Ok(rd) = std::fs::read_dir(d) {
        for e in rd.flatten() {
            v.push(e.path());
            v.extend(walk(&e.path()));
        }
    }
    v
}

#[test]
fn scenes_in_one_session_share_the_device_and_the_gl_context_and_draw_the_same() {
    // Three scenes of other sizes and antialiasing, run one after another
    // in one session (one renderer, reconfigured) and each on its own: the
    // images are the same bytes.
    let dir = scratch("session");
    let text = |size: [u32; 2], msaa: u32, cues: &str| {
        format!(
            "[input]\ngenerate = \"torus\"\nresolution = 3000\n[[camera]]\norbit = 2\n\
             [effects]\n{cues}\n[output]\nsize = [{}, {}]\nmsaa = {msaa}\nformats = [\"png\"]\n",
            size[0], size[1]
        )
    };
    let specs = [
        ([96, 72], 4, "shading = {}\ncontours = {}"),
        (
            [64, 64],
            0,
            "curvature_colors = {}\nfeature_edges = { crease = 20 }",
        ),
        ([96, 72], 2, "ao = {}\nsuggestive_contours = {}"),
    ];
    let mut scenes = Vec::new();
    for (i, (size, msaa, cues)) in specs.iter().enumerate() {
        let p = dir.join(format!("s{i}.toml"));
        std::fs::write(&p, text(*size, *msaa, cues)).unwrap();
        scenes.push(Scene::load(&p).unwrap());
    }
    let opts = |sub: &str| ExecOptions {
        out_dir: Some(dir.join(sub)),
        force: false,
        device: None,
        ..Default::default()
    };
    let mut session = exec::Session::new();
    for s in &scenes {
        let Some(r) = unless_no_gl(session.run(s, &opts("together"), &mut |_, _| {})) else {
            return;
        };
        check_minimal(&r.unwrap(), "in one session");
    }
    for s in &scenes {
        exec::run(s, &opts("alone"), &mut |_, _| {}).unwrap();
    }
    let pngs = |sub: &str| {
        let mut v: Vec<_> = walk(&dir.join(sub))
            .into_iter()
            .filter(|p| p.extension().is_some_and(|e| e == "png"))
            .collect();
        v.sort();
        v
    };
    let (together, alone) = (pngs("together"), pngs("alone"));
    assert_eq!(
        together.len(),
        3 * 2,
        "two views of three scenes: {together:?}"
    );
    assert_eq!(together.len(), alone.len());
    for (a, b) in together.iter().zip(&alone) {
        assert_eq!(a.file_name(), b.file_name());
        assert!(
            std::fs::read(a).unwrap() == std::fs::read(b).unwrap(),
            "{} differs between the session and a run of its own",
            a.display()
        );
    }
}

#[test]
fn the_isosurface_pass_counts_every_step_of_an_extraction() {
    // A scene's isosurface pass joins its kernel time to the plan by steps:
    // each step a direct-numbering extraction runs must be one of them, or
    // the report under-counts the pass (it once counted 0.04 of 9.2 ms).
    use shapecue::spec::vertex_fusion::Fusion;
    use shapecue::stages::marching_cubes::Isosurfacer;
    let gpu = common::gpu();
    for (kind, iso) in [("gyroid", 0.0f32), ("sphere", 0.0)] {
        let v = shapecue::volume::sdf::sdf_by_name(kind, 48).unwrap();
        let mut ex = Isosurfacer::new(gpu.clone(), &v).unwrap();
        for fusion in [Fusion::Direct, Fusion::Edge, Fusion::Hash] {
            let s = ex.extract(iso, fusion).unwrap();
            assert!(s.timing.kernel_ms > 0.0);
            for st in &s.timing.steps {
                assert!(
                    Pass::Isosurface.kernels().contains(&st.step),
                    "{kind} {fusion:?}: {:?} is not counted in the isosurface pass",
                    st.step
                );
            }
        }
    }
}

#[test]
fn a_scene_with_lines_says_what_scaled_their_thresholds() {
    // rtsc's feature size by default, the median edge length where asked;
    // the same number `shapecue lines` uses on the same mesh.
    for (table, want) in [
        ("", "rtsc's"),
        ("[lines]\nfeature_size = \"edge\"\n", "median edge"),
    ] {
        let dir = scratch("fs-note");
        let s = scene(
            &dir,
            &format!(
                "[input]\ngenerate = \"torus\"\nresolution = 3000\n[effects]\n\
                 suggestive_contours = {{}}\n{table}[output]\nsize = [96, 72]\n"
            ),
        );
        let Some(r) = run(&s, &dir, false) else {
            return;
        };
        let r = r.unwrap();
        let note = r
            .notes
            .iter()
            .find(|n| n.contains("feature size"))
            .unwrap_or_else(|| panic!("no feature-size note in {:?}", r.notes));
        assert!(note.contains(want), "{note}");
        let fs: f64 = note
            .split("feature size ")
            .nth(1)
            .and_then(|t| t.split_whitespace().next())
            .and_then(|t| t.parse().ok())
            .unwrap();
        let m = shapecue::mesh::generated_by_name("torus", 3000).unwrap().1;
        if want == "median edge" {
            let edge = shapecue::mesh::feature_size(&m.positions, &m.faces);
            assert!((fs - edge).abs() < 1e-3 * edge, "{fs} vs {edge}");
        } else {
            let gpu = common::gpu();
            let ls = shapecue::api::line_segments_on(
                &gpu,
                &m,
                shapecue::spec::view::View::from_eye([3.0, 0.0, 2.0], false),
                &Default::default(),
                &Default::default(),
            )
            .unwrap();
            let lines_fs = f64::from(ls.feature_size);
            assert!(
                (fs - lines_fs).abs() < 1e-3 * lines_fs,
                "{fs} vs {lines_fs}"
            );
        }
    }
}
