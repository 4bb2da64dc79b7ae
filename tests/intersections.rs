//! The `intersections` family: device against the CPU twin bit for bit
//! (segments and stats, after a refit too, through the grow-and-rerun
//! path), the twin against the f64 brute force (same face pairs but where
//! a segment is shorter than a rounding error; ends within 1e-5), analytic
//! oracles (two crossing spheres: every end on both faces and within the
//! sagitta of the circle x = 0.5, y² + z² = 0.75; a sphere through a plane:
//! the circle z = c), closed loops, self-intersection (a tube crossing
//! itself, two spheres in one mesh), groups, and hard cases (coplanar and
//! degenerate faces, scales 1e-15 to 1e15, coordinates that overflow, no
//! face, one face, bad input).

mod common;

use common::{gpu, to_f32};
use shapecue::cpu::bvh::Tree;
use shapecue::cpu::intersections as twin;
use shapecue::mesh::{Mesh, icosphere, plane, torus};
use shapecue::spec::intersections::{IntersectionOptions, IntersectionStats, Segment};
use shapecue::stages::bvh::Bvh;
use shapecue::stages::intersections::{Intersections, find_once};

/// Meshes concatenated into one (faces renumbered), and each one's face count.
fn concat(meshes: &[Mesh]) -> (Mesh, Vec<usize>) {
    let mut out = Mesh {
        positions: Vec::new(),
        faces: Vec::new(),
        normals: None,
    };
    for m in meshes {
        let base = out.positions.len() as u32;
        out.positions.extend(&m.positions);
        out.faces
            .extend(m.faces.iter().map(|f| f.map(|v| v + base)));
    }
    (out, meshes.iter().map(|m| m.faces.len()).collect())
}

/// `m` turned by a fixed generic rotation about `centre`, then moved by
/// `to`: no vertex or edge of one sphere meets another's by symmetry (the
/// icosphere is symmetric under x → −x, so an unturned copy at (1, 0, 0)
/// would mirror the first across the plane x = 0.5 and every crossing
/// would pass through both meshes' edges at once).
fn turned(m: &Mesh, to: [f64; 3]) -> Mesh {
    let (a, b, c) = (0.3f64, 0.7f64, 1.1f64);
    m.map_positions(|p| {
        let (s, co) = a.sin_cos();
        let p = [p[0], co * p[1] - s * p[2], s * p[1] + co * p[2]];
        let (s, co) = b.sin_cos();
        let p = [co * p[0] + s * p[2], p[1], -s * p[0] + co * p[2]];
        let (s, co) = c.sin_cos();
        let p = [co * p[0] - s * p[1], s * p[0] + co * p[1], p[2]];
        [p[0] + to[0], p[1] + to[1], p[2] + to[2]]
    })
}

/// Two unit icospheres of `level` crossing: at the origin and, turned, at
/// (1, 0, 0).
fn two_spheres(level: u32) -> (Mesh, Vec<usize>) {
    let a = icosphere(1.0, level);
    let b = turned(&icosphere(1.0, level), [1.0, 0.0, 0.0]);
    concat(&[a, b])
}

fn bits(s: &[Segment]) -> &[u32] {
    bytemuck::cast_slice(s)
}

/// Device (built from `pos`) and twin; checks they agree (bit for bit on a
/// device that keeps the strict rules, else within 1e-5 of the size) and
/// returns the twin's result.
fn both(
    what: &str,
    pos: &[[f32; 3]],
    faces: &[[u32; 3]],
    opts: &IntersectionOptions,
) -> (Vec<Segment>, IntersectionStats) {
    let (dev, dstats) = find_once(gpu(), pos, faces, opts).unwrap();
    let tree = Tree::new(what, pos, faces).unwrap();
    let (cpu, cstats) = twin::find(&tree, pos, faces, opts).unwrap();
    same(what, &dev, &cpu, size_of(pos));
    assert_eq!(dstats.pairs_tested, cstats.pairs_tested, "{what}: pairs");
    assert_eq!(dstats.segments, cstats.segments, "{what}: segments");
    (cpu, cstats)
}

fn same(what: &str, dev: &[Segment], cpu: &[Segment], size: f64) {
    if gpu().bitwise_twins() {
        assert_eq!(bits(dev), bits(cpu), "{what}: device vs twin, bit for bit");
        return;
    }
    assert_eq!(dev.len(), cpu.len(), "{what}: segments");
    for (d, c) in dev.iter().zip(cpu) {
        assert_eq!(d.faces, c.faces, "{what}");
        for k in 0..3 {
            let tol = 1e-5 * size;
            assert!(
                (d.a[k] - c.a[k]).abs() as f64 <= tol,
                "{what}: {d:?} vs {c:?}"
            );
            assert!(
                (d.b[k] - c.b[k]).abs() as f64 <= tol,
                "{what}: {d:?} vs {c:?}"
            );
        }
    }
}

/// The largest extent of the positions' box (1 for none).
fn size_of(pos: &[[f32; 3]]) -> f64 {
    let ext = |k: usize| {
        let (lo, hi) = pos.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
            (lo.min(p[k]), hi.max(p[k]))
        });
        (hi - lo) as f64
    };
    let e = ext(0).max(ext(1)).max(ext(2));
    if pos.is_empty() || e == 0.0 { 1.0 } else { e }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn f64s(p: [f32; 3]) -> [f64; 3] {
    p.map(f64::from)
}

/// The twin against the f64 brute force: the same face pairs, except pairs
/// one of them finds with a segment shorter than `1e-5 · size` (a rounding
/// decides those); matched ends within `1e-5 · size`. Returns the largest
/// end distance over the size.
fn against_reference(
    what: &str,
    pos: &[[f32; 3]],
    faces: &[[u32; 3]],
    opts: &IntersectionOptions,
    segs: &[Segment],
) -> f64 {
    let p64: Vec<[f64; 3]> = pos.iter().map(|&p| f64s(p)).collect();
    let refs = twin::find_brute(&p64, faces, opts).unwrap();
    let size = size_of(pos);
    let tol = 1e-5 * size;
    let (mut i, mut j, mut worst, mut unmatched) = (0, 0, 0.0f64, 0);
    while i < segs.len() || j < refs.len() {
        let key_s = segs.get(i).map(|s| s.faces);
        let key_r = refs.get(j).map(|r| r.faces);
        if key_s.is_some() && key_s == key_r {
            let (s, r) = (&segs[i], &refs[j]);
            let (a, b) = (f64s(s.a), f64s(s.b));
            let d = (dist(a, r.a).max(dist(b, r.b))).min(dist(a, r.b).max(dist(b, r.a)));
            assert!(d <= tol, "{what}: pair {:?}: {s:?} vs {r:?}", s.faces);
            worst = worst.max(d / size);
            i += 1;
            j += 1;
        } else if key_r.is_none() || (key_s.is_some() && key_s < key_r) {
            let s = &segs[i];
            let len = dist(f64s(s.a), f64s(s.b));
            assert!(len <= tol, "{what}: twin only: {s:?} (length {len:e})");
            unmatched += 1;
            i += 1;
        } else {
            let r = &refs[j];
            let len = dist(r.a, r.b);
            assert!(len <= tol, "{what}: f64 only: {r:?} (length {len:e})");
            unmatched += 1;
            j += 1;
        }
    }
    assert!(
        unmatched * 100 <= refs.len().max(1),
        "{what}: {unmatched} unmatched"
    );
    eprintln!(
        "{what}: {} segments, f64 reference {}, {unmatched} unmatched, ends within {worst:.2e} of the size",
        segs.len(),
        refs.len()
    );
    worst
}

/// Joins ends closer than `1e-5 · size` and checks that every joined point
/// ends exactly two segments (segments shorter than that join their own
/// ends and are left out); returns the number of closed loops.
fn closed_loops(what: &str, segs: &[Segment], size: f64) -> usize {
    let tol = 1e-5 * size;
    let ends: Vec<[f64; 3]> = segs.iter().flat_map(|s| [f64s(s.a), f64s(s.b)]).collect();
    let mut order: Vec<usize> = (0..ends.len()).collect();
    order.sort_by(|&a, &b| ends[a][0].total_cmp(&ends[b][0]));
    let mut parent: Vec<usize> = (0..ends.len()).collect();
    fn root(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for (n, &a) in order.iter().enumerate() {
        for &b in &order[n + 1..] {
            if ends[b][0] - ends[a][0] > tol {
                break;
            }
            if dist(ends[a], ends[b]) <= tol {
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                parent[ra] = rb;
            }
        }
    }
    let mut degree = std::collections::HashMap::<usize, usize>::new();
    let mut links = Vec::new();
    for s in 0..segs.len() {
        let (a, b) = (root(&mut parent, 2 * s), root(&mut parent, 2 * s + 1));
        if a != b {
            *degree.entry(a).or_default() += 1;
            *degree.entry(b).or_default() += 1;
            links.push((a, b));
        }
    }
    let open: Vec<_> = degree.iter().filter(|&(_, &d)| d != 2).collect();
    assert!(
        open.is_empty(),
        "{what}: {} points not on two segments",
        open.len()
    );
    // loops: components of the joined points
    let mut comp: std::collections::HashMap<usize, usize> =
        degree.keys().map(|&k| (k, k)).collect();
    fn find(c: &mut std::collections::HashMap<usize, usize>, mut x: usize) -> usize {
        while c[&x] != x {
            x = c[&x];
        }
        x
    }
    for (a, b) in links {
        let (ra, rb) = (find(&mut comp, a), find(&mut comp, b));
        comp.insert(ra, rb);
    }
    let keys: Vec<usize> = comp.keys().copied().collect();
    let roots: std::collections::BTreeSet<usize> =
        keys.into_iter().map(|k| find(&mut comp, k)).collect();
    roots.len()
}

/// Distance from `p` to the plane of the triangle and whether its
/// projection lies inside, with barycentric slack `slack`.
fn on_triangle(p: [f64; 3], t: [[f64; 3]; 3], slack: f64) -> (f64, bool) {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let nn = dot(n, n);
    let plane = dot(n, sub(p, t[0])) / nn.sqrt();
    let bary = |i: usize| {
        dot(
            n,
            cross(sub(t[(i + 2) % 3], t[(i + 1) % 3]), sub(p, t[(i + 1) % 3])),
        )
    };
    let inside = (0..3).all(|i| bary(i) / nn >= -slack);
    (plane.abs(), inside)
}

/// Every end lies on both faces of its pair (within 1e-6 of the size off
/// their planes, inside them up to 1e-4 of their barycentric range).
fn ends_on_their_faces(what: &str, m: &Mesh, pos: &[[f32; 3]], segs: &[Segment]) {
    let size = size_of(pos);
    for s in segs {
        for f in s.faces {
            let t = m.faces[f as usize].map(|v| f64s(pos[v as usize]));
            for e in [s.a, s.b] {
                let (off, inside) = on_triangle(f64s(e), t, 1e-4);
                assert!(
                    off <= 1e-6 * size && inside,
                    "{what}: {s:?} off face {f}: {off:e}"
                );
            }
        }
    }
}

/// The largest gap between a face of a unit sphere's mesh and the sphere:
/// 1 − √(1 − R²), R the largest circumradius.
fn sagitta(m: &Mesh) -> f64 {
    let r = (m.faces.iter())
        .map(|f| {
            let p = f.map(|v| m.positions[v as usize]);
            let (a, b, c) = (dist(p[1], p[2]), dist(p[0], p[2]), dist(p[0], p[1]));
            let s = (a + b + c) / 2.0;
            let area = (s * (s - a) * (s - b) * (s - c)).sqrt();
            a * b * c / (4.0 * area)
        })
        .fold(0.0, f64::max);
    1.0 - (1.0 - r * r).sqrt()
}

#[test]
fn two_crossing_spheres_meet_on_the_circle() {
    let (m, counts) = two_spheres(4);
    let pos = to_f32(&m.positions);
    let opts = IntersectionOptions::by_input(&counts);
    let (segs, stats) = both("two spheres", &pos, &m.faces, &opts);
    assert!(segs.len() > 100, "{}", segs.len());
    assert!(stats.pairs_tested as usize >= segs.len());
    let split = counts[0] as u32;
    assert!(
        segs.iter()
            .all(|s| s.faces[0] < split && s.faces[1] >= split)
    );
    ends_on_their_faces("two spheres", &m, &pos, &segs);
    let s = sagitta(&icosphere(1.0, 4));
    let rho0 = 0.75f64.sqrt();
    let (mut dx, mut drho, mut length) = (0.0f64, 0.0f64, 0.0);
    for seg in &segs {
        for e in [seg.a, seg.b] {
            let p = f64s(e);
            dx = dx.max((p[0] - 0.5).abs());
            drho = drho.max(((p[1] * p[1] + p[2] * p[2]).sqrt() - rho0).abs());
        }
        length += dist(f64s(seg.a), f64s(seg.b));
    }
    eprintln!("two spheres: sagitta {s:.2e}, |x - 0.5| <= {dx:.2e}, |rho - rho0| <= {drho:.2e}");
    assert!(dx <= s + 1e-6, "{dx} vs sagitta {s}");
    assert!(drho <= 2.0 * s + 1e-6, "{drho} vs sagitta {s}");
    let circle = 2.0 * std::f64::consts::PI * rho0;
    assert!(
        (length - circle).abs() < 0.01 * circle,
        "{length} vs {circle}"
    );
    assert_eq!(closed_loops("two spheres", &segs, 2.0), 1);
    against_reference("two spheres", &pos, &m.faces, &opts, &segs);
}

#[test]
fn a_sphere_through_a_plane_meets_it_on_the_circle() {
    let c = 0.3125; // dyadic: exact in f32
    let sphere = turned(&icosphere(1.0, 4), [0.0; 3]);
    let flat = plane(33, 3.0).map_positions(|p| [p[0] + 0.01, p[1] - 0.02, c]);
    let (m, counts) = concat(&[sphere.clone(), flat]);
    let pos = to_f32(&m.positions);
    let opts = IntersectionOptions::by_input(&counts);
    let (segs, _) = both("sphere and plane", &pos, &m.faces, &opts);
    assert!(segs.len() > 50);
    ends_on_their_faces("sphere and plane", &m, &pos, &segs);
    let s = sagitta(&sphere);
    let rho0 = (1.0 - c * c).sqrt();
    let rho_lo = ((1.0 - s) * (1.0 - s) - c * c).sqrt();
    for seg in &segs {
        for e in [seg.a, seg.b] {
            let p = f64s(e);
            let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
            assert!((p[2] - c).abs() <= 1e-6, "{p:?}");
            assert!(rho >= rho_lo - 1e-6 && rho <= rho0 + 1e-6, "{p:?}: {rho}");
        }
    }
    assert_eq!(closed_loops("sphere and plane", &segs, 3.0), 1);
    against_reference("sphere and plane", &pos, &m.faces, &opts, &segs);
}

/// A closed tube around the lemniscate (cos u, sin u cos u, 0), whose two
/// passes through the origin cross at right angles; the tube's radius is
/// 0.2 on one pass and 0.1 on the other, so the thin pass runs through the
/// thick one: two loops, where it enters and where it leaves.
fn crossing_tube(nu: usize, nv: usize) -> Mesh {
    use std::f64::consts::PI;
    let mut m = torus(1.0, 0.4, nu, nv);
    for (i, p) in m.positions.iter_mut().enumerate() {
        let u = 2.0 * PI * (i / nv) as f64 / nu as f64;
        let v = 2.0 * PI * (i % nv) as f64 / nv as f64;
        let c = [u.cos(), u.sin() * u.cos()];
        let t = [-u.sin(), (2.0 * u).cos()];
        let tl = (t[0] * t[0] + t[1] * t[1]).sqrt();
        let nrm = [-t[1] / tl, t[0] / tl];
        let r = 0.15 + 0.05 * u.sin();
        *p = [
            c[0] + r * v.cos() * nrm[0],
            c[1] + r * v.cos() * nrm[1],
            r * v.sin(),
        ];
    }
    m
}

#[test]
fn a_tube_crossing_itself_is_found() {
    let m = crossing_tube(240, 16);
    let pos = to_f32(&m.positions);
    let opts = IntersectionOptions::default();
    let (segs, _) = both("crossing tube", &pos, &m.faces, &opts);
    assert!(segs.len() > 20, "{}", segs.len());
    ends_on_their_faces("crossing tube", &m, &pos, &segs);
    for s in &segs {
        for e in [s.a, s.b] {
            assert!(
                e[0].abs() < 0.35 && e[1].abs() < 0.35,
                "{s:?} far from the crossing"
            );
        }
    }
    assert_eq!(closed_loops("crossing tube", &segs, 2.4), 2);
    against_reference("crossing tube", &pos, &m.faces, &opts, &segs);
}

#[test]
fn two_spheres_in_one_mesh_cross_as_two_inputs() {
    let (m, counts) = two_spheres(3);
    let pos = to_f32(&m.positions);
    let grouped = IntersectionOptions::by_input(&counts);
    let (g, gs) = both("two spheres, groups", &pos, &m.faces, &grouped);
    let (one, os) = both("two spheres, one mesh", &pos, &m.faces, &Default::default());
    assert!(!g.is_empty());
    assert_eq!(bits(&one), bits(&g), "a convex mesh does not cross itself");
    assert!(os.pairs_tested > gs.pairs_tested);
    // one group for both: nothing is tested
    let same_group = IntersectionOptions {
        groups: Some(vec![7; m.faces.len()]),
    };
    let (none, ns) = both("two spheres, one group", &pos, &m.faces, &same_group);
    assert!(none.is_empty() && ns.pairs_tested == 0);
}

#[test]
fn groups_restrict_to_pairs_across_groups() {
    // A and B cross and share group 0; C crosses A only, group 1
    let a = icosphere(1.0, 3);
    let b = turned(&icosphere(1.0, 3), [1.0, 0.0, 0.0]);
    let c = turned(&icosphere(1.0, 3), [-1.2, 0.0, 0.3]);
    let (m, counts) = concat(&[a, b, c]);
    let pos = to_f32(&m.positions);
    let opts = IntersectionOptions::by_input(&[counts[0] + counts[1], counts[2]]);
    let (segs, _) = both("three spheres", &pos, &m.faces, &opts);
    assert!(!segs.is_empty());
    let (end_a, end_b) = (counts[0] as u32, (counts[0] + counts[1]) as u32);
    for s in &segs {
        assert!(
            s.faces[0] < end_a && s.faces[1] >= end_b,
            "{s:?}: not A with C"
        );
    }
    assert_eq!(closed_loops("three spheres", &segs, 3.2), 1);
    let (all, _) = both(
        "three spheres, by input",
        &pos,
        &m.faces,
        &IntersectionOptions::by_input(&counts),
    );
    assert_eq!(closed_loops("three spheres, by input", &all, 3.2), 2);
    against_reference("three spheres", &pos, &m.faces, &opts, &segs);
}

#[test]
fn meshes_apart_give_nothing() {
    let a = icosphere(1.0, 3);
    let b = turned(&icosphere(1.0, 3), [2.5, 0.0, 0.0]);
    let (m, counts) = concat(&[a, b]);
    let pos = to_f32(&m.positions);
    let (segs, stats) = both(
        "apart",
        &pos,
        &m.faces,
        &IntersectionOptions::by_input(&counts),
    );
    assert!(segs.is_empty());
    assert_eq!(stats.pairs_tested, 0, "their boxes do not meet");
    let (segs, stats) = both("apart, no groups", &pos, &m.faces, &Default::default());
    assert!(segs.is_empty());
    assert!(
        stats.pairs_tested > 0,
        "faces near each other are tested, and do not cross"
    );
}

#[test]
fn a_refit_pose_and_a_small_buffer_match_the_twin() {
    let (m, counts) = two_spheres(4);
    let opts = IntersectionOptions::by_input(&counts);
    let pos = to_f32(&m.positions);
    let mut bvh = Bvh::new(gpu(), pos.len(), &m.faces).unwrap();
    bvh.build(&pos).unwrap();
    let mut dev = Intersections::with_capacity(gpu(), m.faces.len(), &opts, 1).unwrap();
    let (first, st) = dev.find(&bvh).unwrap();
    assert!(
        st.reran && dev.capacity() == first.len(),
        "grown to the count"
    );
    let mut tree = Tree::new("two spheres", &pos, &m.faces).unwrap();
    let (cpu, _) = twin::find(&tree, &pos, &m.faces, &opts).unwrap();
    same("small buffer", &first, &cpu, 2.0);
    // the second sphere moves: refit, no rebuild
    let split = m.positions.len() - icosphere(1.0, 4).positions.len();
    let moved: Vec<[f32; 3]> = (pos.iter().enumerate())
        .map(|(i, p)| {
            if i >= split {
                [p[0] - 0.3, p[1] + 0.1, p[2] + 0.2]
            } else {
                *p
            }
        })
        .collect();
    bvh.refit(&moved).unwrap();
    tree.refit(&moved, &m.faces);
    let (dev2, st2) = dev.find(&bvh).unwrap();
    let (cpu2, _) = twin::find(&tree, &moved, &m.faces, &opts).unwrap();
    same("refit", &dev2, &cpu2, 2.0);
    assert!(
        dev2.len() > first.len(),
        "a deeper crossing is a longer curve"
    );
    assert!(!st2.reran || dev2.len() > first.len());
    assert!(dev.timing().kernel_ms >= 0.0 && dev.timing().steps.len() <= 2);
    assert_eq!(closed_loops("refit", &dev2, 2.0), 1);
    against_reference("refit", &moved, &m.faces, &opts, &cpu2);
}

#[test]
fn coplanar_and_degenerate_faces_give_no_line() {
    let mut pos: Vec<[f32; 3]> = vec![
        // two coplanar overlapping triangles (z = 0)
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.25, 0.25, 0.0],
        [1.25, 0.25, 0.0],
        [0.25, 1.25, 0.0],
        // a triangle through both (x = 0.5)
        [0.5, -1.0, -1.0],
        [0.5, 2.0, -1.0],
        [0.5, 0.5, 1.0],
    ];
    let mut faces = vec![[0u32, 1, 2], [3, 4, 5], [6, 7, 8]];
    // zero-area faces across the plane: collinear, a repeated corner, a point
    pos.extend([[0.3, 0.3, -1.0], [0.3, 0.3, 0.0], [0.3, 0.3, 1.0]]);
    faces.extend([[9, 10, 11], [9, 9, 11], [10, 10, 10]]);
    let (segs, stats) = both("coplanar", &pos, &faces, &Default::default());
    let pairs: Vec<[u32; 2]> = segs.iter().map(|s| s.faces).collect();
    assert_eq!(
        pairs,
        [[0, 2], [1, 2]],
        "the coplanar pair and the degenerate faces give none"
    );
    assert!(stats.pairs_tested >= 3);
    for s in &segs {
        assert!(s.a.iter().chain(&s.b).all(|c| c.is_finite()));
        assert!(s.a[0] == 0.5 && s.b[0] == 0.5 && s.a[2] == 0.0 && s.b[2] == 0.0);
    }
    against_reference("coplanar", &pos, &faces, &Default::default(), &segs);
}

#[test]
fn tiny_and_huge_scales_stay_finite_and_on_the_circle() {
    let (m, counts) = two_spheres(3);
    let opts = IntersectionOptions::by_input(&counts);
    let (unit, _) = both("scale 1", &to_f32(&m.positions), &m.faces, &opts);
    let s = sagitta(&icosphere(1.0, 3));
    for scale in [1e-15, 1e-6, 1e6, 1e15] {
        let what = format!("scale {scale:e}");
        let pos = to_f32(&m.map_positions(|p| p.map(|c| c * scale)).positions);
        let (segs, _) = both(&what, &pos, &m.faces, &opts);
        assert!(
            segs.len().abs_diff(unit.len()) <= unit.len() / 100,
            "{what}: {}",
            segs.len()
        );
        for seg in &segs {
            for e in [seg.a, seg.b] {
                let p = f64s(e).map(|c| c / scale);
                assert!(p.iter().all(|c| c.is_finite()), "{what}");
                assert!((p[0] - 0.5).abs() <= s + 1e-5, "{what}: {p:?}");
            }
        }
        assert_eq!(closed_loops(&what, &segs, 2.0 * scale), 1);
        against_reference(&what, &pos, &m.faces, &opts, &segs);
    }
    // normals overflow f32 (products of two coordinates near 1e30): no
    // line, and nothing infinite
    let pos = to_f32(&m.map_positions(|p| p.map(|c| c * 1e30)).positions);
    let (segs, _) = both("scale 1e30", &pos, &m.faces, &opts);
    assert!(segs.is_empty(), "{}", segs.len());
}

#[test]
fn no_face_one_face_and_bad_input() {
    let pos = vec![[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let none = IntersectionOptions::default();
    let (segs, stats) = both("no face", &pos, &[], &none);
    assert!(segs.is_empty() && stats == IntersectionStats::default());
    let (segs, stats) = both("one face", &pos, &[[0, 1, 2]], &none);
    assert!(segs.is_empty() && stats.pairs_tested == 0);

    let bad = IntersectionOptions {
        groups: Some(vec![0; 2]),
    };
    let e = Intersections::new(gpu(), 1, &bad)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("2 group ids for 1 faces"), "{e}");
    let tree = Tree::new("one", &pos, &[[0, 1, 2]]).unwrap();
    assert!(twin::find(&tree, &pos, &[[0, 1, 2]], &bad).is_err());
    assert!(
        twin::find(&tree, &pos, &[[0, 1, 2], [0, 1, 2]], &none).is_err(),
        "tree of 1 face"
    );
    let e = twin::find(&tree, &pos, &[[0, 1, 3]], &none)
        .unwrap_err()
        .to_string();
    assert!(e.contains("face 0") && e.contains('3'), "{e}");
    let nan = [[f32::NAN, 0.0, 0.0], pos[1], pos[2]];
    assert!(twin::find(&tree, &nan, &[[0, 1, 2]], &none).is_err());

    let mut bvh = Bvh::new(gpu(), 3, &[[0, 1, 2]]).unwrap();
    let mut dev = Intersections::new(gpu(), 1, &none).unwrap();
    let e = dev.find(&bvh).err().unwrap().to_string();
    assert!(e.contains("not built"), "{e}");
    bvh.build(&pos).unwrap();
    assert!(dev.find(&bvh).unwrap().0.is_empty());
    let mut other = Intersections::new(gpu(), 2, &none).unwrap();
    let e = other.find(&bvh).err().unwrap().to_string();
    assert!(e.contains("1 faces") && e.contains("for 2"), "{e}");
}
