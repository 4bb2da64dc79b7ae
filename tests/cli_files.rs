//! The command line and the files it reads and writes: a volume's detached
//! data file is an input, scenes' outputs are checked together before any
//! runs, meshes too large or small to draw are refused by name, and so are
//! image names, widths, sizes and thresholds out of range.

mod common;

use common::{cli, run_cli, scratch};

/// A 4³ u8 volume as a detached NRRD header `v.nhdr` and its data file
/// `v.raw` in `d`: (header, data file).
fn tiny_nhdr(d: &std::path::Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let raw = d.join("v.raw");
    std::fs::write(&raw, (0..64u8).collect::<Vec<_>>()).unwrap();
    let nhdr = d.join("v.nhdr");
    std::fs::write(
        &nhdr,
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\ndata file: v.raw\n",
    )
    .unwrap();
    (nhdr, raw)
}

#[test]
fn a_volume_data_file_is_an_input() {
    let d = scratch("nhdr-data");
    let (nhdr, raw) = tiny_nhdr(&d);
    let out = cli()
        .arg("isosurface")
        .arg(&nhdr)
        .args(["--iso", "30", "-o"])
        .arg(&raw)
        .arg("--force")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("input file"), "{e}");
    assert_eq!(std::fs::read(&raw).unwrap().len(), 64);
}

/// `shapecue strokes` protects a volume's detached data file like the
/// isosurface command does, and checks outputs before any conversion.
#[test]
fn strokes_never_writes_over_a_volume_data_file() {
    let d = scratch("strokes-nhdr");
    let (nhdr, raw) = tiny_nhdr(&d);
    let out = cli()
        .arg("strokes")
        .arg(&nhdr)
        .args(["--iso", "30", "-o"])
        .arg(d.join("s.png"))
        .arg("--stats")
        .arg(&raw)
        .arg("--force")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("input file"), "{e}");
    assert_eq!(std::fs::read(&raw).unwrap(), (0..64u8).collect::<Vec<_>>());
}

#[test]
fn render_refuses_two_scenes_writing_the_same_files_before_either_runs() {
    let d = scratch("render-collide");
    let text = "[input]\ngenerate = \"torus\"\nresolution = 2000\n[[camera]]\norbit = 1\n\
                [effects]\nshading = {}\n[output]\nname = \"same\"\nsize = [32, 32]\n";
    let (a, b) = (d.join("a.toml"), d.join("b.toml"));
    std::fs::write(&a, text).unwrap();
    std::fs::write(&b, text).unwrap();
    let out = d.join("out");
    let r = run_cli([
        "render",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("a.toml") && err.contains("b.toml") && err.contains("same_report.json"),
        "{err}"
    );
    assert!(!out.exists(), "nothing ran, nothing was written");
    let _ = std::fs::remove_dir_all(&d);
}

/// Three scenes whose third is a flipbook with a frame of another
/// topology: the run fails before the first scene renders, naming the
/// scene file, the frame and its file, and writes nothing; with the frame
/// repaired, all three render, the flipbook from the input the check loaded.
#[test]
fn render_checks_the_third_scene_s_flipbook_before_the_first_runs() {
    let d = scratch("render-flipbook-check");
    let frames = d.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    let m = shapecue::mesh::icosphere(1.0, 1);
    for f in 0..3 {
        let s = 1.0 + 0.1 * f as f64;
        let pos = m.positions.iter().map(|p| p.map(|c| c * s));
        std::fs::write(
            frames.join(format!("f_{f}.obj")),
            common::obj_text(pos, &m.faces),
        )
        .unwrap();
    }
    let fine = |name: &str| {
        format!(
            "[input]\ngenerate = \"sphere\"\nresolution = 50\n[effects]\nshading = {{}}\n\
             [output]\nname = \"{name}\"\nsize = [16, 16]\n"
        )
    };
    let paths: Vec<std::path::PathBuf> = ["a", "b", "c"]
        .iter()
        .map(|n| d.join(format!("{n}.toml")))
        .collect();
    std::fs::write(&paths[0], fine("a")).unwrap();
    std::fs::write(&paths[1], fine("b")).unwrap();
    std::fs::write(
        &paths[2],
        "[input]\nflipbook = \"frames/f_*.obj\"\n[effects]\nshading = {}\n\
         [output]\nname = \"c\"\nsize = [16, 16]\n",
    )
    .unwrap();
    let other = shapecue::mesh::icosphere(1.0, 2);
    std::fs::write(
        frames.join("f_2.obj"),
        common::obj_text(other.positions.iter().copied(), &other.faces),
    )
    .unwrap();
    let out = d.join("out");
    let args = |extra: &[&str]| {
        let mut v: Vec<String> = vec!["render".into()];
        v.extend(paths.iter().map(|p| p.display().to_string()));
        v.extend(["--out".into(), out.display().to_string()]);
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let r = run_cli(args(&[]));
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("c.toml")
            && err.contains("flipbook frame 2")
            && err.contains("f_2.obj")
            && err.contains("vertices"),
        "{err}"
    );
    assert!(!out.exists(), "nothing ran, nothing was written");

    let s = 1.2;
    let pos = m.positions.iter().map(|p| p.map(|c| c * s));
    std::fs::write(frames.join("f_2.obj"), common::obj_text(pos, &m.faces)).unwrap();
    let r = run_cli(args(&[]));
    if common::cli_gl_missing(&r) {
        let _ = std::fs::remove_dir_all(&d);
        return;
    }
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    for f in [
        "a_report.json",
        "b_report.json",
        "c_f0002_v00.png",
        "c_report.json",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn meshes_too_large_or_small_to_draw_in_single_precision_are_refused_by_name() {
    // A unit sphere scaled by 1e30 and by 1e-30: curvature works on both (it
    // normalises); drawing refuses them with the range instead of a camera
    // of infinities.
    let d = scratch("undrawable");
    for (scale, word) in [(1e30, "below"), (1e-30, "at least")] {
        let m = shapecue::mesh::icosphere(1.0, 2);
        let scaled = m.positions.iter().map(|p| p.map(|c| c * scale));
        let obj = common::obj_text(scaled, &m.faces);
        let path = d.join(format!("s{scale:e}.obj"));
        std::fs::write(&path, obj).unwrap();
        let png = d.join("x.png");
        let r = run_cli([
            "edges",
            path.to_str().unwrap(),
            "--eye",
            &format!("{:e},{:e},{:e}", 3.0 * scale, 2.0 * scale, scale),
            "-o",
            png.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(1), "{err}");
        assert!(err.contains("rescale") && err.contains(word), "{err}");
        assert!(!err.contains("Vec3") && !err.contains("Camera {"), "{err}");
        assert!(!png.exists());
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// An image name that is not `.png` is refused (the bytes would be PNG),
/// and a width past the image is refused.
#[test]
fn jpeg_names_and_huge_widths_are_refused() {
    let d = scratch("refusals");
    let run = |args: &[&str]| {
        let o = cli().args(args).output().unwrap();
        assert!(!o.status.success(), "{args:?} should fail");
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let jpg = d.join("o.jpg");
    let j = jpg.to_str().unwrap();
    let e = run(&["strokes", "--sdf", "sphere", "--resolution", "16", "-o", j]);
    assert!(e.contains(".png"), "{e}");
    let e = run(&["edges", "missing.obj", "-o", j]);
    assert!(e.contains(".png"), "{e}");
    assert!(!jpg.exists());
    let e = run(&["edges", "missing.obj", "--width", "1e30", "-o", "x.png"]);
    assert!(e.contains("--width") && e.contains("at most"), "{e}");
    // The lines command checks the same, and its generated meshes' size,
    // before allocating (a huge --vertices aborted on allocation).
    let svg = d.join("l.svg");
    let s = svg.to_str().unwrap();
    let e = run(&["lines", "torus", "--width", "1e9", "-o", s]);
    assert!(e.contains("--width") && e.contains("at most"), "{e}");
    let e = run(&["lines", "torus", "--vertices", "100000000000", "-o", s]);
    assert!(e.contains("--vertices") && e.contains("limit"), "{e}");
    let e = run(&["lines", "torus", "--vertices", "0", "-o", s]);
    assert!(e.contains("--vertices") && e.contains("at least 3"), "{e}");
    let e = run(&[
        "lines",
        "torus",
        "--vertices",
        "2000",
        "--sc-threshold",
        "nan",
        "-o",
        s,
    ]);
    assert!(e.contains("suggestive-contour threshold"), "{e}");
    assert!(!svg.exists());
    // Strokes with no surface say why in the user's terms: an open mesh,
    // or the range of the values as given (density volumes are negated
    // inside, which the range once showed).
    let tri = d.join("tri.obj");
    std::fs::write(&tri, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let png = d.join("s.png");
    let p = png.to_str().unwrap();
    let e = run(&["strokes", tri.to_str().unwrap(), "-o", p]);
    assert!(e.contains("closed"), "{e}");
    let raw = d.join("ramp.raw");
    let ramp: Vec<u8> = (0..512u32)
        .flat_map(|i| (1.0 + (i % 8) as f32).to_le_bytes())
        .collect();
    std::fs::write(&raw, ramp).unwrap();
    let r = raw.to_str().unwrap();
    let dims = ["--dims", "8,8,8", "--type", "f32"];
    let e = run(&[&["strokes", r, "--iso", "20", "-o", p][..], &dims[..]].concat());
    assert!(e.contains("span 1 to 8"), "{e}");
    // A field of view out of range is named as such, not as an infinite eye.
    for fov in ["0", "nan"] {
        let e = run(&[
            "lines",
            "torus",
            "--vertices",
            "2000",
            "--fov",
            fov,
            "-o",
            p,
        ]);
        assert!(e.contains("field of view") && !e.contains("inf"), "{e}");
    }
    assert!(!png.exists());
}
