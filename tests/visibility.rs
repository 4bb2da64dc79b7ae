//! Exact, object-space visibility of line segments (`visibility` family):
//! the device's pieces equal the CPU twin's bit for bit; both agree with
//! the f64 brute-force reference on nearly all of the line length (torus,
//! sphere and spot, perspective and orthographic views, contours and
//! suggestive contours); the depth-buffer method of `render::depth_visibility`
//! is measured against the same reference (skipped, with a message,
//! without headless GL). Hard cases: a segment behind another object, the
//! silhouette of a convex mesh, segments behind the eye, zero-length
//! segments, no segment, bad segments (errors, no panic).

mod common;
mod visibility_support;

use std::time::Instant;

use glam::Vec3;
use shapecue::cpu::bvh::Tree;
use shapecue::cpu::visibility::{classify_reference, classify_twin};
use shapecue::mesh::{Mesh, icosphere, torus};
use shapecue::render::Camera;
use shapecue::spec::feature_lines::{LINE_FREE, Segment};
use shapecue::spec::view::View;
use shapecue::spec::visibility::{Pieces, Spacing, VisibilityOptions};
use shapecue::spec::visibility_plan::RayPlan;
use shapecue::stages::bvh::Bvh;
use shapecue::stages::visibility::{classify, spatial_order};
use visibility_support::*;

fn spot() -> Mesh {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/data/spot.obj");
    shapecue::mesh::load(std::path::Path::new(p), &Default::default()).unwrap()
}

fn segments(m: &Mesh, view: View) -> Vec<Segment> {
    let ls = shapecue::api::line_segments_on(
        &common::gpu(),
        m,
        view,
        &Default::default(),
        &Default::default(),
    )
    .unwrap();
    ls.segments
}

/// Device, twin and reference pieces of `segs`, and the device's and the
/// twin's ms (plan and rounds; the tree is built before).
fn all_three(
    m: &Mesh,
    segs: &[Segment],
    view: &View,
) -> (Vec<Pieces>, Vec<Pieces>, Vec<Pieces>, [f64; 2]) {
    let (p, opts) = (f32s(m), VisibilityOptions::default());
    let mut bvh = Bvh::new(common::gpu(), p.len(), &m.faces).unwrap();
    bvh.build(&p).unwrap();
    let t0 = Instant::now();
    let (dev, overflows) = classify(&mut bvh, &p, &m.faces, segs, view, &opts).unwrap();
    let ms = t0.elapsed().as_secs_f64() * 1e3;
    assert_eq!(overflows, 0);
    let tree = Tree::new("test mesh", &p, &m.faces).unwrap();
    let t0 = Instant::now();
    let plan = RayPlan::new(&p, &m.faces, segs, view, &opts).unwrap();
    let twin = classify_twin(&tree, &p, &m.faces, &plan).unwrap();
    let twin_ms = t0.elapsed().as_secs_f64() * 1e3;
    let reference = classify_reference(&m.positions, &m.faces, &plan).unwrap();
    (dev, twin, reference, [ms, twin_ms])
}

/// The reference with samples ten times closer (1/2000 of the view): what
/// the default spacing misses between two samples shows against it.
fn fine_reference(m: &Mesh, segs: &[Segment], view: &View) -> Vec<Pieces> {
    let opts = VisibilityOptions {
        spacing: Spacing::View(0.0005),
        ..Default::default()
    };
    let plan = RayPlan::new(&f32s(m), &m.faces, segs, view, &opts).unwrap();
    classify_reference(&m.positions, &m.faces, &plan).unwrap()
}

#[test]
fn device_equals_twin_and_both_agree_with_the_reference() {
    let meshes = [
        ("torus", torus(1.0, 0.4, 64, 32)),
        ("sphere", icosphere(1.0, 4)),
        ("spot", spot()),
    ];
    let views = [
        ("perspective (1, 0.6, 0.8)", Vec3::new(1.0, 0.6, 0.8), false),
        (
            "perspective (-0.3, 1, 0.2)",
            Vec3::new(-0.3, 1.0, 0.2),
            false,
        ),
        ("orthographic (0.2, 0.5, 1)", Vec3::new(0.2, 0.5, 1.0), true),
    ];
    for (name, m) in &meshes {
        for (vname, dir, ortho) in views {
            let cam = camera(m, dir, ortho);
            let view = cam.view(W, H);
            let segs = segments(m, view);
            let (dev, twin, reference, ms) = all_three(m, &segs, &view);
            assert_eq!(dev, twin, "{name}, {vname}: device vs twin");
            let s = share(&segs, &dev, &reference);
            let hidden = hidden_share(&segs, &dev);
            let fine = fine_reference(m, &segs, &view);
            let f = share(&segs, &dev, &fine);
            let depth = depth_share(m, &segs, &cam, &reference);
            let depth = depth.map_or("skipped (no GL)".into(), |d| format!("{:.4} %", 100.0 * d));
            println!(
                "{name}, {vname}: {} segments, hidden {:.2} %, device vs reference {:.4} %, \
                 vs a 10× finer reference {:.4} %, depth buffer vs reference {depth}, \
                 device {:.1} ms, twin {:.1} ms",
                segs.len(),
                100.0 * hidden + 0.0,
                100.0 * s,
                100.0 * f,
                ms[0],
                ms[1]
            );
            assert!(s >= 0.999, "{name}, {vname}: agreement {s}");
            assert!(
                f >= 0.999,
                "{name}, {vname}: against the finer reference {f}"
            );
        }
    }
}

/// Two icospheres: the back one (radius 1 at the origin, faces first) and a
/// front one (radius 0.5 at z = 2), and the back one's face count.
fn two_spheres() -> (Mesh, usize) {
    let (back, front) = (icosphere(1.0, 3), icosphere(0.5, 3));
    let nb = back.faces.len();
    let off = back.positions.len() as u32;
    let mut m = back;
    m.positions
        .extend(front.positions.iter().map(|p| [p[0], p[1], p[2] + 2.0]));
    m.faces
        .extend(front.faces.iter().map(|f| f.map(|v| v + off)));
    (m, nb)
}

/// The face among `faces` whose centroid lies highest in z.
fn top_face(m: &Mesh, faces: std::ops::Range<usize>) -> usize {
    let cz = |f: usize| {
        m.faces[f]
            .iter()
            .map(|&v| m.positions[v as usize][2])
            .sum::<f64>()
    };
    faces.max_by(|&a, &b| cz(a).total_cmp(&cz(b))).unwrap()
}

/// A segment inside face `f`: from its centroid to the midpoint of its
/// first edge (ends `[u32::MAX, f]` and the edge).
fn in_face(m: &Mesh, f: usize) -> Segment {
    let t = m.faces[f];
    let p = |v: u32| common::to_f32(&[m.positions[v as usize]])[0];
    let c = std::array::from_fn(|k| (p(t[0])[k] + p(t[1])[k] + p(t[2])[k]) / 3.0);
    let e = std::array::from_fn(|k| 0.5 * (p(t[0])[k] + p(t[1])[k]));
    Segment::new(
        c,
        e,
        0,
        1.0,
        [[u32::MAX, f as u32], [t[0].min(t[1]), t[0].max(t[1])]],
    )
}

/// Device pieces, checked equal to the twin's and the reference's.
fn pieces_of(m: &Mesh, segs: &[Segment], view: &View) -> Vec<Pieces> {
    let (dev, twin, reference, _) = all_three(m, segs, view);
    assert_eq!(dev, twin, "device vs twin");
    assert_eq!(dev, reference, "device vs reference");
    dev
}

fn views_down_z() -> [View; 2] {
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, 6.0), Vec3::ZERO);
    let ortho = Camera {
        ortho_height: Some(3.0),
        ..cam
    };
    [cam.view(W, H), ortho.view(W, H)]
}

#[test]
fn a_segment_behind_another_object_is_hidden_and_visible_without_it() {
    let (m, nb) = two_spheres();
    let back = top_face(&m, 0..nb);
    let seg = in_face(&m, back);
    let alone = Mesh {
        positions: m.positions.clone(),
        faces: m.faces[..nb].to_vec(),
        normals: None,
    };
    let front = in_face(&m, top_face(&m, nb..m.faces.len()));
    // Zero length, at the back face's centroid.
    let point = Segment::new(seg.a, seg.a, 0, 1.0, [seg.ends[0], seg.ends[0]]);
    for view in views_down_z() {
        let got = pieces_of(&m, &[seg, front, point], &view);
        assert_eq!(got[0], vec![(0.0, 1.0, false)], "behind the front sphere");
        assert_eq!(got[1], vec![(0.0, 1.0, true)], "on the front sphere");
        assert_eq!(got[2], vec![(0.0, 1.0, false)], "zero length, behind");
        let got = pieces_of(&alone, &[seg, point], &view);
        assert_eq!(
            got,
            vec![vec![(0.0, 1.0, true)]; 2],
            "without the front sphere"
        );
    }
}

#[test]
fn the_silhouette_of_a_convex_mesh_is_visible() {
    let m = icosphere(1.0, 4);
    for (dir, ortho) in [
        (Vec3::new(0.3, 0.2, 1.0), false),
        (Vec3::new(1.0, -0.4, 0.1), true),
    ] {
        let view = camera(&m, dir, ortho).view(W, H);
        let segs: Vec<Segment> = segments(&m, view)
            .into_iter()
            .filter(|s| s.family == 0)
            .collect();
        assert!(segs.len() > 50, "{} contour segments", segs.len());
        let (dev, twin, _, _) = all_three(&m, &segs, &view);
        assert_eq!(dev, twin);
        let hidden = hidden_share(&segs, &dev);
        assert!(
            hidden <= 1e-3,
            "{hidden} of the length hidden (ortho {ortho})"
        );
    }
}

#[test]
fn segments_behind_the_eye_are_hidden_and_one_crossing_its_plane_is_split() {
    let (m, _) = two_spheres();
    let [view, ortho] = views_down_z();
    let free = [[LINE_FREE, 0], [LINE_FREE, 0]];
    let behind = Segment::new([0.0, 0.0, 7.0], [0.1, 0.0, 8.0], 0, 1.0, free);
    let across = Segment::new([0.0, 0.5, 5.0], [0.0, 0.5, 7.0], 0, 1.0, free);
    let got = pieces_of(&m, &[behind, across], &view);
    assert_eq!(got[0], vec![(0.0, 1.0, false)]);
    assert_eq!(got[1].len(), 2, "{:?}", got[1]);
    assert!(got[1][0].2 && !got[1][1].2, "{:?}", got[1]);
    // The near plane lies 0.06 before the eye: z = 5.94, t = 0.47.
    assert!((got[1][0].1 - 0.47).abs() < 2e-3, "{:?}", got[1]);
    // Orthographic views have no eye to be behind.
    let got = pieces_of(&m, &[behind, across], &ortho);
    assert_eq!(got, vec![vec![(0.0, 1.0, true)]; 2]);
}

#[test]
fn no_segment_gives_no_piece_and_bad_segments_are_plain_errors() {
    let (m, _) = two_spheres();
    let [view, _] = views_down_z();
    assert!(pieces_of(&m, &[], &view).is_empty());
    let p = f32s(&m);
    let mut bvh = Bvh::new(common::gpu(), p.len(), &m.faces).unwrap();
    bvh.build(&p).unwrap();
    let opts = VisibilityOptions::default();
    let ok = in_face(&m, 0);
    // Each bad segment lies below and left of the others, so that the
    // device's order (Morton, of the midpoints) takes it first; the error
    // still names it by the caller's index.
    let c = [-10.0f32; 3];
    let cases: [(&str, Segment); 3] = [
        (
            "face 99999999",
            Segment::new(c, c, 0, 1.0, [[LINE_FREE, 99_999_999], ok.ends[1]]),
        ),
        (
            "vertex 4000000000",
            Segment::new(c, c, 0, 1.0, [ok.ends[0], [7, 4_000_000_000]]),
        ),
        (
            "non-finite",
            Segment::new([f32::NAN, -10.0, -10.0], c, 0, 1.0, ok.ends),
        ),
    ];
    let others = [in_face(&m, 1), in_face(&m, 2), in_face(&m, 3)];
    for (want, seg) in cases {
        let segs = [others[0], others[1], seg, others[2]];
        assert_eq!(spatial_order(&segs)[0], 2, "{want}: taken first");
        let e = classify(&mut bvh, &p, &m.faces, &segs, &view, &opts).unwrap_err();
        assert!(e.to_string().contains(want), "{e}");
        assert!(e.to_string().contains("segment 2"), "{e}");
    }
    let e = classify(&mut bvh, &p, &m.faces[1..], &[ok], &view, &opts).unwrap_err();
    assert!(e.to_string().contains("faces"), "{e}");
}
