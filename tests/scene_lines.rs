//! The curvature line cues of scenes on real runs: each family's cue runs
//! exactly the passes the planner gives it (the pose terms once per pose,
//! the view terms and segments once per view), draws its lines, writes one
//! SVG group per family, and the scene keys' bad values are errors naming
//! the file and the key.
//!
//! Needs OpenCL (PoCL) and headless GL; without libEGL the tests print why
//! and pass, unless `SHAPECUE_REQUIRE_GL=1` (CI).

mod common;

use common::{scratch, unless_no_gl};

use shapecue::Error;
use shapecue::scene::exec::{self, ExecOptions, RunReport};
use shapecue::scene::file::Scene;
use shapecue::scene::planner::{Cue, Input, Outputs, Pass, plan_for};
use shapecue::spec::visibility::VisibilityMethod;

/// PNG and SVG, the SVG's hidden lines found exactly.
fn both_exact() -> Outputs {
    Outputs {
        raster: true,
        vector: true,
        visibility: VisibilityMethod::Exact,
        pieces: false,
        fields: false,
        npz: false,
    }
}
use std::path::Path;

fn scene(dir: &Path, text: &str) -> Scene {
    let p = dir.join("s.toml");
    std::fs::write(&p, text).unwrap();
    Scene::load(&p).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn run(s: &Scene, dir: &Path) -> Option<Result<RunReport, Error>> {
    let opts = ExecOptions {
        out_dir: Some(dir.join("out")),
        force: true,
        device: None,
        ..Default::default()
    };
    unless_no_gl(exec::run(s, &opts, &mut |_, _| {}))
}

/// The passes that ran are exactly the planned ones, each as often as the
/// plan says (the pose terms counted where their kernel ran).
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
}

#[test]
fn each_line_cue_runs_exactly_its_passes_and_draws_its_family() {
    // A torus from two views: ridges (k1 = 1/r everywhere is no extremum,
    // but the mesh's facets give some), parabolic lines on its top and
    // bottom circles, isophotes; no boundary.
    let mut sets: Vec<Vec<Cue>> = Cue::LINE_FAMILIES.iter().map(|&c| vec![c]).collect();
    sets.push(vec![
        Cue::Ridges,
        Cue::Valleys,
        Cue::ApparentRidges,
        Cue::Isophotes,
        Cue::KZero,
        Cue::Contours,
    ]);
    for cues in sets {
        let dir = scratch("line-cues");
        let fx: String = cues
            .iter()
            .map(|c| format!("{} = {{}}\n", c.key()))
            .collect();
        let s = scene(
            &dir,
            &format!(
                "[input]\ngenerate = \"torus\"\nresolution = 3000\n[[camera]]\norbit = 2\n\
                 elevation = 35\n[effects]\n{fx}[output]\nsize = [96, 72]\n\
                 formats = [\"png\", \"svg\"]\n"
            ),
        );
        let Some(r) = run(&s, &dir) else {
            return;
        };
        let r = r.unwrap();
        let what = format!("{cues:?}");
        assert_eq!(
            r.plan,
            plan_for(&cues, Input::Static, s.effects.caps, both_exact()),
            "{what}"
        );
        check_minimal(&r, &what);
        assert_eq!(r.outputs.len(), 4, "2 views × png + svg");
        let svg = std::fs::read_to_string(
            r.outputs
                .iter()
                .find(|p| p.extension().is_some_and(|e| e == "svg"))
                .unwrap(),
        )
        .unwrap();
        for c in &cues {
            let Some(f) = c.family() else { continue };
            let id = f.name();
            assert!(
                svg.contains(&format!("<g id=\"{id}\"")),
                "{what}: group {id} missing"
            );
            assert!(r.lines.contains_key(id), "{what}: {id} not counted");
        }
        for f in ["k-zero", "isophotes"] {
            if let Some(&n) = r.lines.get(f) {
                assert!(n > 0, "{what}: a torus has {f} lines");
            }
        }
        if let Some(&n) = r.lines.get("boundaries") {
            assert_eq!(n, 0, "a torus has no boundary");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn a_flipbook_runs_the_pose_terms_once_per_pose_and_the_view_terms_per_view() {
    let dir = scratch("line-cues-flipbook");
    let m = shapecue::mesh::torus(1.0, 0.4, 32, 16);
    for f in 0..3 {
        let s = 1.0 - 0.2 * f as f64;
        let squashed = m.positions.iter().map(|p| [p[0], p[1], p[2] * s]);
        std::fs::write(
            dir.join(format!("frame_{f}.obj")),
            common::obj_text(squashed, &m.faces),
        )
        .unwrap();
    }
    let s = scene(
        &dir,
        "[input]\nflipbook = \"frame_*.obj\"\n[[camera]]\norbit = 3\n[effects]\n\
         shading = {}\nridges = { threshold = 0.05 }\nprincipal_highlights = {}\n\
         apparent_ridges = {}\nisophotes = { count = 8, light = [0, 1, 1], hidden = \"dashed\" }\n\
         [output]\nsize = [64, 48]\nformats = [\"svg\"]\n",
    );
    let Some(r) = run(&s, &dir) else {
        return;
    };
    let r = r.unwrap();
    check_minimal(&r, "flipbook lines");
    let runs = |p: Pass| r.passes.iter().find(|x| x.pass == p).map(|x| x.runs);
    assert_eq!(
        runs(Pass::LinesPose),
        Some(3),
        "once per pose, 3 views each"
    );
    assert_eq!(runs(Pass::LinesView), Some(9));
    assert_eq!(runs(Pass::LinesDt1q1), Some(9));
    assert_eq!(runs(Pass::LinesCurves), Some(9));
    assert_eq!(runs(Pass::Dcurv), Some(3));
    assert!(r.lines["isophotes"] > 0, "{:?}", r.lines);
    let svg = std::fs::read_to_string(&r.outputs[0]).unwrap();
    assert!(svg.contains("<g id=\"isophotes-hidden\""), "hidden group");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn line_cue_keys_are_checked_with_the_file_and_the_key() {
    let dir = scratch("line-cue-keys");
    let base = "[input]\ngenerate = \"torus\"\n[effects]\n";
    for (fx, words) in [
        ("ridges = { threshold = -1 }", vec!["ridges.threshold"]),
        (
            "ridges = { threshold = 0.1 }\nvalleys = { threshold = 0.2 }",
            vec!["valleys.threshold", "ridges.threshold"],
        ),
        (
            "ridges = { cull = true }\nisophotes = { cull = false }",
            vec!["isophotes.cull", "ridges.cull"],
        ),
        ("isophotes = { count = 0 }", vec!["isophotes.count"]),
        ("isophotes = { light = [0, 0, 0] }", vec!["isophotes.light"]),
        (
            "boundaries = { hidden = \"grey\" }",
            vec!["boundaries.hidden", "dashed"],
        ),
        ("k_zero = { threshold = 0.1 }", vec!["threshold"]),
        ("h_zero = { width = -2 }", vec!["h_zero.width"]),
    ] {
        let p = dir.join("bad.toml");
        std::fs::write(&p, format!("{base}{fx}\n")).unwrap();
        let e = Scene::load(&p).expect_err(fx).to_string();
        assert!(e.contains("bad.toml"), "{fx}: {e}");
        for w in words {
            assert!(e.contains(w), "{fx}: {e} lacks {w}");
        }
    }
    // Good values land in the stage's options.
    let p = dir.join("good.toml");
    std::fs::write(
        &p,
        format!(
            "{base}ridges = {{ threshold = 0.3, fade = false }}\nvalleys = {{}}\n\
             isophotes = {{ count = 7, light = [0, 2, 0] }}\napparent_ridges = {{ threshold = 0.2 }}\n"
        ),
    )
    .unwrap();
    let s = Scene::load(&p).unwrap();
    let c = s.effects.lines.curves;
    assert_eq!(c.ridge_threshold, 0.3);
    assert_eq!(c.apparent_threshold, 0.2);
    assert_eq!((c.isophotes, c.light), (7, [0.0, 2.0, 0.0]));
    assert!(!c.fade && c.cull);
    assert_eq!(c.families.iter().count(), 4);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_line_cue_on_a_nasty_open_mesh_far_from_the_origin_gives_finite_lines() {
    // A torus with a strip of faces cut away (a boundary), far from the
    // origin, with a zero-area face and an unreferenced vertex at 1e30.
    let dir = scratch("line-cues-nasty");
    let m = shapecue::mesh::torus(1.0, 0.4, 32, 16);
    let mut obj = String::new();
    for p in &m.positions {
        obj.push_str(&format!("v {} {} {}\n", 1e5 + p[0], -2e5 + p[1], p[2]));
    }
    obj.push_str("v 1e30 1e30 1e30\n");
    for t in m.faces.iter().skip(40) {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    let f0 = m.faces[50];
    obj.push_str(&format!("f {} {} {}\n", f0[0] + 1, f0[0] + 1, f0[1] + 1));
    std::fs::write(dir.join("nasty.obj"), obj).unwrap();
    let fx: String = Cue::LINE_FAMILIES
        .iter()
        .map(|c| format!("{} = {{ hidden = \"faded\" }}\n", c.key()))
        .collect();
    let s = scene(
        &dir,
        &format!(
            "[input]\nmesh = \"nasty.obj\"\n[[camera]]\ndirection = [0.0, 0.3, 1.0]\n\
             [effects]\n{fx}[output]\nsize = [64, 64]\nmsaa = 0\nformats = [\"png\", \"svg\"]\n"
        ),
    );
    let Some(r) = run(&s, &dir) else {
        return;
    };
    let r = r.unwrap();
    check_minimal(&r, "nasty lines");
    assert!(r.lines["boundaries"] > 0, "{:?}", r.lines);
    for p in &r.outputs {
        if p.extension().is_some_and(|e| e == "svg") {
            let t = std::fs::read_to_string(p).unwrap();
            assert!(!t.contains("NaN") && !t.contains("inf"), "{}", p.display());
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_skinned_scene_runs_the_pose_terms_per_frame() {
    let Some(gltf) = common::model_path("RiggedSimple.glb") else {
        return;
    };
    let dir = scratch("line-cues-skinned");
    let s = scene(
        &dir,
        &format!(
            "[input]\ngltf = {:?}\n[frames]\nend = 6\nstep = 2\n[[camera]]\norbit = 2\n\
             [effects]\nvalleys = {{}}\nh_zero = {{}}\nsuggestive_highlights = {{}}\n\
             contours = {{}}\n[output]\nsize = [64, 48]\n",
            gltf.display().to_string()
        ),
    );
    let Some(r) = run(&s, &dir) else {
        return;
    };
    let r = r.unwrap();
    check_minimal(&r, "skinned lines");
    let runs = |p: Pass| r.passes.iter().find(|x| x.pass == p).map(|x| x.runs);
    assert_eq!(runs(Pass::Skinning), Some(3));
    assert_eq!(runs(Pass::LinesPose), Some(3));
    assert_eq!(runs(Pass::LinesCurves), Some(6));
    assert_eq!(
        runs(Pass::LinesView),
        None,
        "no family here reads the view terms"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
