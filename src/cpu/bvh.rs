//! CPU reference of `kernels/bvh.cl` (the `bvh` family, layout in
//! [`crate::spec::bvh`]), with the device's steps: `morton` (integer codes
//! of the face centroids, [`MortonFrame`]), the sort of (code, face) pairs
//! (stable: ties keep face order, as the device's radix sort), `build`
//! (Karras 2012: each internal node's range from the sign of δ and a binary
//! search, its split by a binary search on the common prefix of the
//! augmented key (code, index)), `refit` (leaf boxes from the triangles,
//! internal boxes bottom-up with one visit counter per node: the second
//! child to arrive computes the parent, and writes both children's boxes
//! padded for the queries, [`Tree::child_boxes`]) and `occluded` (stack
//! traversal with the kernel's f32 arithmetic, over the padded child boxes). Boxes are min/max of f32 values, exact in
//! any order, so they equal the device's bit for bit.
//!
//! [`occluded_brute`] is the f64 brute-force reference the tests compare
//! both with: the same segment–triangle test (Möller–Trumbore, scaled by the
//! determinant so there is no division; epsilons [`EDGE_EPS`] and
//! [`END_EPS`]) in f64 over every face.

use crate::error::Result;
use crate::spec::bvh::{
    BOX_PAD, BvhBox, BvhNode, BvhQuery, EDGE_EPS, END_EPS, LEAF, MortonFrame, NONE, OCCLUDED,
    OVERFLOW, STACK_DEPTH, VISIBLE, bvh_bound,
};
pub use crate::spec::bvh::{Tree, check_faces, check_positions};

/// Step `morton`: the code of each face (mesh order).
pub fn morton(positions: &[[f32; 3]], faces: &[[u32; 3]], frame: &MortonFrame) -> Vec<u32> {
    let p = |v: u32| positions[v as usize];
    faces
        .iter()
        .map(|f| frame.code(p(f[0]), p(f[1]), p(f[2])))
        .collect()
}

/// The sort: (code, face) pairs by code, stably (what the device's radix
/// sort of 30-bit keys gives).
pub fn sort(codes: &[u32]) -> (Vec<u32>, Vec<u32>) {
    let mut pairs: Vec<(u32, u32)> = codes.iter().copied().zip(0..).collect();
    pairs.sort_by_key(|p| p.0);
    pairs.into_iter().unzip()
}

/// Karras's δ(i, j): the common prefix length of the augmented keys
/// (code, index) of leaves i and j, −1 when j is out of range.
fn delta(keys: &[u32], i: i64, j: i64) -> i64 {
    if j < 0 || j >= keys.len() as i64 {
        return -1;
    }
    let (a, b) = (keys[i as usize], keys[j as usize]);
    if a == b {
        32 + ((i as u32) ^ (j as u32)).leading_zeros() as i64
    } else {
        (a ^ b).leading_zeros() as i64
    }
}

/// Internal node `i` of Karras's tree over the sorted `keys`: its
/// `(left, right)` child references.
pub fn karras_node(keys: &[u32], i: usize) -> (u32, u32) {
    let i = i as i64;
    let d: i64 = if delta(keys, i, i + 1) > delta(keys, i, i - 1) {
        1
    } else {
        -1
    };
    let dmin = delta(keys, i, i - d);
    let mut lmax: i64 = 2;
    while delta(keys, i, i + lmax * d) > dmin {
        lmax *= 2;
    }
    let mut l: i64 = 0;
    let mut t = lmax / 2;
    while t >= 1 {
        if delta(keys, i, i + (l + t) * d) > dmin {
            l += t;
        }
        t /= 2;
    }
    let j = i + l * d;
    let dnode = delta(keys, i, j);
    let mut s: i64 = 0;
    let mut div: i64 = 2;
    loop {
        let t = (l + div - 1) / div;
        if delta(keys, i, i + (s + t) * d) > dnode {
            s += t;
        }
        if t <= 1 {
            break;
        }
        div *= 2;
    }
    let gamma = i + s * d + d.min(0);
    let left = if i.min(j) == gamma {
        LEAF | gamma as u32
    } else {
        gamma as u32
    };
    let right = if i.max(j) == gamma + 1 {
        LEAF | (gamma + 1) as u32
    } else {
        (gamma + 1) as u32
    };
    (left, right)
}

/// Step `build`: the internal nodes and leaf parents over sorted `keys`.
pub fn build(keys: &[u32]) -> (Vec<BvhNode>, Vec<u32>) {
    let (leaves, internal) = bvh_bound(keys.len());
    let mut nodes = vec![
        BvhNode {
            parent: NONE,
            ..BvhNode::default()
        };
        internal
    ];
    let mut leaf_parent = vec![NONE; leaves];
    for i in 0..internal {
        let (left, right) = karras_node(keys, i);
        nodes[i].left = left;
        nodes[i].right = right;
        for c in [left, right] {
            if c & LEAF != 0 {
                leaf_parent[(c & !LEAF) as usize] = i as u32;
            } else {
                nodes[c as usize].parent = i as u32;
            }
        }
    }
    (nodes, leaf_parent)
}

/// `a < b ? a : b`, as the kernel writes it (no `fmin`: its choice between
/// −0 and +0 is the device's).
fn lesser(a: f32, b: f32) -> f32 {
    if b < a { b } else { a }
}

fn greater(a: f32, b: f32) -> f32 {
    if b > a { b } else { a }
}

/// The box of a triangle.
pub fn triangle_box(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> BvhBox {
    let mut bx = BvhBox::default();
    for k in 0..3 {
        bx.lo[k] = lesser(lesser(a[k], b[k]), c[k]);
        bx.hi[k] = greater(greater(a[k], b[k]), c[k]);
    }
    bx
}

/// The union of two boxes.
pub fn union(a: &BvhBox, b: &BvhBox) -> BvhBox {
    let mut u = BvhBox::default();
    for k in 0..3 {
        u.lo[k] = lesser(a.lo[k], b.lo[k]);
        u.hi[k] = greater(a.hi[k], b.hi[k]);
    }
    u
}

impl Tree {
    /// Morton codes, sort, build and refit over the first pose.
    pub fn new(what: &str, positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Result<Tree> {
        check_faces(what, positions.len(), faces)?;
        check_positions(what, positions.len(), positions)?;
        let codes = morton(positions, faces, &MortonFrame::of(positions));
        let (keys, faces_sorted) = sort(&codes);
        let (nodes, leaf_parent) = build(&keys);
        let mut t = Tree {
            keys,
            faces_sorted,
            nodes,
            leaf_parent,
            ..Tree::default()
        };
        t.refit(positions, faces);
        Ok(t)
    }

    /// Step `refit`: leaf boxes from the triangles at `positions`, then each
    /// leaf climbs, and the second child to reach a node computes its box.
    pub fn refit(&mut self, positions: &[[f32; 3]], faces: &[[u32; 3]]) {
        let p = |v: u32| positions[v as usize];
        self.leaf_boxes = (self.faces_sorted.iter())
            .map(|&f| {
                let f = faces[f as usize];
                triangle_box(p(f[0]), p(f[1]), p(f[2]))
            })
            .collect();
        self.node_boxes = vec![BvhBox::default(); self.nodes.len()];
        self.child_boxes = vec![BvhBox::default(); 2 * self.nodes.len()];
        let mut visits = vec![0u32; self.nodes.len()];
        for leaf in 0..self.leaf_boxes.len() {
            let mut node = self.leaf_parent[leaf];
            while node != NONE {
                visits[node as usize] += 1;
                if visits[node as usize] == 1 {
                    break;
                }
                let n = self.nodes[node as usize];
                let (l, r) = (self.child_box(n.left), self.child_box(n.right));
                self.node_boxes[node as usize] = union(&l, &r);
                self.child_boxes[2 * node as usize] = padded(&l);
                self.child_boxes[2 * node as usize + 1] = padded(&r);
                node = n.parent;
            }
        }
    }

    /// The box of a child reference.
    pub fn child_box(&self, c: u32) -> BvhBox {
        if c & LEAF != 0 {
            self.leaf_boxes[(c & !LEAF) as usize]
        } else {
            self.node_boxes[c as usize]
        }
    }

    /// The root reference (`None` for an empty tree).
    pub fn root(&self) -> Option<u32> {
        match self.faces_sorted.len() {
            0 => None,
            1 => Some(LEAF),
            _ => Some(0),
        }
    }

    /// Step `occluded` for one query: [`VISIBLE`], [`OCCLUDED`] or
    /// [`OVERFLOW`] (the stack of [`STACK_DEPTH`] entries was full).
    pub fn occluded(&self, positions: &[[f32; 3]], faces: &[[u32; 3]], q: &BvhQuery) -> u32 {
        self.occluded_with_stack(positions, faces, q, STACK_DEPTH)
    }

    /// [`Tree::occluded`] with a stack of `depth` entries (at most
    /// [`STACK_DEPTH`], at least 1), as the kernel built with
    /// `-DBVH_STACK=depth`.
    pub fn occluded_with_stack(
        &self,
        positions: &[[f32; 3]],
        faces: &[[u32; 3]],
        q: &BvhQuery,
        depth: usize,
    ) -> u32 {
        let depth = depth.clamp(1, STACK_DEPTH);
        let Some(root) = self.root() else {
            return VISIBLE;
        };
        let o = [q.origin[0], q.origin[1], q.origin[2]];
        let t = [q.target[0], q.target[1], q.target[2]];
        let d = [t[0] - o[0], t[1] - o[1], t[2] - o[2]];
        let inv = inverse(d);
        let mut stack = [0u32; STACK_DEPTH];
        let mut sp = 0usize;
        if box_hit_inv(&self.child_box(root), o, d, inv) {
            stack[0] = root;
            sp = 1;
        }
        while sp > 0 {
            sp -= 1;
            let r = stack[sp];
            if r & LEAF != 0 {
                let face = self.faces_sorted[(r & !LEAF) as usize];
                if q.exclude.contains(&face) {
                    continue;
                }
                let f = faces[face as usize];
                let p = |k: usize| positions[f[k] as usize];
                if segment_hits_f32(o, d, p(0), p(1), p(2)) {
                    return OCCLUDED;
                }
                continue;
            }
            let n = self.nodes[r as usize];
            for (k, c) in [n.left, n.right].into_iter().enumerate() {
                if padded_hit(&self.child_boxes[2 * r as usize + k], o, d, inv) {
                    if sp == depth {
                        return OVERFLOW;
                    }
                    stack[sp] = c;
                    sp += 1;
                }
            }
        }
        VISIBLE
    }
}

/// The traversal's slab test of the segment `o + t·d`, t ∈ [0, 1], against
/// a box padded by [`BOX_PAD`] of its largest extent (+1e-30).
pub fn box_hit(b: &BvhBox, o: [f32; 3], d: [f32; 3]) -> bool {
    box_hit_inv(b, o, d, inverse(d))
}

/// The reciprocals of `d`'s components (0 for a zero component, which the
/// slab test does not divide by), computed once per query.
pub fn inverse(d: [f32; 3]) -> [f32; 3] {
    d.map(|c| if c != 0.0 { 1.0 / c } else { 0.0 })
}

/// [`box_hit`] with `d`'s reciprocals ([`inverse`]) given, as the kernel
/// computes them once per query.
pub fn box_hit_inv(b: &BvhBox, o: [f32; 3], d: [f32; 3], inv: [f32; 3]) -> bool {
    padded_hit(&padded(b), o, d, inv)
}

/// A box padded by [`BOX_PAD`] of its largest extent (+1e-30), as the
/// traversal tests it (the kernels' `bvh_padded`).
pub fn padded(b: &BvhBox) -> BvhBox {
    let ext = greater(
        greater(b.hi[0] - b.lo[0], b.hi[1] - b.lo[1]),
        b.hi[2] - b.lo[2],
    );
    let pad = BOX_PAD * ext + 1e-30;
    let mut p = BvhBox::default();
    for k in 0..3 {
        (p.lo[k], p.hi[k]) = (b.lo[k] - pad, b.hi[k] + pad);
    }
    p
}

/// The slab test of [`box_hit_inv`] against a box padded already
/// ([`padded`]).
pub fn padded_hit(b: &BvhBox, o: [f32; 3], d: [f32; 3], inv: [f32; 3]) -> bool {
    let (mut tmin, mut tmax) = (0.0f32, 1.0f32);
    for k in 0..3 {
        let (lo, hi) = (b.lo[k], b.hi[k]);
        if d[k] == 0.0 {
            if o[k] < lo || o[k] > hi {
                return false;
            }
            continue;
        }
        let mut t1 = (lo - o[k]) * inv[k];
        let mut t2 = (hi - o[k]) * inv[k];
        if t1 > t2 {
            std::mem::swap(&mut t1, &mut t2);
        }
        tmin = greater(tmin, t1);
        tmax = lesser(tmax, t2);
        if tmin > tmax {
            return false;
        }
    }
    true
}

/// The segment–triangle test in f32 (the kernel's `bvh_segment_hits`,
/// operation for operation). See [`segment_hits_f64`].
pub fn segment_hits_f32(o: [f32; 3], d: [f32; 3], a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> bool {
    let sub = |x: [f32; 3], y: [f32; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let cross = |x: [f32; 3], y: [f32; 3]| {
        [
            x[1] * y[2] - x[2] * y[1],
            x[2] * y[0] - x[0] * y[2],
            x[0] * y[1] - x[1] * y[0],
        ]
    };
    let dotp = |x: [f32; 3], y: [f32; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let (e1, e2) = (sub(b, a), sub(c, a));
    let p = cross(d, e2);
    let mut det = dotp(e1, p);
    let s = sub(o, a);
    let mut u = dotp(s, p);
    let q = cross(s, e1);
    let mut v = dotp(d, q);
    let mut t = dotp(e2, q);
    if det < 0.0 {
        (det, u, v, t) = (-det, -u, -v, -t);
    }
    if det.is_nan() || det <= 0.0 {
        return false;
    }
    let slack = EDGE_EPS * det;
    let trim = END_EPS * det;
    u >= -slack && v >= -slack && u + v <= det + slack && t > trim && t < det - trim
}

/// The segment–triangle test in f64: with `det = e1 · (d × e2)` and the
/// barycentric `u`, `v` and segment parameter `t` all scaled by `|det|`, a
/// hit is `u, v ≥ −ε_e·det`, `u + v ≤ (1 + ε_e)·det` and
/// `ε_t·det < t < (1 − ε_t)·det` (ε_e = [`EDGE_EPS`], ε_t = [`END_EPS`]):
/// triangles grown slightly (no leak between neighbours), segment ends
/// trimmed (no self-occlusion at the endpoints); a segment parallel to the
/// triangle's plane (det = 0) never hits.
pub fn segment_hits_f64(o: [f64; 3], d: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    let m = segment_measures(o, d, a, b, c);
    let Some((det, u, v, t)) = m else {
        return false;
    };
    let slack = EDGE_EPS as f64 * det;
    let trim = END_EPS as f64 * det;
    u >= -slack && v >= -slack && u + v <= det + slack && t > trim && t < det - trim
}

/// `(det, u, v, t)` of the f64 test with `det > 0` (signs flipped so), or
/// `None` when the segment is parallel to the plane.
pub fn segment_measures(
    o: [f64; 3],
    d: [f64; 3],
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
) -> Option<(f64, f64, f64, f64)> {
    let sub = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let cross = |x: [f64; 3], y: [f64; 3]| {
        [
            x[1] * y[2] - x[2] * y[1],
            x[2] * y[0] - x[0] * y[2],
            x[0] * y[1] - x[1] * y[0],
        ]
    };
    let dotp = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let (e1, e2) = (sub(b, a), sub(c, a));
    let p = cross(d, e2);
    let det = dotp(e1, p);
    let s = sub(o, a);
    let q = cross(s, e1);
    let (u, v, t) = (dotp(s, p), dotp(d, q), dotp(e2, q));
    let sign = if det < 0.0 { -1.0 } else { 1.0 };
    (det != 0.0).then_some((det * sign, u * sign, v * sign, t * sign))
}

/// Brute force in f64: whether any face but the `exclude`d ones is crossed
/// by the open segment from `origin` to `target` ([`segment_hits_f64`]).
pub fn occluded_brute(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    origin: [f64; 3],
    target: [f64; 3],
    exclude: &[u32],
) -> bool {
    let d = [
        target[0] - origin[0],
        target[1] - origin[1],
        target[2] - origin[2],
    ];
    faces.iter().enumerate().any(|(i, f)| {
        let p = |k: usize| positions[f[k] as usize];
        !exclude.contains(&(i as u32)) && segment_hits_f64(origin, d, p(0), p(1), p(2))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn karras_tree_is_a_tree_over_duplicates() {
        for keys in [
            vec![0u32, 1, 2, 3, 4],
            vec![7; 9],
            vec![1, 1, 2, 2, 2, 9],
            vec![5, 6],
        ] {
            let (nodes, leaf_parent) = build(&keys);
            assert_eq!(nodes[0].parent, NONE);
            let mut seen = vec![0; nodes.len() + keys.len()];
            for (i, n) in nodes.iter().enumerate() {
                for c in [n.left, n.right] {
                    let slot = if c & LEAF != 0 {
                        assert_eq!(leaf_parent[(c & !LEAF) as usize], i as u32);
                        nodes.len() + (c & !LEAF) as usize
                    } else {
                        assert_eq!(nodes[c as usize].parent, i as u32);
                        c as usize
                    };
                    seen[slot] += 1;
                }
            }
            assert_eq!(seen[0], 0, "the root is nobody's child");
            assert!(seen[1..].iter().all(|&s| s == 1), "{keys:?}: {seen:?}");
        }
    }

    #[test]
    fn segment_test_hits_the_middle_and_trims_the_ends() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let pos = [a, b, c];
        let faces = [[0, 1, 2]];
        assert!(occluded_brute(
            &pos,
            &faces,
            [0.2, 0.2, -1.0],
            [0.2, 0.2, 1.0],
            &[]
        ));
        assert!(!occluded_brute(
            &pos,
            &faces,
            [0.2, 0.2, -1.0],
            [0.2, 0.2, 1.0],
            &[0]
        ));
        assert!(!occluded_brute(
            &pos,
            &faces,
            [0.2, 0.2, 0.0],
            [0.2, 0.2, 1.0],
            &[]
        ));
        assert!(!occluded_brute(
            &pos,
            &faces,
            [0.9, 0.9, -1.0],
            [0.9, 0.9, 1.0],
            &[]
        ));
        assert!(!occluded_brute(
            &pos,
            &faces,
            [0.0, 0.2, 0.0],
            [1.0, 0.2, 0.0],
            &[]
        ));
        let pf: Vec<[f32; 3]> = pos.iter().map(|p| p.map(|c| c as f32)).collect();
        let tree = Tree::new("one triangle", &pf, &faces).unwrap();
        let q = BvhQuery::new([0.2, 0.2, -1.0], [0.2, 0.2, 1.0], &[]);
        assert_eq!(tree.occluded(&pf, &faces, &q), OCCLUDED);
        assert!(Tree::new("bad", &pf, &[[0, 1, 3]]).is_err());
    }
}
