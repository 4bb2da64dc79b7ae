//! Vector output with no OpenGL: `lines`, `edges` and a scene write SVG
//! (and segments) with exact visibility while no EGL vendor can be found
//! (`__EGL_VENDOR_LIBRARY_DIRS` at an empty folder), and agree with the
//! depth-buffer method's SVG (where GL is available) on how much line is
//! visible.

mod common;

use common::{assert_succeeded, cli, cli_gl_missing, cli_no_gl, scratch};
use std::path::Path;
use std::process::Output;

/// The command with no EGL vendor to load.
fn no_gl(dir: &Path, args: &[&str]) -> Output {
    cli_no_gl(dir).args(args).output().unwrap()
}

fn ok(out: &Output) {
    assert_succeeded(out);
}

/// The polylines of each SVG group: (id, polylines, length in pixels).
fn groups(svg: &str) -> Vec<(String, usize, f64)> {
    let mut out = Vec::new();
    for g in svg.split("<g id=\"").skip(1) {
        let id = g.split('"').next().unwrap().to_string();
        let body = g.split("</g>").next().unwrap();
        let mut n = 0;
        let mut len = 0.0;
        for pl in body.split("points=\"").skip(1) {
            let pts: Vec<[f64; 2]> = (pl.split('"').next().unwrap().split_whitespace())
                .map(|p| {
                    let mut c = p.split(',').map(|x| x.parse::<f64>().unwrap());
                    [c.next().unwrap(), c.next().unwrap()]
                })
                .collect();
            n += 1;
            len += (pts.windows(2))
                .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt())
                .sum::<f64>();
        }
        out.push((id, n, len));
    }
    out
}

fn spot() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/data/spot.obj").to_string()
}

#[test]
fn lines_write_svg_and_segments_with_no_gl() {
    let d = scratch("lines-no-gl");
    let (svg, json) = (d.join("spot.svg"), d.join("spot.json"));
    let out = no_gl(
        &d,
        &[
            "lines",
            &spot(),
            "--lines",
            "contours,suggestive,ridges",
            "-o",
            svg.to_str().unwrap(),
            "--segments",
            json.to_str().unwrap(),
        ],
    );
    ok(&out);
    let text = std::fs::read_to_string(&svg).unwrap();
    let g = groups(&text);
    let ids: Vec<&str> = g.iter().map(|x| x.0.as_str()).collect();
    assert_eq!(ids, ["contours", "suggestive", "ridges"], "{text}");
    // The contours are drawn, as chains of several segments.
    assert!(g[0].1 >= 3 && g[0].2 > 500.0, "{g:?}");
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(doc["visibility"], "exact");
    let segs = doc["segments"].as_array().unwrap();
    let visible = segs.iter().filter(|s| s["visible"] == true).count();
    let hidden = segs.iter().filter(|s| s["visible"] == false).count();
    // Spot from the default view: both visible and hidden lines.
    assert!(visible > 100 && hidden > 10, "{visible} {hidden}");
    for s in segs {
        let faces = s["faces"].as_array().unwrap();
        assert!(!faces.is_empty() && faces.len() <= 4, "{s}");
        // The face the piece lies in is one of its segment's, with each
        // end's barycentric coordinates there (each summing to 1).
        assert!(faces.contains(&s["face"]), "{s}");
        for end in s["bary"].as_array().unwrap() {
            let w: Vec<f64> = end
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-4, "{s}");
            assert!(w.iter().all(|x| *x > -1e-3), "{s}");
        }
        assert!(s["chain"].as_u64().unwrap() < doc["chains"].as_array().unwrap().len() as u64);
    }
    let mean = doc["mean_visible_chain_segments"].as_f64().unwrap();
    assert!(mean > 2.0, "{mean}");
}

#[test]
fn edges_write_svg_with_no_gl_and_refuse_other_names() {
    let d = scratch("edges-no-gl");
    let (svg, stats) = (d.join("e.svg"), d.join("e.json"));
    let out = no_gl(
        &d,
        &[
            "edges",
            &spot(),
            "-o",
            svg.to_str().unwrap(),
            "--stats",
            stats.to_str().unwrap(),
        ],
    );
    ok(&out);
    let g = groups(&std::fs::read_to_string(&svg).unwrap());
    assert_eq!(g.len(), 1);
    assert_eq!(g[0].0, "feature-edges");
    assert!(g[0].1 > 10 && g[0].2 > 1000.0, "{g:?}");
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    // No frame drawn: the edges are read back, no caps are made.
    assert_eq!(doc["interop"]["route"], "host", "{doc}");
    assert_eq!(doc["cap_pairs"], 0, "{doc}");
    assert!(doc["phases_ms"]["visibility"].as_f64().unwrap() >= 0.0);
    let bad = d.join("e.ply");
    let out = no_gl(&d, &["edges", &spot(), "-o", bad.to_str().unwrap()]);
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains(".png") && e.contains(".svg"), "{e}");
    assert!(!bad.exists());
}

#[test]
fn a_scene_of_svg_only_opens_no_gl_and_reports_its_chains() {
    let d = scratch("scene-no-gl");
    let scene = d.join("cow.toml");
    std::fs::write(
        &scene,
        format!(
            "[input]\nmesh = {:?}\n[[camera]]\norbit = 3\n[effects]\ncontours = {{}}\n\
             suggestive_contours = {{}}\nfeature_edges = {{}}\nshading = {{}}\n\
             [output]\nformats = [\"svg\"]\ndir = {:?}\n",
            spot(),
            d.join("out").to_str().unwrap()
        ),
    )
    .unwrap();
    let out = no_gl(&d, &["render", scene.to_str().unwrap()]);
    ok(&out);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("out/cow_report.json")).unwrap()).unwrap();
    let passes: Vec<&str> = (report["passes"].as_array().unwrap().iter())
        .map(|p| p["pass"].as_str().unwrap())
        .collect();
    assert!(
        passes.contains(&"bvh") && passes.contains(&"visibility"),
        "{passes:?}"
    );
    assert!(
        !passes.contains(&"render") && !passes.contains(&"caps"),
        "{passes:?}"
    );
    assert!(report["renderer"].as_str().unwrap().starts_with("none"));
    assert!(
        report["chains"]["mean_length"].as_f64().unwrap() > 1.0,
        "{report}"
    );
    let bvh = (report["passes"].as_array().unwrap().iter())
        .find(|p| p["pass"] == "bvh")
        .unwrap();
    // Built once for the static mesh, however many views.
    assert_eq!(bvh["runs"], 1);
    assert_eq!(report["outputs"].as_array().unwrap().len(), 3);
}

#[test]
fn exact_and_depth_svgs_agree_on_the_visible_length() {
    let d = scratch("exact-vs-depth");
    let (exact, depth) = (d.join("exact.svg"), d.join("depth.svg"));
    let run = |o: &Path, method: &str| {
        cli()
            .args(["lines", &spot(), "--visibility", method, "-o"])
            .arg(o)
            .output()
            .unwrap()
    };
    ok(&run(&exact, "exact"));
    let out = run(&depth, "depth");
    if cli_gl_missing(&out) {
        return;
    }
    ok(&out);
    let a = groups(&std::fs::read_to_string(&exact).unwrap());
    let b = groups(&std::fs::read_to_string(&depth).unwrap());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.0, y.0);
        let rel = (x.2 - y.2).abs() / y.2.max(1.0);
        assert!(rel < 0.05, "{x:?} against {y:?}");
    }
}

/// Two icospheres crossing (the second shifted off the first's symmetry
/// planes) as one OBJ.
fn crossing_spheres_obj() -> String {
    let a = shapecue::mesh::icosphere(1.0, 3);
    let b = shapecue::mesh::icosphere(1.0, 3);
    let n = a.positions.len() as u32;
    let pos = (a.positions.iter().copied()).chain(
        b.positions
            .iter()
            .map(|p| [p[0] + 1.0, p[1] + 0.013, p[2] + 0.007]),
    );
    let faces: Vec<[u32; 3]> = (a.faces.iter().copied())
        .chain(b.faces.iter().map(|f| f.map(|v| v + n)))
        .collect();
    common::obj_text(pos, &faces)
}

#[test]
fn intersection_lines_are_a_scene_cue_chained_into_a_loop() {
    let d = scratch("intersection-lines");
    let obj = d.join("two.obj");
    std::fs::write(&obj, crossing_spheres_obj()).unwrap();
    let scene = d.join("two.toml");
    std::fs::write(
        &scene,
        format!(
            "[input]\nmesh = {:?}\n[[camera]]\ndirection = [0.3, 1.0, 0.5]\n[effects]\n\
             intersection_lines = {{ width = 1.5 }}\n[output]\nformats = [\"svg\"]\ndir = {:?}\n",
            obj.to_str().unwrap(),
            d.join("out").to_str().unwrap()
        ),
    )
    .unwrap();
    let out = no_gl(&d, &["render", scene.to_str().unwrap()]);
    ok(&out);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("out/two_report.json")).unwrap()).unwrap();
    let passes: Vec<&str> = (report["passes"].as_array().unwrap().iter())
        .map(|p| p["pass"].as_str().unwrap())
        .collect();
    assert_eq!(
        passes,
        ["bvh", "intersections", "visibility", "svg"],
        "{report}"
    );
    let svg = std::fs::read_to_string(d.join("out/two_f0000_v00.svg")).unwrap();
    let g = groups(&svg);
    assert_eq!(g.len(), 1, "{svg}");
    assert_eq!(g[0].0, "intersection-lines");
    // The circle x = 0.5 seen from the side: its near half visible, one
    // chain or a few, never one polyline per segment.
    assert!(g[0].1 >= 1 && g[0].1 <= 4 && g[0].2 > 50.0, "{g:?}");
}

#[test]
fn strokes_write_svg_with_no_gl() {
    let d = scratch("strokes-no-gl");
    let svg = d.join("torus.svg");
    let args = [
        "strokes",
        "--sdf",
        "torus",
        "--resolution",
        "48",
        "--size",
        "300x300",
        "-o",
        svg.to_str().unwrap(),
    ];
    let out = no_gl(&d, &args);
    ok(&out);
    let g = groups(&std::fs::read_to_string(&svg).unwrap());
    assert_eq!(g.len(), 1);
    assert_eq!(g[0].0, "curvature-strokes");
    // The torus seen from the fitted direction: strokes on its near side,
    // chained into polylines (not one per traced step).
    assert!(g[0].1 >= 5 && g[0].2 > 300.0, "{g:?}");
    // --svg (the facing strokes as outlines) goes beside a PNG only.
    let both = no_gl(
        &d,
        &[&args[..8], &[svg.to_str().unwrap(), "--svg", "x.svg"]].concat(),
    );
    assert!(!both.status.success());
}

/// The intersection pass's segment count, from the run report.
fn isect_segments(report: &Path) -> u64 {
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(report).unwrap()).unwrap();
    let pass = (r["passes"].as_array().unwrap().iter())
        .find(|p| p["pass"] == "intersections")
        .unwrap_or_else(|| panic!("{r}"));
    let how = pass["how"].as_str().unwrap();
    let n = how
        .split(" segments")
        .next()
        .unwrap()
        .rsplit(' ')
        .next()
        .unwrap();
    n.parse().unwrap_or_else(|_| panic!("{how}"))
}

#[test]
fn intersection_lines_cross_the_files_of_a_scene_not_each_file() {
    let d = scratch("intersection-files");
    // a: two crossing spheres (a self-intersecting file); b: a third
    // sphere crossing the first of a only.
    let a = d.join("a.obj");
    std::fs::write(&a, crossing_spheres_obj()).unwrap();
    let s = shapecue::mesh::icosphere(1.0, 3);
    let moved = |p: &[f64; 3]| [p[0] - 0.9, p[1] + 0.011, p[2] + 0.9];
    let b_pos: Vec<[f64; 3]> = s.positions.iter().map(moved).collect();
    let b = d.join("b.obj");
    std::fs::write(&b, common::obj_text(b_pos.clone(), &s.faces)).unwrap();
    let ma = shapecue::mesh::load(&a, &Default::default()).unwrap();
    let bm = shapecue::Mesh::new(b_pos, s.faces.clone(), "b").unwrap();
    let union = shapecue::Mesh::concat(&[ma, bm], "union").unwrap();
    let u = d.join("union.obj");
    std::fs::write(&u, common::obj_text(union.positions, &union.faces)).unwrap();
    let run = |name: &str, input: String| {
        let scene = d.join(format!("{name}.toml"));
        let text = format!(
            "[input]\n{input}\n[[camera]]\ndirection = [0.3, 1.0, 0.5]\n[effects]\n\
             intersection_lines = {{ width = 1.5 }}\n[output]\nformats = [\"svg\"]\ndir = {:?}\n",
            d.join(name).to_str().unwrap()
        );
        std::fs::write(&scene, text).unwrap();
        no_gl(&d, &["render", scene.to_str().unwrap()])
    };
    let q = |p: &Path| format!("{:?}", p.to_str().unwrap());
    ok(&run("files", format!("meshes = [{}, {}]", q(&a), q(&b))));
    ok(&run("a", format!("mesh = {}", q(&a))));
    ok(&run("union", format!("mesh = {}", q(&u))));
    let files = isect_segments(&d.join("files/files_report.json"));
    let own = isect_segments(&d.join("a/a_report.json"));
    let all = isect_segments(&d.join("union/union_report.json"));
    // The files' crossing alone: every crossing of the union but a's own.
    assert!(files > 50 && own > 50, "{files} {own}");
    assert_eq!(files, all - own, "files {files}, a {own}, union {all}");
    let svg = std::fs::read_to_string(d.join("files/files_f0000_v00.svg")).unwrap();
    assert_eq!(groups(&svg)[0].0, "intersection-lines");
    // One file is `mesh`; a missing file is named.
    let one = run("one", format!("meshes = [{}]", q(&a)));
    assert!(!one.status.success());
    assert!(String::from_utf8_lossy(&one.stderr).contains("two or more"));
    let gone = run(
        "gone",
        format!("meshes = [{}, {}]", q(&a), q(&d.join("nope.obj"))),
    );
    let err = String::from_utf8_lossy(&gone.stderr);
    assert!(
        !gone.status.success() && err.contains("meshes[1]") && err.contains("nope.obj"),
        "{err}"
    );
}
