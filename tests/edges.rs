//! Edges (House & Li, seed 002): topology rules, device vs CPU reference for
//! every kernel, analytic oracles (cube creases, flat plane, torus contours,
//! open-cylinder boundaries), the near-plane rule, degenerate caps, bad input.
//!
//! Outputs are indexed by edge or cap pair (no atomics, no appends), so the
//! canonical order is the index order and device and CPU compare element by
//! element. Cap kernels are compared on the *device's* edge-out buffer (CPU
//! from that stage on), so a classification tie cannot cascade.

mod common;

use common::{gpu, shared_mesh, to_f32};

use glam::Vec3;
use shapecue::Error;
use shapecue::cpu::edges as cpu;
use shapecue::mesh::edges::{EdgeTopology, parse_marked};
use shapecue::mesh::topology::vertex_normals;
use shapecue::mesh::{self, Mesh};
use shapecue::render::Camera;
use shapecue::spec::edges::{
    CapMode, EdgeOutput, EdgeParams, KIND_BOUNDARY, KIND_CONTOUR, KIND_CREASE, KIND_DRAWN,
    memory_use,
};
use shapecue::stages::edges::EdgeStage;
fn camera(eye: [f32; 3], target: [f32; 3]) -> Camera {
    let mut cam = Camera::look_at(Vec3::from(eye), Vec3::from(target));
    cam.fov_y_deg = 40.0;
    cam
}

fn params(eye: [f32; 3], target: [f32; 3]) -> EdgeParams {
    params_of(camera(eye, target))
}

fn params_of(cam: Camera) -> EdgeParams {
    EdgeParams::new(cam.view(320, 240))
}

fn topo(m: &Mesh) -> EdgeTopology {
    EdgeTopology::new(m, &[], "test").unwrap()
}

fn run(m: &Mesh, t: &EdgeTopology, p: &EdgeParams, mode: CapMode) -> EdgeOutput {
    let mut s = EdgeStage::new(gpu(), m, t).unwrap();
    s.run(p, mode).unwrap();
    s.read().unwrap()
}

fn count(kind: &[u32], bit: u32) -> usize {
    kind.iter().filter(|&&k| k & bit != 0).count()
}

fn close(a: [f32; 4], b: [f32; 4]) -> bool {
    let marker = |v: [f32; 4]| v[0].is_nan() && v[1] == 0.0 && v[2] == -1.0 && v[3] == 1.0;
    if marker(a) || marker(b) {
        return marker(a) && marker(b);
    }
    a.iter()
        .zip(b)
        .all(|(x, y)| (x - y).abs() <= 1e-3 * (1.0 + x.abs().max(y.abs())))
}

/// Device vs CPU for every kernel; returns the device output with caps of `mode`.
fn compare(m: &Mesh, t: &EdgeTopology, p: &EdgeParams, mode: CapMode) -> EdgeOutput {
    let dev = run(m, t, p, mode);
    let packed = p.pack().unwrap();
    let pos = to_f32(&m.positions);
    let (out, kind) = cpu::edges_detect(&packed, &pos, &vertex_normals(m), &t.edges);
    let mismatched = (0..t.edges.len())
        .filter(|&e| kind[e] != dev.kind[e])
        .count();
    // Ties (a face exactly edge-on) may classify differently after rounding.
    assert!(
        mismatched * 1000 <= t.edges.len(),
        "{mismatched} of {} edges classified differently",
        t.edges.len()
    );
    for e in 0..t.edges.len() {
        if kind[e] == dev.kind[e] {
            for k in 0..4 {
                let (a, b) = (dev.edge_out[4 * e + k], out[4 * e + k]);
                assert!(close(a, b), "edge {e} vertex {k}: device {a:?} cpu {b:?}");
            }
        }
    }
    match mode {
        CapMode::None => {}
        CapMode::Mh => {
            let (c0, c1) = cpu::caps_mh(&packed, &pos, &vertex_normals(m), &t.edges, &dev.edge_out);
            // A projected normal along the edge makes sign(m·p) a tie, decided by
            // rounding: allow a few triangles to open to the other side.
            let pairs: Vec<_> = dev
                .cap_mh0
                .iter()
                .zip(&c0)
                .chain(dev.cap_mh1.iter().zip(&c1))
                .collect();
            let differ = pairs.iter().filter(|(a, b)| !close(**a, **b)).count();
            assert!(
                differ <= 2 + pairs.len() / 100,
                "{differ} of {} mh cap vertices differ",
                pairs.len()
            );
        }
        CapMode::Adjacency => {
            let c = cpu::caps_adjacency(&packed, &t.edges, &t.caps, &dev.edge_out);
            assert_eq!(c.len(), dev.cap_adj.len());
            let differ = c
                .iter()
                .zip(&dev.cap_adj)
                .filter(|(a, b)| !close(**a, **b))
                .count();
            // Near-collinear pairs sit at the 1e-4 threshold: allow a few flips.
            assert!(
                differ * 1000 <= c.len().max(1000),
                "{differ} adjacency cap vertices differ"
            );
        }
    }
    no_nan_geometry(&dev.edge_out, 4);
    no_nan_geometry(&dev.cap_mh0, 3);
    no_nan_geometry(&dev.cap_mh1, 3);
    no_nan_geometry(&dev.cap_adj, 4);
    dev
}

/// Every primitive is either the marker on all its vertices or fully finite.
fn no_nan_geometry(v: &[[f32; 4]], per: usize) {
    for (i, prim) in v.chunks(per).enumerate() {
        let marker = prim
            .iter()
            .all(|q| q[0].is_nan() && q[1] == 0.0 && q[2] == -1.0 && q[3] == 1.0);
        let finite = prim.iter().flatten().all(|c| c.is_finite());
        assert!(
            marker || finite,
            "primitive {i} mixes NaN and geometry: {prim:?}"
        );
    }
}

#[test]
fn cube_topology_and_creases_at_30_degrees() {
    let m = mesh::cube(1.0);
    let t = topo(&m);
    assert_eq!(t.edges.len(), 18);
    assert_eq!((t.boundary, t.non_manifold), (0, 0));
    // Σ_v deg(v)(deg(v)−1)/2 over the 8 vertices.
    let mut deg = [0usize; 8];
    for e in &t.edges {
        deg[e[0] as usize] += 1;
        deg[e[1] as usize] += 1;
    }
    assert_eq!(
        t.caps.len(),
        deg.iter().map(|d| d * (d - 1) / 2).sum::<usize>()
    );
    let mut p = params([5.0, 5.0, 5.0], [0.0; 3]);
    p.contours = false;
    let out = compare(&m, &t, &p, CapMode::Adjacency);
    assert_eq!(count(&out.kind, KIND_CREASE), 12);
    // Every crease edge of the cube is axis-aligned: length 1.
    for (e, k) in t.edges.iter().zip(&out.kind) {
        let (a, b) = (m.positions[e[0] as usize], m.positions[e[1] as usize]);
        let len = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        assert_eq!(k & KIND_CREASE != 0, (len - 1.0).abs() < 1e-9, "edge {e:?}");
    }
    compare(&m, &t, &p, CapMode::Mh);
    // 100°: no cube edge is that sharp.
    p.crease_deg = Some(100.0);
    assert_eq!(count(&run(&m, &t, &p, CapMode::None).kind, KIND_CREASE), 0);
}

#[test]
fn flat_subdivided_plane_has_no_creases_and_its_border_is_boundary() {
    let m = mesh::plane(12, 2.0);
    let t = topo(&m);
    assert_eq!(t.boundary, 4 * 11);
    let p = params([1.0, 2.0, 3.0], [0.0; 3]);
    let out = compare(&m, &t, &p, CapMode::Adjacency);
    assert_eq!(count(&out.kind, KIND_CREASE), 0);
    assert_eq!(count(&out.kind, KIND_CONTOUR), 0);
    assert_eq!(count(&out.kind, KIND_BOUNDARY), 44);
    assert_eq!(count(&out.kind, KIND_DRAWN), 44);
}

#[test]
fn torus_along_its_axis_has_inner_and_outer_contours() {
    let (big_r, r) = (1.0, 0.4);
    let m = mesh::torus(big_r, r, 64, 32);
    let t = topo(&m);
    for ortho in [false, true] {
        let mut cam = camera([0.0, 0.0, 6.0], [0.0; 3]);
        if ortho {
            cam.ortho_height = Some(4.0);
        }
        let mut p = params_of(cam);
        p.crease_deg = None;
        let out = compare(&m, &t, &p, CapMode::Mh);
        let rho: Vec<f64> = t
            .edges
            .iter()
            .zip(&out.kind)
            .filter(|(_, k)| **k & KIND_CONTOUR != 0)
            .map(|(e, _)| {
                let (a, b) = (m.positions[e[0] as usize], m.positions[e[1] as usize]);
                (0.25 * ((a[0] + b[0]).powi(2) + (a[1] + b[1]).powi(2))).sqrt()
            })
            .collect();
        assert!(
            rho.iter().any(|&x| x > big_r + 0.8 * r),
            "outer contour (ortho {ortho})"
        );
        assert!(
            rho.iter().any(|&x| x < big_r - 0.8 * r),
            "inner contour (ortho {ortho})"
        );
        assert!(
            rho.iter().all(|&x| (x - big_r).abs() > 0.5 * r),
            "only silhouettes (ortho {ortho})"
        );
    }
}

#[test]
fn open_cylinder_boundary_edges() {
    let m = mesh::cylinder(0.5, 1.0, 24, 6);
    let t = topo(&m);
    assert_eq!(t.boundary, 48);
    let mut p = params([3.0, 1.0, 2.0], [0.0; 3]);
    p.contours = false;
    p.crease_deg = None;
    let out = compare(&m, &t, &p, CapMode::Adjacency);
    assert_eq!(count(&out.kind, KIND_BOUNDARY), 48);
    assert_eq!(count(&out.kind, KIND_DRAWN), 48);
    for (e, k) in t.edges.iter().zip(&out.kind) {
        assert_eq!(e[3] == e[0], k & KIND_BOUNDARY != 0);
    }
    // Consecutive boundary edges at a rim vertex form caps.
    assert!(out.cap_adj.chunks(4).any(|c| !c[0][0].is_nan()));
    p.boundaries = false;
    assert_eq!(count(&run(&m, &t, &p, CapMode::None).kind, KIND_DRAWN), 0);
}

#[test]
fn icosphere_and_depth_scaled_width_match_the_cpu() {
    let m = mesh::icosphere(1.0, 3);
    let t = topo(&m);
    let mut p = params([2.0, 3.0, 4.0], [0.0; 3]);
    for mode in CapMode::ALL {
        let out = compare(&m, &t, &p, mode);
        assert!(count(&out.kind, KIND_CONTOUR) > 20);
    }
    p.depth_scale = Some(10.0);
    p.line_width = 3.0;
    let out = compare(&m, &t, &p, CapMode::Adjacency);
    // With k/w > 1 everywhere the quads are wider than line_width.
    let q = &out.edge_out[4 * out.kind.iter().position(|k| k & KIND_DRAWN != 0).unwrap()..][..4];
    let px = |v: [f32; 4]| [v[0] / v[3] * 160.0, v[1] / v[3] * 120.0];
    let (a, b) = (px(q[0]), px(q[3]));
    let w = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
    assert!(w > 3.0 * 1.5, "depth-scaled width {w}");
}

#[test]
fn camera_inside_the_mesh_draws_nothing_through_the_near_plane() {
    let m = mesh::icosphere(1.0, 3);
    let t = topo(&m);
    let mut cam = camera([0.2, 0.1, 0.0], [1.0, 0.3, 0.2]);
    cam.near = 0.05;
    let mut p = params_of(cam);
    p.crease_deg = Some(5.0); // icosphere edges bend ~6°: many creases, all around the eye
    let out = compare(&m, &t, &p, CapMode::Adjacency);
    let drawn = count(&out.kind, KIND_DRAWN);
    assert!(
        drawn > 0 && drawn < count(&out.kind, KIND_CREASE),
        "some edges are behind the eye"
    );
    for q in out.edge_out.chunks(4).filter(|q| !q[0][0].is_nan()) {
        for v in q {
            assert!(v[3] > 0.05, "vertex at w = {} ≤ near", v[3]);
        }
    }
}

#[test]
fn camera_looking_away_gives_empty_output() {
    let m = mesh::icosphere(1.0, 2);
    let t = topo(&m);
    let p = params([0.0, 0.0, 5.0], [0.0, 0.0, 10.0]);
    let out = compare(&m, &t, &p, CapMode::Adjacency);
    assert_eq!(count(&out.kind, KIND_DRAWN), 0);
    assert!(out.cap_adj.iter().all(|v| v[0].is_nan()));
}

#[test]
fn collinear_and_folded_pairs_give_degenerate_caps_not_nan_geometry() {
    // A straight polyline of boundary edges: a strip of triangles along x.
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [2.0, 1.0, 0.0],
    ];
    let faces = vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
    let m = Mesh::new(positions, faces, "strip").unwrap();
    let t = topo(&m);
    let p = params([1.0, 0.5, 4.0], [1.0, 0.5, 0.0]);
    let out = compare(&m, &t, &p, CapMode::Adjacency);
    // Caps between the two collinear bottom edges (0-1, 1-2) are degenerate.
    let bottom: Vec<usize> = t
        .edges
        .iter()
        .enumerate()
        .filter(|(_, e)| {
            e[3] == e[0]
                && m.positions[e[0] as usize][1] == 0.0
                && m.positions[e[1] as usize][1] == 0.0
        })
        .map(|(i, _)| i)
        .collect();
    assert_eq!(bottom.len(), 2);
    let c = t
        .caps
        .iter()
        .position(|c| bottom.contains(&(c[0] as usize)) && bottom.contains(&(c[1] as usize)))
        .unwrap();
    assert!(out.cap_adj[4 * c][0].is_nan());
    // A corner (bottom edge 1-2 with the right edge 2-5) gets a real cap.
    assert!(
        out.cap_adj
            .chunks(4)
            .any(|q| q.iter().flatten().all(|v| v.is_finite()))
    );
}

#[test]
fn non_manifold_edges_pair_faces_in_order() {
    // Three triangles on the edge 0-1, and a fourth pair on 0-1 makes four.
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
        [0.5, 0.0, 1.0],
        [0.5, 0.0, -1.0],
    ];
    let three = Mesh::new(
        positions.clone(),
        vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
        "t",
    )
    .unwrap();
    let t = topo(&three);
    assert_eq!(t.non_manifold, 1);
    let e01: Vec<[u32; 4]> = t
        .edges
        .iter()
        .copied()
        .filter(|e| e[0].min(e[1]) == 0 && e[0].max(e[1]) == 1)
        .collect();
    assert_eq!(e01, vec![[0, 1, 2, 3], [0, 1, 4, 0]]);
    let four = Mesh::new(
        positions,
        vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 0, 5]],
        "f",
    )
    .unwrap();
    let t = topo(&four);
    let e01: Vec<[u32; 4]> = t
        .edges
        .iter()
        .copied()
        .filter(|e| e[0].min(e[1]) == 0 && e[0].max(e[1]) == 1)
        .collect();
    assert_eq!(e01, vec![[0, 1, 2, 3], [0, 1, 4, 5]]);
    // Duplicates of one edge never form a cap with each other.
    let dup: Vec<u32> = (0..t.edges.len() as u32)
        .filter(|&i| {
            let e = t.edges[i as usize];
            e[0].min(e[1]) == 0 && e[0].max(e[1]) == 1
        })
        .collect();
    assert!(
        !t.caps
            .iter()
            .any(|c| dup.contains(&c[0]) && dup.contains(&c[1]))
    );
    compare(
        &four,
        &t,
        &params([1.0, 2.0, 3.0], [0.5, 0.0, 0.0]),
        CapMode::Adjacency,
    );
}

#[test]
fn marked_edges_are_drawn_and_bad_lists_name_the_line() {
    let m = mesh::plane(4, 1.0);
    // An interior edge: vertices 5 and 6 (row 1, columns 1 and 2).
    let marked = parse_marked("# interior edge\n5, 6\n\n", "marks.txt").unwrap();
    assert_eq!(marked, vec![[5, 6]]);
    let t = EdgeTopology::new(&m, &marked, "marks.txt").unwrap();
    assert_eq!(t.marked, 1);
    let mut p = params([0.3, 0.2, 3.0], [0.0; 3]);
    p.crease_deg = None;
    let out = compare(&m, &t, &p, CapMode::None);
    assert_eq!(count(&out.kind, KIND_BOUNDARY), 12 + 1);
    let err = |text: &str| parse_marked(text, "marks.txt").unwrap_err().to_string();
    assert!(
        err("1 2\n3\n").contains("marks.txt: line 2"),
        "{}",
        err("1 2\n3\n")
    );
    assert!(err("1 x\n").contains("line 1") && err("1 x\n").contains("\"x\""));
    assert!(err("-1 2\n").contains("line 1"));
    assert!(err("4 4\n").contains("itself"));
    let e = EdgeTopology::new(&m, &[[0, 15]], "marks.txt")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("marked edge 1 (0, 15)") && e.contains("not an edge"),
        "{e}"
    );
    let e = EdgeTopology::new(&m, &[[0, 99]], "marks.txt")
        .unwrap_err()
        .to_string();
    assert!(e.contains("past the mesh's 16 vertices"), "{e}");
}

#[test]
fn bad_parameters_are_clear_errors() {
    let m = mesh::cube(1.0);
    let t = topo(&m);
    let mut s = EdgeStage::new(gpu(), &m, &t).unwrap();
    let ok = params([5.0, 5.0, 5.0], [0.0; 3]);
    let check = |p: EdgeParams, what: &str, s: &mut EdgeStage| {
        let e = s.run(&p, CapMode::Mh).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument(_)), "{e}");
        assert!(e.to_string().contains(what), "{e}");
    };
    for w in [0.0, -2.0, f32::NAN, f32::INFINITY] {
        let mut p = ok;
        p.line_width = w;
        check(p, "line width", &mut s);
    }
    let mut cam = camera([5.0, 5.0, 5.0], [0.0; 3]);
    cam.eye = cam.target;
    check(params_of(cam), "camera", &mut s);
    let mut cam = camera([5.0, 5.0, 5.0], [0.0; 3]);
    cam.eye.x = f32::NAN;
    check(params_of(cam), "camera", &mut s);
    let mut p = ok;
    p.crease_deg = Some(0.0);
    check(p, "crease", &mut s);
    let mut p = ok;
    p.depth_scale = Some(-1.0);
    check(p, "depth scale", &mut s);
    let mut p = ok;
    p.view.width = 0;
    check(p, "viewport", &mut s);
    let e = "round".parse::<CapMode>().unwrap_err().to_string();
    assert!(e.contains("unknown cap mode \"round\""), "{e}");
    assert_eq!("adjacency".parse::<CapMode>().unwrap(), CapMode::Adjacency);
}

#[test]
fn memory_use_counts_the_buffers() {
    let m = memory_use(CapMode::Adjacency, 10, 7);
    assert_eq!(m.edge_bits, 10 * 21 * 32);
    assert_eq!(m.cap_bits, 7 * 19 * 32);
    assert_eq!(memory_use(CapMode::Mh, 10, 7).cap_bits, 10 * 24 * 32);
    assert_eq!(memory_use(CapMode::None, 10, 7).cap_bits, 0);
}

#[test]
fn shared_meshes_match_the_cpu() {
    let Some(m) = shared_mesh("teapot.obj") else {
        return;
    };
    let m = mesh::unit_sized(&m);
    let t = topo(&m);
    let p = params([5.0, 5.0, 5.0], [0.0; 3]);
    for mode in CapMode::ALL {
        compare(&m, &t, &p, mode);
    }
}

#[test]
fn outputs_persist_correctly_across_frames() {
    // Undrawn-then-undrawn primitives are not rewritten: a stage reused for
    // different views, widths and cap modes must still match a fresh CPU run.
    let m = mesh::torus(1.0, 0.4, 48, 24);
    let t = topo(&m);
    let pos = to_f32(&m.positions);
    let mut s = EdgeStage::new(gpu(), &m, &t).unwrap();
    let views = [
        ([0.0, 0.0, 6.0], CapMode::Adjacency, 4.0),
        ([5.0, 1.0, 0.5], CapMode::Mh, 3.0),
        ([5.0, 1.0, 0.5], CapMode::Adjacency, 6.0),
        ([0.0, 0.0, 6.0], CapMode::Adjacency, 2.0),
        ([0.0, 0.0, -6.0], CapMode::Mh, 4.0),
        ([0.0, 0.0, 6.0], CapMode::Mh, 4.0),
    ];
    for (eye, mode, width) in views {
        let mut p = params(eye, [0.0; 3]);
        p.line_width = width;
        s.run(&p, mode).unwrap();
        let dev = s.read().unwrap();
        let packed = p.pack().unwrap();
        let (out, kind) = cpu::edges_detect(&packed, &pos, &vertex_normals(&m), &t.edges);
        let same = (0..t.edges.len())
            .filter(|&e| kind[e] == dev.kind[e])
            .count();
        assert!(same * 1000 >= 999 * t.edges.len(), "kinds after {eye:?}");
        for e in (0..t.edges.len()).filter(|&e| kind[e] == dev.kind[e]) {
            for k in 0..4 {
                assert!(
                    close(dev.edge_out[4 * e + k], out[4 * e + k]),
                    "edge {e} after {eye:?}"
                );
            }
        }
        if mode == CapMode::Adjacency {
            let c = cpu::caps_adjacency(&packed, &t.edges, &t.caps, &dev.edge_out);
            let differ = c
                .iter()
                .zip(&dev.cap_adj)
                .filter(|(a, b)| !close(**a, **b))
                .count();
            assert!(
                differ <= 4,
                "{differ} adjacency cap vertices differ after {eye:?}"
            );
        } else {
            let (c0, c1) =
                cpu::caps_mh(&packed, &pos, &vertex_normals(&m), &t.edges, &dev.edge_out);
            let differ = c0
                .iter()
                .zip(&dev.cap_mh0)
                .chain(c1.iter().zip(&dev.cap_mh1))
                .filter(|(a, b)| !close(**a, **b))
                .count();
            assert!(differ <= 6, "{differ} mh cap vertices differ after {eye:?}");
        }
    }
}

#[test]
fn a_huge_fan_is_refused_for_adjacency_caps_only() {
    // One apex with 30,000 triangles around it: 4.5·10⁸ cap pairs at the apex.
    let n = 30_000u32;
    let mut positions = vec![[0.0, 0.0, 1.0]];
    for i in 0..n {
        let a = i as f64 / n as f64 * std::f64::consts::TAU;
        positions.push([a.cos(), a.sin(), 0.0]);
    }
    let faces = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    let m = Mesh::new(positions, faces, "fan").unwrap();
    let e = EdgeTopology::new(&m, &[], "fan.obj")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("fan.obj: vertex 0:") && e.contains("cap pairs"),
        "{e}"
    );
    let t = EdgeTopology::without_caps(&m, &[], "fan.obj").unwrap();
    assert_eq!((t.edges.len(), t.caps.len()), (2 * n as usize, 0));
    let out = run(&m, &t, &params([0.5, 0.5, 3.0], [0.0; 3]), CapMode::Mh);
    assert_eq!(out.kind.len(), 2 * n as usize);
}

#[test]
fn ideal_stroke_of_one_segment_is_a_capsule() {
    // A horizontal edge from pixel x 20 to 60 at y = 50 (between pixel rows) of a 100x100 image,
    // half width 5: a 40x10 rectangle plus two half discs of radius 5.
    let to_clip = |x: f32, y: f32| [x / 50.0 - 1.0, 1.0 - y / 50.0, 0.0, 1.0];
    let (a, b) = (to_clip(20.0, 50.0), to_clip(60.0, 50.0));
    let quad = [a, b, b, a];
    let cov = st_ideal(&quad);
    let n = cov.iter().filter(|&&c| c).count() as f32;
    let area = 40.0 * 10.0 + std::f32::consts::PI * 25.0;
    assert!((n - area).abs() < 0.05 * area, "{n} pixels vs {area}");
    assert!(cov[50 * 100 + 40] && !cov[50 * 100 + 70] && !cov[40 * 100 + 40]);
}

fn st_ideal(edge_out: &[[f32; 4]]) -> Vec<bool> {
    shapecue::report::caps::ideal_coverage(edge_out, 100, 100, 5.0)
}

#[test]
fn caps_close_the_gaps_of_thick_edges() {
    use shapecue::render::Renderer;
    if common::unless_no_gl(Renderer::new(Default::default())).is_none() {
        return;
    }
    let m = mesh::unit_sized(&mesh::capped_cylinder(0.5, 1.0, 32));
    let t = topo(&m);
    let mut cam = camera([5.0, 5.0, 5.0], [0.0; 3]);
    cam.fov_y_deg = 20.0;
    let mut p = params_of(cam);
    p.line_width = 10.0;
    let q = shapecue::report::caps::cap_quality(gpu(), &m, &t, &p).unwrap();
    let (none, mh, adj) = (&q[0], &q[1], &q[2]);
    assert!(
        none.gap > 50,
        "thick edges without caps leave gaps: {none:?}"
    );
    assert!(adj.gap * 10 <= none.gap && mh.gap * 5 <= none.gap, "{q:?}");
    for r in &q {
        assert!(
            r.extra * 100 <= r.ideal,
            "caps stay inside the round stroke: {r:?}"
        );
    }
}

#[test]
fn half_contour_quads_open_outward() {
    let (big_r, r) = (1.0, 0.4);
    let m = mesh::torus(big_r, r, 64, 32);
    let t = topo(&m);
    let mut p = params([0.0, 0.0, 6.0], [0.0; 3]);
    p.crease_deg = None;
    p.half_contours = true;
    let out = compare(&m, &t, &p, CapMode::Adjacency);
    let px = |v: [f32; 4]| ((v[0] / v[3] * 160.0).powi(2) + (v[1] / v[3] * 120.0).powi(2)).sqrt();
    let (mut outer, mut inner) = (0, 0);
    for (i, (e, k)) in t.edges.iter().zip(&out.kind).enumerate() {
        if k & KIND_DRAWN == 0 {
            continue;
        }
        let q = &out.edge_out[4 * i..4 * i + 4];
        let (a, b) = (m.positions[e[0] as usize], m.positions[e[1] as usize]);
        let rho = (0.25 * ((a[0] + b[0]).powi(2) + (a[1] + b[1]).powi(2))).sqrt();
        // Slot 0 is the edge end itself; slot 3 lies outside the silhouette:
        // farther from the image centre on the outer contour, nearer on the inner one.
        if rho > big_r {
            outer += 1;
            assert!(px(q[3]) > px(q[0]), "outer contour opens outward");
        } else {
            inner += 1;
            assert!(px(q[3]) < px(q[0]), "inner contour opens into the hole");
        }
    }
    assert!(outer > 0 && inner > 0);
}

/// The primitives of a read-back that hold geometry (first vertex not NaN), in order.
fn geometry(v: &[[f32; 4]], per: usize) -> Vec<[f32; 4]> {
    v.chunks_exact(per)
        .filter(|p| !p[0][0].is_nan())
        .flatten()
        .copied()
        .collect()
}

#[test]
fn compact_read_back_holds_what_the_full_one_draws() {
    // The torus draws many scattered runs (one whole read), the plane only
    // its border (one read per run).
    for m in [
        mesh::unit_sized(&mesh::torus(1.0, 0.4, 96, 48)),
        mesh::plane(12, 1.0),
    ] {
        compact_read_back_case(&m);
    }
}

fn compact_read_back_case(m: &Mesh) {
    use shapecue::render::{MeshStyle, RenderOptions, Renderer, edges::draw_edges};
    let t = topo(m);
    // Two views, so that the second run also rewrites what the first drew.
    let views = [
        ([5.0, 5.0, 5.0], [0.0; 3]),
        ([0.2, 4.0, 0.5], [0.1, 0.0, 0.0]),
    ];
    let mut s = EdgeStage::new(gpu(), m, &t).unwrap();
    let gl = common::unless_no_gl(Renderer::new(RenderOptions {
        width: 320,
        height: 240,
        ..Default::default()
    }));
    let mut r = gl.map(|r| r.unwrap());
    for mode in CapMode::ALL {
        for &(eye, target) in &views {
            let cam = camera(eye, target);
            let mut p = params_of(cam);
            p.line_width = 3.0;
            s.run(&p, mode).unwrap();
            let (full, drawn) = (s.read().unwrap(), s.read_drawn().unwrap());
            let what = format!("{} from {eye:?}", mode.name());
            // The device's compaction equals its CPU twin's, bit for bit.
            let twin = shapecue::cpu::edges::compact_drawn(&full);
            let bits = |v: &[[f32; 4]]| v.iter().flatten().map(|c| c.to_bits()).collect::<Vec<_>>();
            for (d, t, name) in [
                (&drawn.edge_out, &twin.edge_out, "edge-out"),
                (&drawn.cap_mh0, &twin.cap_mh0, "cap_mh0"),
                (&drawn.cap_mh1, &twin.cap_mh1, "cap_mh1"),
                (&drawn.cap_adj, &twin.cap_adj, "cap_adj"),
            ] {
                assert!(
                    bits(d) == bits(t),
                    "{what}: {name} compacted on the device vs the twin"
                );
            }
            assert!(
                s.compact_timing()
                    .steps
                    .iter()
                    .any(|st| st.step.kernel() == "edges_compact"),
                "{what}: the compaction is timed"
            );
            assert_eq!(drawn.kind, full.kind, "{what}");
            assert!(
                count(&full.kind, KIND_DRAWN) > 0,
                "{what}: something is drawn"
            );
            for (d, f, per) in [
                (&drawn.edge_out, &full.edge_out, 4),
                (&drawn.cap_mh0, &full.cap_mh0, 3),
                (&drawn.cap_mh1, &full.cap_mh1, 3),
                (&drawn.cap_adj, &full.cap_adj, 4),
            ] {
                let (d, f) = (geometry(d, per), geometry(f, per));
                assert_eq!(d.len(), f.len(), "{what}");
                assert!(d.iter().zip(&f).all(|(a, b)| a == b), "{what}");
            }
            if let Some(r) = r.as_mut() {
                let pos = to_f32(&m.positions);
                let nrm = vertex_normals(m);
                let mut frame = |o: &EdgeOutput| {
                    r.begin(&cam).unwrap();
                    r.draw_mesh(&pos, &nrm, &[], &m.faces, MeshStyle::default())
                        .unwrap();
                    draw_edges(r, o, [0.0, 0.0, 0.0, 1.0]).unwrap();
                    r.finish().unwrap()
                };
                assert!(frame(&full) == frame(&drawn), "{what}: same image");
            }
        }
    }
}
