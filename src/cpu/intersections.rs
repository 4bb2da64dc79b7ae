//! CPU twin of `kernels/intersections.cl` (the `intersections` family,
//! types in [`crate::spec::intersections`]): the curves where faces of a
//! mesh cross, one segment per crossing face pair.
//!
//! Step `find`: for each leaf of the `bvh` family's tree ([`Tree`], built
//! and refitted over the same positions), a stack traversal with the leaf's
//! box (box–box overlap, exact) gives the candidate faces; a candidate is
//! tested when its index is above the leaf's face (each pair once), it
//! shares no vertex position with it, and (with groups) its group differs.
//! The pair test ([`triangle_pair`]) is Möller's interval overlap (1997, "A
//! fast triangle-triangle intersection test"), written here from the
//! paper's description with the segment's ends kept in 3-D:
//!
//! 1. signed distances of each triangle's vertices to the other's plane,
//!    `n · (v − p0)` with `n = (p1 − p0) × (p2 − p0)` divided by its largest
//!    absolute component (free of the mesh's scale; a zero-area face, whose
//!    normal is zero, gives no line); all of one sign: no crossing; all
//!    zero: coplanar, no line;
//! 2. each triangle meets the other's plane in a segment: its vertices at
//!    distance 0 and the crossings of its edges whose ends have strictly
//!    opposite signs, `p + (q − p) · dp / (dp − dq)` with the edge's ends in
//!    lexicographic order (so two faces sharing the edge compute the same
//!    bits, and the curve's segments meet end to end exactly);
//! 3. both segments lie on the line along `d = n1 × n2`; on the axis of d's
//!    largest component their intervals overlap in the intersection: its
//!    ends are the inner ends of the two intervals (the first triangle's on
//!    ties), kept only if of positive length and finite.
//!
//! The twin computes in f32 with the kernel's operations in the kernel's
//! order (Rust never fuses a multiply and an add), so the device, built
//! with the strict rules, gives the same bits after [`sort_canonical`].
//! [`find_brute`] is the f64 reference: the same test in f64 over every
//! pair of faces (an exact box test first skips pairs that cannot cross).

use crate::cpu::bvh::{Tree, check_faces, check_positions};
use crate::error::{Error, Result};
use crate::spec::bvh::{BvhBox, LEAF, STACK_DEPTH};
use crate::spec::intersections::{IntersectionOptions, IntersectionStats, Segment, sort_canonical};
use std::cmp::Ordering::{Greater, Less};
use std::ops::{Add, Div, Mul, Sub};

/// The arithmetic of the pair test: f32 (the twin) or f64 (the reference).
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
{
    /// Zero.
    const ZERO: Self;
    /// The absolute value.
    fn abs(self) -> Self;
    /// Neither infinite nor NaN.
    fn finite(self) -> bool;
}

impl Real for f32 {
    const ZERO: f32 = 0.0;
    fn abs(self) -> f32 {
        f32::abs(self)
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Real for f64 {
    const ZERO: f64 = 0.0;
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
}

/// A triangle's three corners.
pub type Tri<R> = [[R; 3]; 3];

fn sub<R: Real>(a: [R; 3], b: [R; 3]) -> [R; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross<R: Real>(a: [R; 3], b: [R; 3]) -> [R; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot<R: Real>(a: [R; 3], b: [R; 3]) -> R {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The face's normal `(p1 − p0) × (p2 − p0)` divided by its largest
/// absolute component, so that the distances and `n1 × n2` below are free
/// of the mesh's scale (products of two coordinate differences, not four);
/// `None` for a zero-area face (zero normal) or a normal that is not finite.
fn normal<R: Real>(t: &Tri<R>) -> Option<[R; 3]> {
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let mut m = n[0].abs();
    if n[1].abs() > m {
        m = n[1].abs();
    }
    if n[2].abs() > m {
        m = n[2].abs();
    }
    if m.partial_cmp(&R::ZERO) != Some(Greater) || !m.finite() {
        return None;
    }
    Some([n[0] / m, n[1] / m, n[2] / m])
}

/// Signed distances (scaled by |n|) of `t`'s corners to the plane through
/// `p0` with normal `n`.
fn distances<R: Real>(t: &Tri<R>, n: [R; 3], p0: [R; 3]) -> [R; 3] {
    [
        dot(n, sub(t[0], p0)),
        dot(n, sub(t[1], p0)),
        dot(n, sub(t[2], p0)),
    ]
}

/// All three strictly on one side.
fn one_side<R: Real>(d: [R; 3]) -> bool {
    let z = R::ZERO;
    (d[0] > z && d[1] > z && d[2] > z) || (d[0] < z && d[1] < z && d[2] < z)
}

/// `p` before `q` in lexicographic (x, y, z) order.
fn lex_less<R: Real>(p: [R; 3], q: [R; 3]) -> bool {
    p[0] < q[0] || (p[0] == q[0] && (p[1] < q[1] || (p[1] == q[1] && p[2] < q[2])))
}

/// Where the edge (p, q) with distances (dp, dq) of strictly opposite signs
/// crosses the plane, from the lexicographically first end.
fn crossing<R: Real>(p: [R; 3], dp: R, q: [R; 3], dq: R) -> [R; 3] {
    let ((p, dp), (q, dq)) = if lex_less(q, p) {
        ((q, dq), (p, dp))
    } else {
        ((p, dp), (q, dq))
    };
    let s = dp / (dp - dq);
    [
        p[0] + (q[0] - p[0]) * s,
        p[1] + (q[1] - p[1]) * s,
        p[2] + (q[2] - p[2]) * s,
    ]
}

/// Where triangle `t` (distances `d` to the other's plane) meets that
/// plane: its corners at distance 0, then the crossings of edges (0, 1),
/// (1, 2), (2, 0); `None` unless that is exactly two points.
fn on_plane<R: Real>(t: &Tri<R>, d: [R; 3]) -> Option<([R; 3], [R; 3])> {
    let z = R::ZERO;
    let mut pts = [[z; 3]; 3];
    let mut n = 0usize;
    for i in 0..3 {
        if d[i] == z && n < 3 {
            pts[n] = t[i];
            n += 1;
        }
    }
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        let opposite = (d[i] < z && d[j] > z) || (d[i] > z && d[j] < z);
        if opposite && n < 3 {
            pts[n] = crossing(t[i], d[i], t[j], d[j]);
            n += 1;
        }
    }
    (n == 2).then_some((pts[0], pts[1]))
}

/// The segment where triangles `t1` and `t2` cross, running along
/// `n1 × n2`, or `None`: no crossing, coplanar or degenerate faces, a touch
/// at one point, or a result that is not finite. See the module's steps.
pub fn triangle_pair<R: Real>(t1: &Tri<R>, t2: &Tri<R>) -> Option<([R; 3], [R; 3])> {
    let z = R::ZERO;
    let n2 = normal(t2)?;
    let d1 = distances(t1, n2, t2[0]);
    if one_side(d1) {
        return None;
    }
    let n1 = normal(t1)?;
    let d2 = distances(t2, n1, t1[0]);
    if one_side(d2) || d1.iter().all(|&x| x == z) || d2.iter().all(|&x| x == z) {
        return None;
    }
    let d = cross(n1, n2);
    let mut k = 0;
    if d[1].abs() > d[k].abs() {
        k = 1;
    }
    if d[2].abs() > d[k].abs() {
        k = 2;
    }
    // zero (parallel planes) or NaN: no line
    if d[k].abs().partial_cmp(&z) != Some(Greater) {
        return None;
    }
    let (mut p0, mut p1) = on_plane(t1, d1)?;
    let (mut q0, mut q1) = on_plane(t2, d2)?;
    if p1[k] < p0[k] {
        (p0, p1) = (p1, p0);
    }
    if q1[k] < q0[k] {
        (q0, q1) = (q1, q0);
    }
    let mut start = if q0[k] > p0[k] { q0 } else { p0 };
    let mut end = if q1[k] < p1[k] { q1 } else { p1 };
    // positive length only (a touch at one point gives nothing)
    if start[k].partial_cmp(&end[k]) != Some(Less) {
        return None;
    }
    if d[k] < z {
        (start, end) = (end, start);
    }
    start
        .iter()
        .chain(&end)
        .all(|c| c.finite())
        .then_some((start, end))
}

/// Whether two triangles share a corner position (bit for bit, −0 = +0).
pub fn share_a_vertex<R: Real>(t1: &Tri<R>, t2: &Tri<R>) -> bool {
    t1.iter().any(|p| t2.contains(p))
}

/// Whether two boxes overlap (closed boxes: touching counts).
pub fn boxes_overlap(a: &BvhBox, b: &BvhBox) -> bool {
    (0..3).all(|k| a.lo[k] <= b.hi[k] && b.lo[k] <= a.hi[k])
}

/// Checks that `tree` is a tree over `n_faces` faces whose references stay
/// in range (a [`Tree`] from [`Tree::new`] always is).
fn check_tree(tree: &Tree, n_faces: usize) -> Result<()> {
    let n = tree.faces_sorted.len();
    let nodes_ok = tree.nodes.len() == n.saturating_sub(1)
        && tree.node_boxes.len() == tree.nodes.len()
        && tree.leaf_boxes.len() == n
        && (tree.nodes.iter()).all(|nd| {
            [nd.left, nd.right].iter().all(|&c| {
                if c & LEAF != 0 {
                    ((c & !LEAF) as usize) < n
                } else {
                    (c as usize) < tree.nodes.len()
                }
            })
        });
    let faces_ok = n == n_faces && tree.faces_sorted.iter().all(|&f| (f as usize) < n_faces);
    if nodes_ok && faces_ok {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "intersections: the tree holds {n} leaves, {} nodes; it is not a tree over these \
             {n_faces} faces (build it with Tree::new over the same mesh)",
            tree.nodes.len()
        )))
    }
}

/// The inputs of one search, checked.
struct Search<'a> {
    tree: &'a Tree,
    positions: &'a [[f32; 3]],
    faces: &'a [[u32; 3]],
    groups: Option<&'a [u32]>,
}

impl Search<'_> {
    fn tri(&self, f: u32) -> Tri<f32> {
        self.faces[f as usize].map(|v| self.positions[v as usize])
    }

    /// The kernel's work-item for `leaf`: its pairs with higher faces, the
    /// segments appended to `out`; returns (pairs tested, stack overflows).
    fn leaf(&self, leaf: usize, out: &mut Vec<Segment>) -> (u64, u32) {
        let t = self.tree;
        let f = t.faces_sorted[leaf];
        let bx = t.leaf_boxes[leaf];
        let t1 = self.tri(f);
        let (mut tested, mut overflows) = (0u64, 0u32);
        let mut stack = [0u32; STACK_DEPTH];
        let mut sp = 0usize;
        if let Some(root) = t.root().filter(|&r| boxes_overlap(&t.child_box(r), &bx)) {
            stack[0] = root;
            sp = 1;
        }
        while sp > 0 {
            sp -= 1;
            let r = stack[sp];
            if r & LEAF == 0 {
                let nd = t.nodes[r as usize];
                for c in [nd.left, nd.right] {
                    if !boxes_overlap(&t.child_box(c), &bx) {
                        continue;
                    }
                    if sp == STACK_DEPTH {
                        overflows += 1;
                    } else {
                        stack[sp] = c;
                        sp += 1;
                    }
                }
                continue;
            }
            let g = t.faces_sorted[(r & !LEAF) as usize];
            let t2 = self.tri(g);
            let same_group = self
                .groups
                .is_some_and(|gr| gr[f as usize] == gr[g as usize]);
            if g <= f || same_group || share_a_vertex(&t1, &t2) {
                continue;
            }
            tested += 1;
            if let Some((a, b)) = triangle_pair(&t1, &t2) {
                out.push(Segment {
                    a,
                    b,
                    faces: [f, g],
                });
            }
        }
        (tested, overflows)
    }
}

/// Step `find`: every crossing of the mesh's faces, in canonical order
/// ([`sort_canonical`]), with the search's stats. `tree` is the `bvh`
/// twin's tree over these faces, built or refitted at `positions`.
pub fn find(
    tree: &Tree,
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    opts: &IntersectionOptions,
) -> Result<(Vec<Segment>, IntersectionStats)> {
    let what = "intersections mesh";
    check_faces(what, positions.len(), faces)?;
    check_positions(what, positions.len(), positions)?;
    opts.check(what, faces.len())?;
    check_tree(tree, faces.len())?;
    let s = Search {
        tree,
        positions,
        faces,
        groups: opts.groups.as_deref(),
    };
    let mut out = Vec::new();
    let (mut tested, mut overflows) = (0u64, 0u32);
    for leaf in 0..faces.len() {
        let (t, o) = s.leaf(leaf, &mut out);
        tested += t;
        overflows += o;
    }
    if overflows > 0 {
        return Err(Error::InvalidArgument(format!(
            "intersections: the traversal stack of {STACK_DEPTH} entries overflowed {overflows} \
             times (the tree is deeper than a Karras tree can be)"
        )));
    }
    sort_canonical(&mut out);
    let stats = IntersectionStats {
        pairs_tested: tested.min(u32::MAX as u64) as u32,
        segments: out.len(),
        reran: false,
    };
    Ok((out, stats))
}

/// A segment of the f64 reference ([`find_brute`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReferenceSegment {
    /// First end.
    pub a: [f64; 3],
    /// Second end.
    pub b: [f64; 3],
    /// The two faces, lower index first.
    pub faces: [u32; 2],
}

/// The box of an f64 triangle: (lo, hi).
fn box64(t: &Tri<f64>) -> ([f64; 3], [f64; 3]) {
    let lo = std::array::from_fn(|k| t[0][k].min(t[1][k]).min(t[2][k]));
    let hi = std::array::from_fn(|k| t[0][k].max(t[1][k]).max(t[2][k]));
    (lo, hi)
}

/// The f64 reference: [`triangle_pair`] in f64 over every pair of faces
/// `f < g` that share no vertex position (and, with groups, lie in
/// different groups), by face pair. Pairs whose boxes do not overlap are
/// skipped first (they cannot cross); there is no tree.
pub fn find_brute(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    opts: &IntersectionOptions,
) -> Result<Vec<ReferenceSegment>> {
    let what = "intersections reference mesh";
    check_faces(what, positions.len(), faces)?;
    if let Some(i) = (positions.iter()).position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(Error::InvalidInput {
            source_name: what.to_string(),
            element: format!("vertex {i}"),
            problem: "position is not finite".to_string(),
        });
    }
    opts.check(what, faces.len())?;
    let tris: Vec<Tri<f64>> = (faces.iter())
        .map(|f| f.map(|v| positions[v as usize]))
        .collect();
    let boxes: Vec<_> = tris.iter().map(box64).collect();
    let groups = opts.groups.as_deref();
    let mut out = Vec::new();
    for f in 0..tris.len() {
        for g in f + 1..tris.len() {
            let (a, b) = (&boxes[f], &boxes[g]);
            let overlap = (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k]);
            if !overlap
                || groups.is_some_and(|gr| gr[f] == gr[g])
                || share_a_vertex(&tris[f], &tris[g])
            {
                continue;
            }
            if let Some((a, b)) = triangle_pair(&tris[f], &tris[g]) {
                out.push(ReferenceSegment {
                    a,
                    b,
                    faces: [f as u32, g as u32],
                });
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const FLAT: Tri<f64> = [[-1.0, -1.0, 0.0], [2.0, -1.0, 0.0], [-1.0, 2.0, 0.0]];

    #[test]
    fn a_triangle_through_a_flat_one_crosses_along_a_line() {
        // x = 0.25, z from -1 to 1: crosses the plane z = 0 along y
        let t2: Tri<f64> = [[0.25, -0.5, -1.0], [0.25, 0.5, -1.0], [0.25, 0.0, 1.0]];
        let (a, b) = triangle_pair(&FLAT, &t2).unwrap();
        for p in [a, b] {
            assert_eq!(p[2], 0.0);
            assert_eq!(p[0], 0.25);
        }
        let mut ys = [a[1], b[1]];
        ys.sort_by(f64::total_cmp);
        assert_eq!(ys, [-0.25, 0.25]);
        // along n1 × n2: n1 = (0, 0, 9), n2 = (2, 0, 0) (times signs)
        let n1 = normal(&FLAT).unwrap();
        let n2 = normal(&t2).unwrap();
        let d = cross(n1, n2);
        assert!((b[1] - a[1]) * d[1] > 0.0);
        // the same pair swapped runs the other way
        let (a2, b2) = triangle_pair(&t2, &FLAT).unwrap();
        assert_eq!((a2, b2), (b, a));
    }

    #[test]
    fn coplanar_touching_and_degenerate_pairs_give_nothing() {
        let coplanar: Tri<f64> = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(triangle_pair(&FLAT, &coplanar), None);
        // touches the plane at one corner only
        let touch: Tri<f64> = [[0.0, 0.0, 0.0], [0.5, 0.0, 1.0], [0.0, 0.5, 1.0]];
        assert_eq!(triangle_pair(&FLAT, &touch), None);
        // crosses the plane outside the flat triangle
        let outside: Tri<f64> = [[5.0, 5.0, -1.0], [6.0, 5.0, 1.0], [5.0, 6.0, 1.0]];
        assert_eq!(triangle_pair(&FLAT, &outside), None);
        // zero area: collinear, and a repeated corner
        let line: Tri<f64> = [[0.0, 0.0, -1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let repeated: Tri<f64> = [[0.1, 0.1, -1.0], [0.1, 0.1, -1.0], [0.2, 0.1, 1.0]];
        for t in [line, repeated] {
            assert_eq!(triangle_pair(&FLAT, &t), None);
            assert_eq!(triangle_pair(&t, &FLAT), None);
        }
        // an edge lying in the plane: the faces touch along it, and that
        // line is their intersection (from either side of the plane)
        for apex in [1.0, -1.0] {
            let t: Tri<f64> = [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.25, 0.3, apex]];
            let (a, b) = triangle_pair(&FLAT, &t).unwrap();
            let mut xs = [a[0], b[0]];
            xs.sort_by(f64::total_cmp);
            assert_eq!(xs, [0.0, 0.5]);
            assert!(a[1] == 0.0 && b[1] == 0.0 && a[2] == 0.0 && b[2] == 0.0);
        }
    }

    #[test]
    fn overflowing_coordinates_give_nothing_rather_than_infinities() {
        let big = 1e30f32;
        let t1: Tri<f32> = [[-big, -big, 0.0], [big, -big, 0.0], [-big, big, 0.0]];
        let t2: Tri<f32> = [[0.0, -big, -big], [0.0, big, -big], [0.0, 0.0, big]];
        // normals overflow to infinity: no panic, and nothing infinite
        if let Some((a, b)) = triangle_pair(&t1, &t2) {
            assert!(a.iter().chain(&b).all(|c| c.is_finite()));
        }
        let tiny = 1e-30f32;
        let s1 = t1.map(|p| p.map(|c| c / big * tiny));
        let s2 = t2.map(|p| p.map(|c| c / big * tiny));
        if let Some((a, b)) = triangle_pair(&s1, &s2) {
            assert!(a.iter().chain(&b).all(|c| c.is_finite()));
        }
    }

    #[test]
    fn a_shared_edge_crossing_has_the_same_bits_from_both_faces() {
        let p = [0.1f32, 0.7, -0.3];
        let q = [0.4f32, -0.2, 0.9];
        let (dp, dq) = (-0.37f32, 0.81f32);
        assert_eq!(crossing(p, dp, q, dq), crossing(q, dq, p, dp));
    }
}
