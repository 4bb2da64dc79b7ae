//! Where a line's ends lie on the mesh, as its face and the barycentric
//! coordinates of each end in that face: the provenance dataset builders
//! keep beside 3-D lines (a line's point is then `Σ wᵢ pᵢ` of the face's
//! corners in any pose of the mesh).

/// The barycentric coordinates of `p` projected onto the plane of the
/// triangle `t` (least squares in f64; they sum to 1). A triangle with no
/// area gives the weights of its nearest corner.
pub fn barycentric(p: [f64; 3], t: [[f64; 3]; 3]) -> [f64; 3] {
    let g = Gram::of(t);
    // No area, or a NaN: the nearest corner.
    if !g.has_area() {
        let dist = |q: [f64; 3]| dot(sub(p, q), sub(p, q));
        let k = (0..3)
            .min_by(|&i, &j| dist(t[i]).total_cmp(&dist(t[j])))
            .unwrap_or(0);
        let mut w = [0.0; 3];
        w[k] = 1.0;
        return w;
    }
    let d = sub(p, t[0]);
    let (r1, r2) = (dot(d, g.e1), dot(d, g.e2));
    let u = (g.c * r1 - g.b * r2) / g.det;
    let v = (g.a * r2 - g.b * r1) / g.det;
    [1.0 - u - v, u, v]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| a[i] - b[i])
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A triangle's edges from its first corner and their Gram matrix
/// `[[a, b], [b, c]]` with its determinant: what the barycentric solve
/// and the test for an area both read.
struct Gram {
    e1: [f64; 3],
    e2: [f64; 3],
    a: f64,
    b: f64,
    c: f64,
    det: f64,
}

impl Gram {
    fn of(t: [[f64; 3]; 3]) -> Gram {
        let (e1, e2) = (sub(t[1], t[0]), sub(t[2], t[0]));
        let (a, b, c) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
        Gram {
            e1,
            e2,
            a,
            b,
            c,
            det: a * c - b * b,
        }
    }

    /// Whether the triangle has an area [`barycentric`] can place points
    /// in (not a repeated corner, not three corners on a line, no NaN).
    fn has_area(&self) -> bool {
        let m = self.a.max(self.c);
        self.det.partial_cmp(&(1e-24 * m * m)) == Some(std::cmp::Ordering::Greater)
    }
}

/// Of `candidates` (face indices into `faces`), the face both `a` and `b`
/// lie in best (a face with area before one without, whose weights would
/// only name its nearest corner; then the least negative barycentric weight
/// over both ends), with each end's coordinates in it; `None` when there
/// is no candidate.
pub fn face_of_segment(
    (a, b): ([f64; 3], [f64; 3]),
    candidates: &[u32],
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
) -> Option<(u32, [[f64; 3]; 2])> {
    let corners = |f: u32| faces[f as usize].map(|v| positions[v as usize]);
    let score = |f: u32| -> (bool, f64, [[f64; 3]; 2]) {
        let t = corners(f);
        let w = [barycentric(a, t), barycentric(b, t)];
        let worst = w.iter().flatten().fold(0.0f64, |m, &x| m.min(x));
        (Gram::of(t).has_area(), worst, w)
    };
    candidates
        .iter()
        .filter(|&&f| (f as usize) < faces.len())
        .map(|&f| (f, score(f)))
        .max_by(|x, y| x.1.0.cmp(&y.1.0).then(x.1.1.total_cmp(&y.1.1)))
        .map(|(f, (_, _, w))| (f, w))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_weights_rebuild_the_point_and_pick_the_face_holding_both_ends() {
        let t = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let w = barycentric([0.5, 0.5, 0.3], t);
        assert!((w[0] - 0.5).abs() < 1e-12 && (w[1] - 0.25).abs() < 1e-12);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        // No area: the nearest corner.
        let flat = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert_eq!(barycentric([1.9, 0.1, 0.0], flat), [0.0, 0.0, 1.0]);
        // Two faces share the edge (1, 2); a segment from that edge into
        // face 1 belongs to face 1.
        let pos = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        let faces = [[0, 1, 2], [1, 3, 2]];
        let seg = ([0.5, 0.5, 0.0], [0.9, 0.8, 0.0]);
        let (f, w) = face_of_segment(seg, &[0, 1], &pos, &faces).unwrap();
        assert_eq!(f, 1);
        assert!(w.iter().flatten().all(|x| *x > -1e-12));
        assert!(face_of_segment(seg, &[], &pos, &faces).is_none());
    }
}
