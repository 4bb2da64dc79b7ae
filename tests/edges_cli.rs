//! `shapecue edges` from the command line: PNG, SVG and stats, bad input,
//! and the view framed without an eye (GL needed; skipped without EGL).

mod common;

use common::{cli, cli_gl_missing, run_cli, scratch};

use shapecue::mesh;

/// A unit cube as OBJ text (8 shared vertices, 12 triangles).
fn cube_obj() -> String {
    let m = mesh::cube(1.0);
    common::obj_text(m.positions.iter().copied(), &m.faces)
}

#[test]
fn cli_renders_png_svg_and_stats() {
    let d = scratch("render");
    let obj = d.join("cube.obj");
    std::fs::write(&obj, cube_obj()).unwrap();
    let (png, svg, json) = (d.join("c.png"), d.join("c.svg"), d.join("c.json"));
    let out = cli()
        .args([
            "edges",
            obj.to_str().unwrap(),
            "--eye",
            "3,2,4",
            "--caps",
            "adjacency",
            "--width",
            "6",
        ])
        .args([
            "--size",
            "200x150",
            "-o",
            png.to_str().unwrap(),
            "--svg",
            svg.to_str().unwrap(),
        ])
        .args(["--stats", json.to_str().unwrap()])
        .output()
        .unwrap();
    if cli_gl_missing(&out) {
        return;
    }
    common::assert_succeeded(&out);
    let img = image::open(&png).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (200, 150));
    assert!(
        img.pixels().filter(|p| p[0] < 40).count() > 100,
        "black edge pixels"
    );
    let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(s["edges"], 18);
    assert_eq!(s["crease"], 12);
    assert_eq!(s["interop"]["shared"], false);
    assert!(
        s["interop"]["reason"]
            .as_str()
            .unwrap()
            .contains("host path")
    );
    // From (3,2,4), 9 of the cube's 12 edges are visible (the 3 at the far corner are hidden).
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("stroke-width=\"6\""));
    let n = s["svg_polylines"].as_u64().unwrap();
    assert!((1..=9).contains(&n), "{n} polylines");
    let pts: usize = text
        .lines()
        .filter(|l| l.starts_with("<polyline"))
        .map(|l| l.matches(',').count())
        .sum();
    assert!(
        pts >= 9 + n as usize,
        "visible edges joined into polylines: {pts} points"
    );
    // The output exists now: refused without --force.
    let again = run_cli([
        "edges",
        obj.to_str().unwrap(),
        "--eye",
        "3,2,4",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
}

#[test]
fn cli_bad_input_is_a_clear_error() {
    let d = scratch("bad");
    let obj = d.join("cube.obj");
    std::fs::write(&obj, cube_obj()).unwrap();
    let png = d.join("x.png");
    let run = |extra: &[&str]| {
        let out = cli()
            .args(["edges", obj.to_str().unwrap(), "-o", png.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let (code, err) = run(&["--eye", "5,5,5", "--interop", "on"]);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("cl_khr_gl_sharing") && err.contains("cl_khr_external_memory_opaque_fd"),
        "{err}"
    );
    let (code, err) = run(&["--eye", "5,5,5", "--caps", "round"]);
    assert_eq!(code, Some(1));
    assert!(err.contains("unknown cap mode \"round\""), "{err}");
    let (_, err) = run(&["--eye", "5,5,5", "--width", "0"]);
    assert!(err.contains("--width 0"), "{err}");
    let (_, err) = run(&["--eye", "5,5,5", "--width", "-3"]);
    assert!(err.contains("--width -3"), "{err}");
    let (_, err) = run(&["--eye", "0,0,0", "--target", "0,0,0"]);
    assert!(err.contains("coincide"), "{err}");
    let (_, err) = run(&["--eye", "NaN,0,1"]);
    assert!(err.contains("--eye"), "{err}");
    let (_, err) = run(&["--eye", "1,2"]);
    assert!(err.contains("three finite numbers"), "{err}");
    let (_, err) = run(&["--eye", "5,5,5", "--size", "0x10"]);
    assert!(err.contains("--size"), "{err}");
    let marks = d.join("marks.txt");
    std::fs::write(&marks, "0 1\n0 7\n").unwrap();
    let (_, err) = run(&["--eye", "5,5,5", "--marked", marks.to_str().unwrap()]);
    assert!(
        err.contains("marks.txt: marked edge 2 (0, 7): not an edge"),
        "{err}"
    );
    std::fs::write(&marks, "0 1\nzero one\n").unwrap();
    let (_, err) = run(&["--eye", "5,5,5", "--marked", marks.to_str().unwrap()]);
    assert!(err.contains("marks.txt: line 2"), "{err}");
    assert!(!png.exists());
}

#[test]
fn cli_without_an_eye_frames_the_mesh() {
    // A cube 0.02 across, far off the origin: with a fixed eye it would be a
    // few pixels; fitted, it fills most of the image and is not cut off.
    let d = scratch("framed");
    let obj = d.join("small.obj");
    let m = mesh::cube(0.02);
    let moved = m.positions.iter().map(|p| [p[0] + 10.0, p[1] - 3.0, p[2]]);
    std::fs::write(&obj, common::obj_text(moved, &m.faces)).unwrap();
    let png = d.join("small.png");
    let out = run_cli([
        "edges",
        obj.to_str().unwrap(),
        "--size",
        "240x200",
        "-o",
        png.to_str().unwrap(),
    ]);
    if cli_gl_missing(&out) {
        return;
    }
    common::assert_succeeded(&out);
    let img = image::open(&png).unwrap().to_rgba8();
    let (mut lo, mut hi) = ([u32::MAX; 2], [0u32; 2]);
    for (x, y, p) in img.enumerate_pixels() {
        if p[0] < 250 || p[1] < 250 || p[2] < 250 {
            lo = [lo[0].min(x), lo[1].min(y)];
            hi = [hi[0].max(x), hi[1].max(y)];
        }
    }
    let (w, h) = (
        hi[0] + 1 - lo[0].min(hi[0] + 1),
        hi[1] + 1 - lo[1].min(hi[1] + 1),
    );
    assert!(
        h * 10 >= 200 * 6,
        "drawn {w}x{h} pixels of 240x200 ({lo:?}..{hi:?})"
    );
    assert!(
        lo[0] > 0 && lo[1] > 0 && hi[0] < 239 && hi[1] < 199,
        "not cut off: {lo:?}..{hi:?}"
    );
    // --target alone is refused (the fitted view looks at the centre).
    let out = run_cli([
        "edges",
        obj.to_str().unwrap(),
        "--target",
        "0,0,0",
        "-o",
        d.join("t.png").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--target needs --eye"));
}

/// The visible polyline length of an SVG's `points` attributes, in pixels.
fn svg_visible_length(svg: &std::path::Path) -> f64 {
    let t = std::fs::read_to_string(svg).unwrap();
    let mut total = 0.0;
    for part in t.split("points=\"").skip(1) {
        let pts: Vec<(f64, f64)> = part[..part.find('"').unwrap()]
            .split_whitespace()
            .map(|p| {
                let (x, y) = p.split_once(',').unwrap();
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect();
        total += pts
            .windows(2)
            .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
            .sum::<f64>();
    }
    total
}

#[test]
fn svg_visibility_does_not_depend_on_the_stroke_width() {
    // Wide strokes once hid the lines beside them: their quads were in the
    // depth buffer the SVG's visibility test reads (a width of 50 kept a
    // seventh of Spot's contours). Only the surface may hide a line.
    let d = scratch("svg-width");
    let spot = concat!(env!("CARGO_MANIFEST_DIR"), "/data/spot.obj");
    for cmd in ["lines", "edges"] {
        let mut lengths = Vec::new();
        for width in ["2", "50"] {
            let svg = d.join(format!("{cmd}-{width}.svg"));
            let png = d.join(format!("{cmd}-{width}.png"));
            let args: Vec<&str> = if cmd == "lines" {
                vec!["lines", spot, "-o", svg.to_str().unwrap(), "--width", width]
            } else {
                let (p, s) = (png.to_str().unwrap(), svg.to_str().unwrap());
                vec!["edges", spot, "-o", p, "--svg", s, "--width", width]
            };
            let out = run_cli(&args);
            if cli_gl_missing(&out) {
                return;
            }
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            lengths.push(svg_visible_length(&svg));
        }
        let (thin, wide) = (lengths[0], lengths[1]);
        assert!(thin > 100.0, "{cmd}: {thin} px of visible lines");
        assert!(
            (wide - thin).abs() <= 0.02 * thin,
            "{cmd}: {thin} px visible at width 2, {wide} px at width 50"
        );
    }
}
