//! The `bvh` family: device against the CPU twin step by step (Morton codes
//! and sorted order, Karras's nodes and parents, boxes bit for bit, refit
//! after a new pose, occlusion queries), boxes containing their subtrees,
//! queries against the f64 brute force, and hard cases (degenerate faces,
//! huge and tiny coordinates, no face, one centroid for every face).
//!
//! The device and the twin do the same f32 arithmetic, so they must agree on
//! every query. The f64 brute force may disagree only on queries within
//! [`NEAR`] of a decision boundary of some face (an edge, a trimmed end, or
//! a grazing angle), and such disagreements must stay under 0.5 %.

mod common;

use common::{gpu, to_f32};
use shapecue::cpu::bvh::{self as twin, Tree, segment_measures};
use shapecue::mesh::{Generated, Mesh, splitmix};
use shapecue::spec::bvh::{
    BvhBox, BvhQuery, END_EPS, LEAF, NONE, OCCLUDED, OVERFLOW, STACK_DEPTH, VISIBLE,
};
use shapecue::stages::bvh::Bvh;

/// Relative band around a decision boundary (barycentric, segment end, or
/// the sine of the angle between segment and plane) within which the f32
/// test may decide otherwise than the f64 one.
const NEAR: f64 = 1e-3;

/// Builds on the device and with the twin, checks they agree, returns both.
fn build_both(what: &str, pos: &[[f32; 3]], faces: &[[u32; 3]]) -> (Bvh, Tree) {
    let mut dev = Bvh::new(gpu(), pos.len(), faces).unwrap();
    dev.build(pos).unwrap();
    let cpu = Tree::new(what, pos, faces).unwrap();
    same(what, &dev.read().unwrap(), &cpu);
    contains(what, &cpu, pos, faces);
    (dev, cpu)
}

/// The bits of a box list.
fn bits(b: &[BvhBox]) -> &[u32] {
    bytemuck::cast_slice(b)
}

/// Device tree = twin tree: codes of every face (sorted keys with their
/// faces), topology, boxes bit for bit.
fn same(what: &str, dev: &Tree, cpu: &Tree) {
    assert_eq!(dev.keys, cpu.keys, "{what}: Morton codes");
    assert_eq!(dev.faces_sorted, cpu.faces_sorted, "{what}: sorted faces");
    assert_eq!(dev.nodes, cpu.nodes, "{what}: children and parents");
    assert_eq!(dev.leaf_parent, cpu.leaf_parent, "{what}: leaf parents");
    assert_eq!(
        bits(&dev.leaf_boxes),
        bits(&cpu.leaf_boxes),
        "{what}: leaf boxes"
    );
    assert_eq!(
        bits(&dev.node_boxes),
        bits(&cpu.node_boxes),
        "{what}: node boxes"
    );
    assert_eq!(
        bits(&dev.child_boxes),
        bits(&cpu.child_boxes),
        "{what}: padded child boxes"
    );
}

fn inside(b: &BvhBox, p: [f32; 3]) -> bool {
    (0..3).all(|k| b.lo[k] <= p[k] && p[k] <= b.hi[k])
}

/// Every leaf box holds its triangle and every node box its children's
/// boxes (so every box holds its subtree's triangles); the tree is no
/// deeper than the traversal stack.
fn contains(what: &str, t: &Tree, pos: &[[f32; 3]], faces: &[[u32; 3]]) {
    for (i, &f) in t.faces_sorted.iter().enumerate() {
        for &v in &faces[f as usize] {
            assert!(
                inside(&t.leaf_boxes[i], pos[v as usize]),
                "{what}: leaf {i}"
            );
        }
    }
    for (i, n) in t.nodes.iter().enumerate() {
        for c in [n.left, n.right] {
            let cb = t.child_box(c);
            for k in 0..3 {
                let b = &t.node_boxes[i];
                assert!(
                    b.lo[k] <= cb.lo[k] && cb.hi[k] <= b.hi[k],
                    "{what}: node {i}"
                );
            }
        }
    }
    for leaf in 0..t.leaf_parent.len() {
        let (mut depth, mut node) = (1, t.leaf_parent[leaf]);
        while node != NONE {
            depth += 1;
            node = t.nodes[node as usize].parent;
        }
        assert!(depth <= STACK_DEPTH, "{what}: leaf {leaf} at depth {depth}");
    }
}

fn torus() -> Mesh {
    Generated::Torus.mesh(3000).1
}

fn sphere() -> Mesh {
    Generated::Sphere.mesh(2600).1
}

/// A plane with one triangle doubled (two faces with one centroid).
fn doubled() -> Mesh {
    let mut m = Generated::Plane.mesh(100).1;
    let f = m.faces[7];
    m.faces.push(f);
    m.faces.insert(3, [f[1], f[2], f[0]]);
    m
}

fn triangles(n: usize) -> Mesh {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.5],
    ];
    let faces = [[0, 1, 2], [1, 3, 2]][..n].to_vec();
    Mesh {
        positions,
        faces,
        normals: None,
    }
}

fn meshes() -> Vec<(&'static str, Mesh)> {
    vec![
        ("torus", torus()),
        ("sphere", sphere()),
        ("doubled triangle", doubled()),
        ("one triangle", triangles(1)),
        ("two triangles", triangles(2)),
    ]
}

#[test]
fn tree_and_boxes_match_the_twin() {
    for (what, m) in meshes() {
        let pos = to_f32(&m.positions);
        let (_, cpu) = build_both(what, &pos, &m.faces);
        assert_eq!(cpu.faces_sorted.len(), m.faces.len(), "{what}");
        if what == "doubled triangle" {
            // face 8 and the last are one triangle: equal codes, the earlier
            // face first (stable sort)
            let at = |f: usize| {
                cpu.faces_sorted
                    .iter()
                    .position(|&x| x as usize == f)
                    .unwrap()
            };
            let (a, b) = (at(8), at(m.faces.len() - 1));
            assert_eq!(cpu.keys[a], cpu.keys[b], "{what}");
            assert!(a < b, "{what}");
        }
    }
}

/// The torus twisted about its axis (z) by up to `angle` radians and moved.
fn twisted(p: &[[f64; 3]], angle: f64) -> Vec<[f64; 3]> {
    p.iter()
        .map(|&[x, y, z]| {
            let a = angle * z / 0.4;
            let (s, c) = a.sin_cos();
            [c * x - s * y + 0.3, s * x + c * y, 1.5 * z]
        })
        .collect()
}

#[test]
fn refit_after_a_new_pose_matches_the_twin() {
    let m = torus();
    let pos = to_f32(&m.positions);
    let (mut dev, mut cpu) = build_both("torus", &pos, &m.faces);
    let before = dev.read().unwrap();
    for angle in [0.3, 1.2] {
        let p2 = to_f32(&twisted(&m.positions, angle));
        dev.refit(&p2).unwrap();
        cpu.refit(&p2, &m.faces);
        let got = dev.read().unwrap();
        same("twisted torus", &got, &cpu);
        contains("twisted torus", &cpu, &p2, &m.faces);
        assert_eq!(got.nodes, before.nodes, "refit keeps the tree");
        assert_ne!(bits(&got.node_boxes), bits(&before.node_boxes));
    }
}

/// `n` random segments in the box `[-s, s]³`, a third of them starting at a
/// face's centroid with that face excluded.
fn random_queries(
    pos: &[[f32; 3]],
    faces: &[[u32; 3]],
    n: usize,
    s: f64,
    seed: u64,
) -> Vec<BvhQuery> {
    let mut st = seed;
    let mut r = || ((2.0 * splitmix(&mut st) - 1.0) * s) as f32;
    (0..n)
        .map(|i| {
            let target = [r(), r(), r()];
            if i % 3 == 0 && !faces.is_empty() {
                let f = (i / 3 * 7919) % faces.len();
                let c = (0..3).map(|k| {
                    let v = |j: usize| pos[faces[f][j] as usize][k] as f64;
                    ((v(0) + v(1) + v(2)) / 3.0) as f32
                });
                let c: Vec<f32> = c.collect();
                BvhQuery::new([c[0], c[1], c[2]], target, &[f as u32])
            } else {
                BvhQuery::new([r(), r(), r()], target, &[])
            }
        })
        .collect()
}

/// Whether the query is within [`NEAR`] of a decision boundary of a face
/// that is not excluded (f64).
fn near_boundary(p: &[[f64; 3]], faces: &[[u32; 3]], o: [f64; 3], d: [f64; 3], ex: &[u32]) -> bool {
    faces.iter().enumerate().any(|(i, f)| {
        if ex.contains(&(i as u32)) {
            return false;
        }
        let (a, b, c) = (p[f[0] as usize], p[f[1] as usize], p[f[2] as usize]);
        let Some((det, u, v, t)) = segment_measures(o, d, a, b, c) else {
            return false;
        };
        let (u, v, t) = (u / det, v / det, t / det);
        let w = 1.0 - u - v;
        let close = u > -NEAR && v > -NEAR && w > -NEAR && t > -NEAR && t < 1.0 + NEAR;
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let norm = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        let sine = det / (norm(n) * norm(d));
        let end = END_EPS as f64;
        let edge = u.abs().min(v.abs()).min(w.abs()) < NEAR;
        let trimmed = (t - end).abs().min((t - 1.0 + end).abs()) < NEAR;
        close && (edge || trimmed || sine < NEAR)
    })
}

/// Runs the queries on the device and the twin (must agree on every one)
/// and against the f64 brute force; returns (queries, near, disagreements).
fn check_queries(
    what: &str,
    dev: &mut Bvh,
    cpu: &Tree,
    pos: &[[f32; 3]],
    faces: &[[u32; 3]],
    qs: &[BvhQuery],
) -> (usize, usize, usize) {
    let (got, overflows) = dev.occluded(qs).unwrap();
    assert_eq!(overflows, 0, "{what}");
    let p64: Vec<[f64; 3]> = pos.iter().map(|p| p.map(f64::from)).collect();
    let (mut near, mut disagree) = (0, 0);
    for (i, q) in qs.iter().enumerate() {
        assert_eq!(
            got[i],
            cpu.occluded(pos, faces, q),
            "{what}: query {i} device vs twin"
        );
        let o = [q.origin[0], q.origin[1], q.origin[2]].map(f64::from);
        let t = [q.target[0], q.target[1], q.target[2]].map(f64::from);
        let ex: Vec<u32> = q.exclude.iter().copied().filter(|&f| f != NONE).collect();
        let brute = twin::occluded_brute(&p64, faces, o, t, &ex);
        let d = [t[0] - o[0], t[1] - o[1], t[2] - o[2]];
        let is_near = near_boundary(&p64, faces, o, d, &ex);
        near += is_near as usize;
        if (got[i] == OCCLUDED) != brute {
            disagree += 1;
            assert!(
                is_near,
                "{what}: query {i} {q:?}: device {} vs f64 {brute}, far from any boundary",
                got[i]
            );
        }
    }
    assert!(
        disagree * 200 < qs.len().max(1),
        "{what}: {disagree} of {} disagree",
        qs.len()
    );
    eprintln!(
        "{what}: {} queries, {} occluded, {near} near a boundary, {disagree} disagree with f64",
        qs.len(),
        got.iter().filter(|&&r| r == OCCLUDED).count()
    );
    (qs.len(), near, disagree)
}

#[test]
fn occlusion_queries_match_the_twin_and_the_brute_force() {
    let mut total = (0, 0, 0);
    for (what, m, s) in [
        ("torus", torus(), 1.6),
        ("sphere", sphere(), 1.3),
        ("two triangles", triangles(2), 1.2),
    ] {
        let pos = to_f32(&m.positions);
        let (mut dev, cpu) = build_both(what, &pos, &m.faces);
        let qs = random_queries(&pos, &m.faces, 3000, s, 17);
        let (n, near, dis) = check_queries(what, &mut dev, &cpu, &pos, &m.faces, &qs);
        total = (total.0 + n, total.1 + near, total.2 + dis);
        // after a refit too
        let p2 = to_f32(&twisted(&m.positions, 0.5));
        dev.refit(&p2).unwrap();
        let mut cpu2 = cpu.clone();
        cpu2.refit(&p2, &m.faces);
        let qs = random_queries(&p2, &m.faces, 1000, s, 29);
        let (n, near, dis) = check_queries(what, &mut dev, &cpu2, &p2, &m.faces, &qs);
        total = (total.0 + n, total.1 + near, total.2 + dis);
    }
    eprintln!(
        "all: {} queries, {} near, {} disagree",
        total.0, total.1, total.2
    );
    assert!(total.1 > 0 || total.2 == 0);
}

#[test]
fn degenerate_triangles_are_never_hit_and_keep_the_tree_valid() {
    let mut m = sphere();
    let nv = m.positions.len() as u32;
    // dyadic coordinates: every product and sum below is exact, so the
    // degenerate faces have det = 0 exactly, in f32 and in f64
    m.positions.push([0.125, 0.25, 0.375]);
    m.positions.push([0.25, 0.375, 0.5]);
    m.positions.push([0.375, 0.5, 0.625]); // collinear with the two before
    m.faces.push([nv, nv + 1, nv + 2]);
    m.faces.push([nv, nv, nv + 1]);
    m.faces.push([nv + 2, nv + 2, nv + 2]);
    let pos = to_f32(&m.positions);
    let (mut dev, cpu) = build_both("degenerate", &pos, &m.faces);
    // segments across the degenerate faces, inside the sphere
    let qs: Vec<BvhQuery> = (0..=32)
        .map(|i| {
            let s = i as f32 / 128.0;
            let p = [0.125 + s, 0.25 + s, 0.375 + s];
            BvhQuery::new(
                [p[0] - 0.0625, p[1] + 0.0625, p[2]],
                [p[0] + 0.0625, p[1] - 0.0625, p[2]],
                &[],
            )
        })
        .collect();
    let (got, _) = dev.occluded(&qs).unwrap();
    assert!(got.iter().all(|&r| r == VISIBLE), "{got:?}");
    check_queries("degenerate", &mut dev, &cpu, &pos, &m.faces, &qs);
}

#[test]
fn huge_and_tiny_coordinates_quantize_without_overflow() {
    let m = sphere();
    for (what, scale, offset) in [
        ("tiny", 1e-6, 0.0),
        ("huge offset", 1e-6, 1e6),
        ("huge", 1e6, 0.0),
        ("far", 1.0, 1e6),
    ] {
        let p64: Vec<[f64; 3]> = m
            .positions
            .iter()
            .map(|p| p.map(|c| c * scale + offset))
            .collect();
        let pos = to_f32(&p64);
        let (mut dev, cpu) = build_both(what, &pos, &m.faces);
        assert!(
            cpu.node_boxes
                .iter()
                .all(|b| b.lo.iter().chain(&b.hi).all(|c| c.is_finite()))
        );
        let qs = random_queries(&pos, &m.faces, 300, 1.3 * scale, 5);
        let qs: Vec<BvhQuery> = (qs.into_iter())
            .map(|mut q| {
                for k in 0..3 {
                    q.origin[k] += offset as f32;
                    q.target[k] += offset as f32;
                }
                q
            })
            .collect();
        let (got, overflows) = dev.occluded(&qs).unwrap();
        assert_eq!(overflows, 0);
        for (i, q) in qs.iter().enumerate() {
            assert_eq!(got[i], cpu.occluded(&pos, &m.faces, q), "{what}: query {i}");
        }
        if offset == 0.0 {
            // scale-free arithmetic: the brute force agrees as at scale 1
            check_queries(what, &mut dev, &cpu, &pos, &m.faces, &qs);
        }
    }
}

#[test]
fn one_centroid_for_every_face() {
    // triangles rotated about a common centroid
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for i in 0..40u32 {
        let a = i as f64 * 0.37;
        for k in 0..3 {
            let b = a + k as f64 * 2.0 * std::f64::consts::PI / 3.0;
            positions.push([b.cos(), b.sin(), 0.0]);
        }
        faces.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let pos = to_f32(&positions);
    let (mut dev, cpu) = build_both("one centroid", &pos, &faces);
    let codes: std::collections::BTreeSet<u32> = cpu.keys.iter().copied().collect();
    assert!(codes.len() <= 2, "{codes:?}");
    let qs = random_queries(&pos, &faces, 500, 1.2, 3);
    check_queries("one centroid", &mut dev, &cpu, &pos, &faces, &qs);
}

#[test]
fn no_face_is_an_empty_tree_and_bad_input_is_an_error() {
    let pos = vec![[0.0f32; 3]; 3];
    let mut dev = Bvh::new(gpu(), 3, &[]).unwrap();
    assert!(dev.refit(&pos).is_err(), "refit before build");
    assert!(dev.occluded(&[]).is_err(), "queries before build");
    dev.build(&pos).unwrap();
    let t = dev.read().unwrap();
    assert!(t.faces_sorted.is_empty() && t.nodes.is_empty());
    assert_eq!(Tree::new("empty", &pos, &[]).unwrap().root(), None);
    let q = BvhQuery::new([0.0; 3], [1.0; 3], &[]);
    assert_eq!(dev.occluded(&[q]).unwrap(), (vec![VISIBLE], 0));

    let e = Bvh::new(gpu(), 3, &[[0, 1, 2], [0, 1, 5]])
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("face 1") && e.contains("5"), "{e}");
    let mut dev = Bvh::new(gpu(), 3, &[[0, 1, 2]]).unwrap();
    let e = dev
        .build(&[[0.0, 0.0, f32::NAN], [0.0; 3], [1.0; 3]])
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("vertex 0") && e.contains("finite"), "{e}");
    assert!(dev.build(&pos[..2]).is_err(), "too few positions");
    assert_eq!(LEAF, 1 << 31);
}

#[test]
fn chords_of_a_convex_mesh_are_visible() {
    // Segments between two vertices of the icosphere (convex) run inside
    // it: the faces around each end are hit at t = 0 or 1 (trimmed) or
    // contain the segment (det = 0): no exclusion is needed.
    let m = sphere();
    let pos = to_f32(&m.positions);
    let (mut dev, cpu) = build_both("sphere", &pos, &m.faces);
    let nv = m.positions.len() as u64;
    let (a, b) = (common::random(2000, nv, 11), common::random(2000, nv, 12));
    let qs: Vec<BvhQuery> = (a.iter().zip(&b))
        .filter(|(a, b)| a != b)
        .map(|(&a, &b)| BvhQuery::new(pos[a as usize], pos[b as usize], &[]))
        .collect();
    let (got, _) = dev.occluded(&qs).unwrap();
    let blocked = got.iter().filter(|&&r| r != VISIBLE).count();
    assert_eq!(blocked, 0, "{blocked} of {} chords blocked", qs.len());
    check_queries("sphere chords", &mut dev, &cpu, &pos, &m.faces, &qs);
}

#[test]
fn a_short_stack_overflows_into_the_counter_as_the_twin_does() {
    let m = torus();
    let pos = to_f32(&m.positions);
    let mut dev = Bvh::with_stack(gpu(), pos.len(), &m.faces, 3).unwrap();
    dev.build(&pos).unwrap();
    let cpu = Tree::new("torus", &pos, &m.faces).unwrap();
    let qs = random_queries(&pos, &m.faces, 2000, 1.6, 23);
    let (got, overflows) = dev.occluded(&qs).unwrap();
    let want: Vec<u32> = (qs.iter())
        .map(|q| cpu.occluded_with_stack(&pos, &m.faces, q, 3))
        .collect();
    assert_eq!(got, want, "device vs twin with a 3-entry stack");
    let counted = got.iter().filter(|&&r| r == OVERFLOW).count();
    assert!(counted > 0, "a 3-entry stack overflows on a torus");
    assert_eq!(
        overflows as usize, counted,
        "one count per overflowed query"
    );
    assert!(Bvh::with_stack(gpu(), pos.len(), &m.faces, 0).is_err());
    assert!(Bvh::with_stack(gpu(), pos.len(), &m.faces, STACK_DEPTH + 1).is_err());
}
