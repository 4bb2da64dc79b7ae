//! `shapecue report <topic>`: each topic on a tiny size prints its Markdown
//! table under the header line (date, device, command), writes its numbers
//! as JSON and its charts as SVG; the old report flags are gone, and an
//! unknown topic is a clear error.

mod common;

use common::{cli, run_cli, scratch};
use serde_json::Value;
use std::path::Path;

/// Runs `shapecue report <args> --json --plot` in a fresh folder; checks
/// the header line, the JSON's keys (the tables named in `tables` and the
/// row fields in `fields`) and the SVG. Returns the Markdown and the
/// JSON, or `None` when the topic needs headless GL that is missing. Each
/// field must be in the rows of one of the tables at least.
fn report(args: &[&str], tables: &[&str], fields: &[&str]) -> Option<(String, Value)> {
    let d = scratch(&format!("report-{}", args[0]));
    let (json, svg) = (d.join("r.json"), d.join("r.svg"));
    let out = cli()
        .arg("report")
        .args(args)
        .arg("--json")
        .arg(&json)
        .arg("--plot")
        .arg(&svg)
        .output()
        .unwrap();
    if common::cli_gl_missing(&out) {
        return None;
    }
    common::assert_succeeded(&out);
    let text = String::from_utf8(out.stdout).unwrap();
    let first = text.lines().next().unwrap_or_default();
    assert!(
        first.starts_with("Measured ")
            && first.contains(" UTC, device ")
            && first.contains(&format!(", command `shapecue report {}", args.join(" "))),
        "{first}"
    );
    assert!(text.contains("\n|---|"), "a Markdown table: {text}");
    let doc: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(doc["topic"], args[0]);
    for key in ["measured_utc", "device", "command"] {
        assert!(doc[key].is_string(), "{key}: {doc}");
    }
    let mut all = Vec::new();
    for t in tables {
        let rows = doc["tables"][t]
            .as_array()
            .unwrap_or_else(|| panic!("{t}: {doc}"));
        assert!(!rows.is_empty(), "{t}");
        all.extend(rows);
    }
    for f in fields {
        assert!(
            all.iter().any(|r| r.get(*f).is_some()),
            "no table has the field {f}: {doc}"
        );
    }
    let plot = std::fs::read_to_string(&svg).unwrap();
    assert!(plot.contains("<svg"), "{plot}");
    assert!(
        plot.contains("Measured "),
        "the plot names its device and command"
    );
    let _ = std::fs::remove_dir_all(&d);
    Some((text, doc))
}

/// The rows of the Markdown table whose heading starts with `heading`.
fn table_rows<'a>(text: &'a str, heading: &str) -> Vec<&'a str> {
    text.lines()
        .skip_while(|l| !l.starts_with(heading))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .collect()
}

/// `report curvature` has a row for every variant the library compares,
/// in order; a variant the device cannot run (native float atomics where the
/// device has no float atomic add) is a row saying why, and the table goes
/// on; then the refinement sweep.
#[test]
fn curvature_report_has_a_row_for_every_variant() {
    let (text, doc) = report(
        &["curvature", "--resolution", "500", "--runs", "1"],
        &["variants", "refinement"],
        &["variant", "k1_rms_vs_analytic", "kernel_ms", "wall_ms"],
    )
    .expect("no GL needed");
    let rows = table_rows(&text, "| variant |");
    let variants = shapecue::report::metrics::variants();
    assert_eq!(
        rows.len(),
        variants.len() + 1,
        "variants and the CPU reference: {text}"
    );
    let info = common::gpu().info.clone();
    for (row, o) in rows.iter().zip(&variants) {
        let label = shapecue::report::metrics::label(o);
        assert!(row.starts_with(&format!("| {label} |")), "{row}");
        use shapecue::spec::curvature::{Accumulate, Precision};
        let f64 = o.precision == Precision::F64;
        let (native, atomic) = (
            o.accumulate == Accumulate::AtomicNative,
            o.accumulate == Accumulate::Atomic,
        );
        let expected = (native && !info.float_atomics)
            || (f64 && !info.fp64)
            || (f64 && atomic && !info.int64_atomics);
        assert_eq!(row.contains("not on this device"), expected, "{row}");
        if native && expected && !f64 {
            assert!(row.contains("cl_ext_float_atomics"), "{row}");
        }
    }
    assert!(
        rows.last().unwrap().starts_with("| cpu reference"),
        "{text}"
    );
    assert_eq!(
        table_rows(&text, "| vertices | h |").len(),
        shapecue::report::curvature::REFINEMENT.len()
    );
    let refinement = doc["tables"]["refinement"].as_array().unwrap();
    assert!(refinement.iter().all(|r| r["h"].as_f64().unwrap() > 0.0));
    assert!(refinement[0].get("exact_f32_k1_rms").is_some());
}

#[test]
fn isosurface_report_on_small_grids() {
    let (text, _) = report(
        &["isosurface", "--max-resolution", "64", "--runs", "1"],
        &["extraction", "resolution_sweep"],
        &["volume", "fusion", "kernel_ms", "faces", "h"],
    )
    .expect("no GL needed");
    // Every fusion variant of the bundled buckyball; the sphere and torus at 64³.
    assert_eq!(table_rows(&text, "| volume | fuse |").len(), 4, "{text}");
    assert_eq!(table_rows(&text, "| surface | res |").len(), 2, "{text}");
}

#[test]
fn strokes_report_on_the_smallest_grid() {
    let (text, doc) = report(
        &["strokes", "--max-resolution", "32"],
        &["sweep"],
        &["res", "h", "seeds", "k1_rel_err_median", "kernel_ms"],
    )
    .expect("no GL needed");
    assert_eq!(table_rows(&text, "| res |").len(), 3, "{text}");
    assert_eq!(doc["tables"]["sweep"][0]["res"], 32);
}

#[test]
fn pipeline_report_of_a_skinned_model() {
    let Some(model) = common::model_path("CesiumMan.glb") else {
        return;
    };
    let m = model.to_str().unwrap();
    let (text, doc) = report(
        &["pipeline", m, "--frames", "1", "--runs", "1"],
        &["passes"],
        &["pass", "kernel_ms", "ao_rms_vs_exact", "model"],
    )
    .expect("no GL needed");
    assert_eq!(table_rows(&text, "| pass |").len(), 7, "{text}");
    assert!(text.contains("16 ms frame budget"), "{text}");
    assert_eq!(doc["tables"]["passes"][0]["pass"], "skin");
}

#[test]
fn caps_report_on_a_small_image() {
    let Some((text, _)) = report(
        &["caps", "--size", "64x48", "--width", "2"],
        &["caps"],
        &["mesh", "caps", "ideal_px", "gap_px", "extra_px"],
    ) else {
        return;
    };
    // Three cap variants per mesh.
    assert_eq!(table_rows(&text, "| mesh | caps |").len() % 3, 0, "{text}");
    assert!(text.contains("| cube | adjacency |"), "{text}");
}

#[test]
fn lines_batch_report_splits_pose_and_views() {
    let spot = concat!(env!("CARGO_MANIFEST_DIR"), "/data/spot.obj");
    let (text, doc) = report(
        &[
            "lines-batch",
            spot,
            "--views",
            "3",
            "--generated-faces",
            "2000",
            "--generated-views",
            "2",
            "--size",
            "160x120",
        ],
        &["views"],
        &[
            "mesh",
            "faces",
            "families",
            "pose_ms",
            "per_view_ms",
            "npz_ms",
            "views_per_second",
        ],
    )
    .expect("no GL needed");
    let rows = doc["tables"]["views"].as_array().unwrap();
    // Two meshes, two family sets each.
    assert_eq!(rows.len(), 4, "{text}");
    assert_eq!(rows[0]["mesh"], "spot.obj");
    assert_eq!(rows[0]["families"], "every family");
    assert_eq!(rows[1]["families"], "contours + suggestive");
    for r in rows {
        let (pose, view) = (
            r["pose_ms"].as_f64().unwrap(),
            r["per_view_ms"].as_f64().unwrap(),
        );
        assert!(
            pose > 0.0 && view > 0.0 && r["npz_ms"].as_f64().unwrap() <= view,
            "{r}"
        );
        assert!(r["pieces_per_view"].as_f64().unwrap() > 0.0, "{r}");
    }
    // Every family draws more than the contours alone.
    assert!(rows[0]["pieces_per_view"].as_f64() > rows[1]["pieces_per_view"].as_f64());
    assert!(
        rows[2]["mesh"]
            .as_str()
            .unwrap()
            .starts_with("generated torus")
    );
}

/// `report visibility` on spot alone, small: a row per view with the
/// exact method's agreement beside its ms, and the depth-buffer method's
/// (or "no OpenGL" in its cells where the machine has none).
#[test]
fn visibility_report_on_spot() {
    let spot = concat!(env!("CARGO_MANIFEST_DIR"), "/data/spot.obj");
    let (text, doc) = report(
        &[
            "visibility",
            spot,
            "--runs",
            "1",
            "--size",
            "160x120",
            "--reference-tests",
            "3e6",
        ],
        &["meshes", "views"],
        &[
            "mesh",
            "faces",
            "bvh_build_ms",
            "view",
            "segments",
            "checked_segments",
            "exact_agreement_percent",
            "exact_ms",
            "depth_agreement_percent",
            "depth_ms",
            "line_kernels_ms",
        ],
    )
    .expect("the depth-buffer cells say when there is no OpenGL");
    let rows = doc["tables"]["views"].as_array().unwrap();
    assert_eq!(rows.len(), 3, "{text}");
    assert_eq!(doc["tables"]["meshes"][0]["mesh"], "spot.obj");
    let gl = !text.contains("no OpenGL");
    for r in rows {
        let (n, checked) = (
            r["segments"].as_u64().unwrap(),
            r["checked_segments"].as_u64().unwrap(),
        );
        assert!(n > 0 && (1..=n).contains(&checked), "{r}");
        assert!(
            r["exact_agreement_percent"].as_f64().unwrap() >= 99.0,
            "{r}"
        );
        assert!(r["exact_ms"].as_f64().unwrap() > 0.0, "{r}");
        assert!(r["line_kernels_ms"].as_f64().unwrap() > 0.0, "{r}");
        assert_eq!(r["depth_ms"].is_number(), gl, "{r}");
        if gl {
            assert!(r["depth_agreement_percent"].as_f64().unwrap() > 50.0, "{r}");
        }
    }
    assert!(
        rows[2]["view"]
            .as_str()
            .unwrap()
            .starts_with("orthographic")
    );
}

#[test]
fn memory_report_needs_no_device() {
    let (text, doc) = report(
        &["memory"],
        &["memory"],
        &[
            "mesh",
            "edges",
            "caps",
            "none_bits",
            "mh_bits",
            "adjacency_bits",
        ],
    )
    .expect("no GL needed");
    // The cube: 18 edges, 66 cap pairs; without caps 21 32-bit words per edge.
    assert!(
        text.contains(&format!("| cube | 18 | 66 | {} |", 18 * 21 * 32)),
        "{text}"
    );
    assert_eq!(doc["tables"]["memory"][0]["adjacency_bits"], 52224);
    for name in ["cylinder", "cone", "icosphere"] {
        assert!(text.contains(&format!("| {name} |")), "{text}");
    }
}

/// The report flags of the other commands are gone (clap refuses them with
/// its usage code), and `report` refuses an unknown topic, listing the
/// topics; outputs are checked before any measuring.
#[test]
fn old_report_flags_are_gone_and_unknown_topics_are_refused() {
    for args in [
        &["curvature", "--generate", "torus", "--report"][..],
        &["isosurface", "--sdf", "sphere", "--report"],
        &["strokes", "--sdf", "torus", "-o", "x.png", "--report"],
        &["render", "scenes/torus.toml", "--report"],
        &["edges", "m.obj", "-o", "x.png", "--memory-table"],
        &["edges", "m.obj", "-o", "x.png", "--cap-quality"],
    ] {
        let out = run_cli(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("unexpected argument"), "{args:?}: {err}");
    }
    let out = run_cli(["report", "speed"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("speed")
            && err.contains(
                "curvature, isosurface, strokes, pipeline, caps, lines-batch, coherence, visibility, \
                 memory"
            ),
        "{err}"
    );
    let d = scratch("report-refusals");
    let png = d.join("plot.png");
    let out = run_cli(["report", "memory", "--plot", png.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains(".svg"), "{err}");
    let json = common::write(&d, "taken.json", "{}");
    let out = run_cli(["report", "memory", "--json", json.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--force"), "{err}");
    assert_eq!(std::fs::read_to_string(&json).unwrap(), "{}");
    let out = run_cli(["report", "pipeline", "missing.glb"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("missing.glb"),
        "{err}"
    );
    assert!(!Path::new("missing.glb").exists());
    let _ = std::fs::remove_dir_all(&d);
}

/// `report coherence` on the bundled Fox: every measured family has a row
/// with coherence off and on beside its control, the control of
/// view-independent families is 0, contours are the same off and on, and
/// a scene of a static mesh is refused with its name.
#[test]
fn report_coherence_measures_flicker_off_and_on_beside_a_control() {
    let d = scratch("report-coherence");
    let fox = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/Fox.glb");
    let scene = common::write(
        &d,
        "fox.toml",
        format!(
            "[input]\ngltf = {:?}\nclip = \"Walk\"\nweld = true\n[frames]\nend = 8\n\
             [[camera]]\ndirection = [1.0, 0.4, 0.2]\n[effects]\ncontours = {{}}\n",
            fox.display().to_string()
        ),
    );
    let json = d.join("c.json");
    let out = cli()
        .args([
            "report",
            "coherence",
            scene.to_str().unwrap(),
            "--size",
            "320x240",
            "--json",
        ])
        .arg(&json)
        .output()
        .unwrap();
    common::assert_succeeded(&out);
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let rows = v["tables"]["flicker"]
        .as_array()
        .expect("the flicker table");
    assert_eq!(rows.len(), 8, "{rows:?}");
    for r in rows {
        if r["kind"] == "view-independent" {
            assert_eq!(
                (r["control_pop"].as_f64(), r["control_short_lived"].as_f64()),
                (Some(0.0), Some(0.0))
            );
        }
        if r["family"] == "contours" {
            assert_eq!(r["pop_off"], r["pop_on"], "{r}");
            assert!(r["control_pop"].as_f64().is_some(), "{r}");
        }
    }
    let cost = v["tables"]["cost"].as_array().expect("the cost table");
    assert_eq!(cost[0]["frames"], 8);
    let still = common::write(
        &d,
        "still.toml",
        "[input]\ngenerate = \"torus\"\n[effects]\ncontours = {}\n",
    );
    let out = run_cli(["report", "coherence", still.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("still.toml") && err.contains("skinned"),
        "{err}"
    );
}
