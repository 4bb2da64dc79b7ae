//! Unit tests of the visibility family's plan and rounds.
use super::*;

/// Two triangles sharing the edge (1, 2), seen from above.
fn quad() -> (Vec<[f32; 3]>, Vec<[u32; 3]>, View) {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    (
        p,
        vec![[0, 1, 2], [1, 3, 2]],
        View::from_eye([0.5, 0.5, 5.0], false),
    )
}

#[test]
fn a_segment_lies_on_the_faces_both_ends_name() {
    let (p, f, view) = quad();
    let opts = VisibilityOptions::default();
    let s = |e0: [u32; 2], e1: [u32; 2]| Segment::new([0.2; 3], [0.4; 3], 0, 1.0, [e0, e1]);
    let segs = [
        s([0, 1], [1, 2]),         // face 0 only
        s([1, 2], [1, 2]),         // along the shared edge: both
        s([2, 2], [LINE_FREE, 1]), // vertex 2 and face 1
        s([u32::MAX, 0], [1, 3]),  // face 0 and an edge of face 1: the union
        s([0, 3], [0, 3]),         // no such edge: nothing
    ];
    let plan = RayPlan::new(&p, &f, &segs, &view, &opts).unwrap();
    let ex: Vec<Vec<u32>> = plan.segs.iter().map(|s| s.exclude.to_vec()).collect();
    assert_eq!(ex, vec![vec![0], vec![0, 1], vec![1], vec![0, 1], vec![]]);
    assert!(plan.segs.iter().all(|s| s.offset > 0.0 && s.intervals >= 1));
}

#[test]
fn rounds_place_the_split_by_bisection_and_merge_equal_neighbours() {
    let (p, f, view) = quad();
    let opts = VisibilityOptions {
        spacing: Spacing::Diagonal(0.1),
        bisect: 12,
        contour_offset: 0.0,
    };
    let seg = Segment::new([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0, 1.0, [[0, 0], [1, 1]]);
    // The same line with ends of its own (ends at one vertex share
    // their sample: see the next test).
    let other = Segment::new(seg.a, seg.b, 0, 1.0, [[2, 2], [3, 3]]);
    let plan = RayPlan::new(&p, &f, &[seg, other], &view, &opts).unwrap();
    let mut rounds = 0;
    let got = classify_by(&plan, |casts| {
        rounds += 1;
        // Segment 0: hidden for t > 0.3; segment 1: always visible.
        Ok(casts.iter().map(|&(s, t)| s == 0 && t > 0.3).collect())
    })
    .unwrap();
    assert_eq!(rounds, 1 + 12);
    assert_eq!(got[1], vec![(0.0, 1.0, true)]);
    assert_eq!(got[0].len(), 2);
    assert!((got[0][0].1 - 0.3).abs() < 1e-4, "{:?}", got[0]);
    assert!(got[0][0].2 && !got[0][1].2);
    let (same, len) = agreement(&got[0], &got[1], 2.0);
    assert!((same - 0.6).abs() < 1e-3 && len == 2.0, "{same}");
}

#[test]
fn ends_on_one_edge_or_vertex_share_one_sample() {
    let (p, f, view) = quad();
    let opts = VisibilityOptions {
        spacing: Spacing::Diagonal(10.0),
        ..Default::default()
    };
    // Two ridges (one interval each) crossing edge (1, 2) from faces 0 and
    // 1, meeting there (their crossings differ by rounding), and a third.
    let a = Segment::new([0.1, 0.1, 0.0], [0.5, 0.5, 0.0], 2, 1.0, [[0, 1], [1, 2]]);
    let b = Segment::new(
        [0.5000001, 0.5, 0.0],
        [0.9, 0.9, 0.0],
        2,
        1.0,
        [[2, 1], [1, 3]],
    );
    let c = Segment::new(
        [0.2, 0.0, 0.0],
        [0.3, 0.0, 0.0],
        2,
        1.0,
        [[LINE_FREE, 0], [LINE_FREE, 0]],
    );
    let plan = RayPlan::new(&p, &f, &[a, b, c], &view, &opts).unwrap();
    assert_eq!(plan.segs[0].end_ids[1], plan.segs[1].end_ids[0]);
    assert_eq!(plan.ends.len(), 5);
    let shared = &plan.ends[plan.segs[0].end_ids[1] as usize];
    // The least point (by its bits), both faces left out.
    assert_eq!(shared.p, a.b);
    assert_eq!(shared.exclude.to_vec(), vec![0, 1]);
    let mut casts = Vec::new();
    classify_by(&plan, |c| {
        casts.extend_from_slice(c);
        Ok(vec![false; c.len()])
    })
    .unwrap();
    // Six ends, one shared: five samples in the first round.
    assert_eq!(casts.len(), 5, "{casts:?}");
    let q = plan.query((1, 0.0)).unwrap();
    assert_eq!(q, plan.query((0, 1.0)).unwrap());
    // A contour (kind 0) as short gets two intervals: a sample inside.
    let contour = Segment::new(a.a, a.b, 0, 1.0, a.ends);
    let plan = RayPlan::new(&p, &f, &[contour], &view, &opts).unwrap();
    assert_eq!(plan.segs[0].intervals, 2);
}

#[test]
fn agreement_is_length_weighted() {
    let got = [
        vec![(0.0, 0.3, true), (0.3, 1.0, false)],
        vec![(0.0, 1.0, true)],
    ];
    let (same, len) = agreement(&got[0], &got[1], 2.0);
    assert!((same - 0.6).abs() < 1e-3 && len == 2.0, "{same}");
}

#[test]
fn the_plan_is_the_same_on_any_number_of_threads() {
    // A grid of 60 × 60 cells, two faces each; in every face a line of one
    // of two families from one edge to another, so that most ends meet
    // another face's end on a shared edge; some ends inside faces, one at
    // a vertex.
    let n = 60u32;
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            p.push([x, y, 0.05 * (7.0 * x).sin() * (5.0 * y).cos()]);
        }
    }
    let at = |i: u32, j: u32| j * (n + 1) + i;
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..n {
            faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            faces.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let mid = |u: u32, v: u32| -> [f32; 3] {
        let (a, b) = (p[u as usize], p[v as usize]);
        std::array::from_fn(|k| 0.5 * (a[k] + b[k]))
    };
    let mut segs = Vec::new();
    for (fi, t) in faces.iter().enumerate() {
        let family = if fi % 3 == 0 { 2 } else { 0 };
        let e0 = [t[0].min(t[1]), t[0].max(t[1])];
        let e1 = [t[1].min(t[2]), t[1].max(t[2])];
        let mut s = Segment::new(mid(t[0], t[1]), mid(t[1], t[2]), family, 1.0, [e0, e1]);
        if fi % 17 == 0 {
            s.ends[1] = [LINE_FREE, fi as u32];
        }
        if fi == 5 {
            s.ends[0] = [t[0], t[0]];
            s.a = p[t[0] as usize];
        }
        segs.push(s);
    }
    let view = View::from_eye([0.5, 0.4, 3.0], false);
    let opts = VisibilityOptions::default();
    let one = RayPlan::on_threads((&p, &faces), &segs, &view, &opts, 1).unwrap();
    assert!(
        one.ends.len() < 2 * segs.len() - 1000,
        "ends are shared: {}",
        one.ends.len()
    );
    for threads in [2, 3, 7] {
        let many = RayPlan::on_threads((&p, &faces), &segs, &view, &opts, threads).unwrap();
        assert_eq!(many, one, "{threads} threads");
    }
    // The error is the first bad segment's, on any number of threads.
    let mut bad = segs.clone();
    bad[6000].a[0] = f32::NAN;
    bad[2000].b[1] = f32::INFINITY;
    for threads in [1, 3] {
        let e = RayPlan::on_threads((&p, &faces), &bad, &view, &opts, threads).unwrap_err();
        assert!(e.to_string().contains("segment 2000"), "{e}");
    }
}
