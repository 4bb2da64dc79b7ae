//! The flicker measure of `shapecue report coherence`: line segments of
//! consecutive frames, mapped to the rest pose (by each piece's face and
//! barycentric coordinates), compared where the surface is.
//!
//! - The **pop share** between two frames: the share of their line length
//!   farther than τ from the other frame's lines of the same family, both
//!   directions together; over a sequence, the far length of every pair of
//!   consecutive frames over their total length.
//! - The **short-lived share**: the share of line length that persists
//!   (within τ, frame to frame) for fewer than 3 frames, over the frames
//!   whose two neighbours on each side exist (a life of 3 is decided
//!   there).
//!
//! Lengths are measured by samples: each segment is cut into pieces of at
//! most τ/2, each piece's midpoint standing for its length. A sample is
//! near a frame's lines when some segment of that family lies within τ
//! (exactly: point to segment), found through a hash grid of cell 1.25 τ
//! holding each segment at points τ/2 apart, so that any segment within τ
//! has such a point in the sample's cell or a neighbouring one.

use glam::DVec3;
use std::collections::HashMap;

/// One line segment of a frame, in rest-pose coordinates, with its family
/// code.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestSeg {
    /// Family code ([`crate::spec::feature_lines::LineFamily`] as `u32`).
    pub family: u32,
    /// First end.
    pub a: DVec3,
    /// Second end.
    pub b: DVec3,
    /// Its chain's id across frames (`u32::MAX`: none).
    pub chain_id: u32,
}

/// The flicker of one family over a sequence of frames.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Flicker {
    /// The pop share over every pair of consecutive frames (NaN: no line).
    pub pop: f64,
    /// The pop share of each pair of consecutive frames (NaN: no line).
    pub pop_per_pair: Vec<f64>,
    /// The short-lived share (NaN: no line, or fewer than 5 frames).
    pub short_lived: f64,
    /// The mean line length per frame.
    pub mean_length: f64,
}

/// The segments of one family in one frame, with the grid that finds
/// those near a point.
struct Indexed<'a> {
    segs: Vec<&'a RestSeg>,
    grid: HashMap<[i64; 3], Vec<u32>>,
    cell: f64,
}

impl<'a> Indexed<'a> {
    fn new(frame: &'a [RestSeg], family: u32, tau: f64) -> Indexed<'a> {
        let cell = 1.25 * tau;
        let segs: Vec<&RestSeg> = frame.iter().filter(|s| s.family == family).collect();
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (i, s) in segs.iter().enumerate() {
            let n = pieces(s, tau);
            let mut last = None;
            for k in 0..=n {
                let p = s.a.lerp(s.b, k as f64 / n as f64);
                let c = cell_of(p, cell);
                if last != Some(c) {
                    let v = grid.entry(c).or_default();
                    if v.last() != Some(&(i as u32)) {
                        v.push(i as u32);
                    }
                    last = Some(c);
                }
            }
        }
        Indexed { segs, grid, cell }
    }

    /// Whether a segment lies within `tau` of `p`.
    fn near(&self, p: DVec3, tau: f64) -> bool {
        let c = cell_of(p, self.cell);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(v) = self.grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    if v.iter()
                        .any(|&i| point_segment(p, self.segs[i as usize]) <= tau)
                    {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// The samples of these segments: (midpoint, length) of pieces at most
    /// τ/2 long.
    fn samples(&self, tau: f64) -> Vec<(DVec3, f64)> {
        let mut out = Vec::new();
        for s in &self.segs {
            let n = pieces(s, tau);
            let len = (s.b - s.a).length() / n as f64;
            for k in 0..n {
                out.push((s.a.lerp(s.b, (k as f64 + 0.5) / n as f64), len));
            }
        }
        out
    }
}

/// Pieces of at most τ/2 along `s` (at least one).
fn pieces(s: &RestSeg, tau: f64) -> usize {
    let len = (s.b - s.a).length();
    ((len / (0.5 * tau)).ceil() as usize).clamp(1, 1 << 20)
}

fn cell_of(p: DVec3, cell: f64) -> [i64; 3] {
    let c = (p / cell).floor();
    [c.x as i64, c.y as i64, c.z as i64]
}

/// The distance from `p` to the segment `s`.
fn point_segment(p: DVec3, s: &RestSeg) -> f64 {
    let d = s.b - s.a;
    let l2 = d.length_squared();
    let t = if l2 > 0.0 {
        ((p - s.a).dot(d) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (s.a + t * d - p).length()
}

/// The flicker of `family` over `frames` (each frame's segments, rest-pose
/// coordinates) at distance `tau`.
pub fn flicker(frames: &[Vec<RestSeg>], family: u32, tau: f64) -> Flicker {
    let idx: Vec<Indexed> = frames
        .iter()
        .map(|f| Indexed::new(f, family, tau))
        .collect();
    let samples: Vec<Vec<(DVec3, f64)>> = idx.iter().map(|i| i.samples(tau)).collect();
    let total = |k: usize| samples[k].iter().map(|s| s.1).sum::<f64>();
    let far = |k: usize, other: usize| -> f64 {
        (samples[k].iter())
            .filter(|s| !idx[other].near(s.0, tau))
            .map(|s| s.1)
            .sum()
    };
    let n = frames.len();
    let (mut far_all, mut tot_all) = (0.0, 0.0);
    let mut pop_per_pair = Vec::new();
    for k in 0..n.saturating_sub(1) {
        let f = far(k, k + 1) + far(k + 1, k);
        let t = total(k) + total(k + 1);
        far_all += f;
        tot_all += t;
        pop_per_pair.push(if t > 0.0 { f / t } else { f64::NAN });
    }
    let (mut short, mut tot_short) = (0.0, 0.0);
    for (k, frame) in samples.iter().enumerate().take(n.saturating_sub(2)).skip(2) {
        for &(p, w) in frame {
            let run = |js: [usize; 2]| js.iter().take_while(|&&j| idx[j].near(p, tau)).count();
            if run([k - 1, k - 2]) + run([k + 1, k + 2]) < 2 {
                short += w;
            }
            tot_short += w;
        }
    }
    let share = |a: f64, b: f64| if b > 0.0 { a / b } else { f64::NAN };
    Flicker {
        pop: share(far_all, tot_all),
        pop_per_pair,
        short_lived: share(short, tot_short),
        mean_length: (0..n).map(total).sum::<f64>() / n.max(1) as f64,
    }
}

/// The share of `family`'s line length, over every frame but the last,
/// whose chain id the next frame also has (NaN: no line with an id).
pub fn chain_ids_kept(frames: &[Vec<RestSeg>], family: u32) -> f64 {
    let (mut kept, mut total) = (0.0, 0.0);
    for w in frames.windows(2) {
        let next: std::collections::HashSet<u32> = (w[1].iter())
            .filter(|s| s.family == family && s.chain_id != u32::MAX)
            .map(|s| s.chain_id)
            .collect();
        for s in w[0]
            .iter()
            .filter(|s| s.family == family && s.chain_id != u32::MAX)
        {
            let len = (s.b - s.a).length();
            total += len;
            if next.contains(&s.chain_id) {
                kept += len;
            }
        }
    }
    if total > 0.0 { kept / total } else { f64::NAN }
}

/// The rigid motion (rotation, translation) that best maps `rest` onto
/// `posed` in least squares (Kabsch's problem, solved by Horn's unit
/// quaternion: the eigenvector of the largest eigenvalue of a symmetric
/// 4×4 matrix, by Jacobi rotations). `None` for fewer than 3 points.
pub fn best_rigid(rest: &[DVec3], posed: &[DVec3]) -> Option<(glam::DMat3, DVec3)> {
    if rest.len() < 3 || rest.len() != posed.len() {
        return None;
    }
    let n = rest.len() as f64;
    let cr = rest.iter().copied().sum::<DVec3>() / n;
    let cp = posed.iter().copied().sum::<DVec3>() / n;
    // s[a][b] = Σ (r − cr)_a (p − cp)_b.
    let mut s = [[0.0f64; 3]; 3];
    for (r, p) in rest.iter().zip(posed) {
        let (r, p) = ((*r - cr).to_array(), (*p - cp).to_array());
        for a in 0..3 {
            for b in 0..3 {
                s[a][b] += r[a] * p[b];
            }
        }
    }
    let [[xx, xy, xz], [yx, yy, yz], [zx, zy, zz]] = s;
    let m = [
        [xx + yy + zz, yz - zy, zx - xz, xy - yx],
        [yz - zy, xx - yy - zz, xy + yx, zx + xz],
        [zx - xz, xy + yx, -xx + yy - zz, yz + zy],
        [xy - yx, zx + xz, yz + zy, -xx - yy + zz],
    ];
    let (vals, vecs) = jacobi4(m);
    let best = (0..4).max_by(|&a, &b| vals[a].total_cmp(&vals[b]))?;
    let q = glam::DQuat::from_xyzw(vecs[1][best], vecs[2][best], vecs[3][best], vecs[0][best]);
    if !q.is_finite() || q.length() == 0.0 {
        return None;
    }
    let r = glam::DMat3::from_quat(q.normalize());
    Some((r, cp - r * cr))
}

/// Eigenvalues and eigenvectors (columns) of a symmetric 4×4 matrix, by
/// cyclic Jacobi rotations.
fn jacobi4(mut a: [[f64; 4]; 4]) -> ([f64; 4], [[f64; 4]; 4]) {
    let mut v = [[0.0; 4]; 4];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _ in 0..50 {
        let off: f64 = (0..4)
            .flat_map(|i| (0..4).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        if off < 1e-30 {
            break;
        }
        for p in 0..3 {
            for q in p + 1..4 {
                if a[p][q].abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (rp, rq) = (a[p], a[q]);
                a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
                a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
                for row in &mut v {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2], a[3][3]], v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(family: u32, a: [f64; 3], b: [f64; 3]) -> RestSeg {
        RestSeg {
            family,
            a: DVec3::from(a),
            b: DVec3::from(b),
            chain_id: 0,
        }
    }

    #[test]
    fn chain_ids_kept_is_the_length_whose_id_the_next_frame_has() {
        let mut a = seg(2, [0.0; 3], [3.0, 0.0, 0.0]);
        let mut b = seg(2, [0.0; 3], [1.0, 0.0, 0.0]);
        b.chain_id = 7;
        let frames = vec![vec![a, b], vec![a]];
        assert!((chain_ids_kept(&frames, 2) - 0.75).abs() < 1e-12);
        a.chain_id = u32::MAX;
        assert!(chain_ids_kept(&[vec![a], vec![a]], 2).is_nan());
    }

    #[test]
    fn identical_frames_do_not_flicker_and_a_blink_is_short_lived() {
        let line = seg(2, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let still: Vec<Vec<RestSeg>> = vec![vec![line]; 7];
        let f = flicker(&still, 2, 0.01);
        assert_eq!((f.pop, f.short_lived), (0.0, 0.0));
        assert!((f.mean_length - 1.0).abs() < 1e-12);
        // Another family is absent: NaN, not 0.
        assert!(flicker(&still, 3, 0.01).pop.is_nan());
        // A second line of length 1 that shows in frame 3 only: it pops in
        // and out (pairs 2–3 and 3–4) and lives one frame.
        let mut blink = still.clone();
        blink[3].push(seg(2, [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]));
        let f = flicker(&blink, 2, 0.01);
        assert!((f.pop_per_pair[2] - 1.0 / 3.0).abs() < 1e-9, "{f:?}");
        assert!((f.pop_per_pair[3] - 1.0 / 3.0).abs() < 1e-9, "{f:?}");
        assert_eq!(f.pop_per_pair[0], 0.0);
        // Frames 2..=4 are judged: 1 of their 4 length units is short-lived.
        assert!((f.short_lived - 0.25).abs() < 1e-9, "{f:?}");
        // A line that moves by less than τ each frame does not pop.
        let drift: Vec<Vec<RestSeg>> = (0..7)
            .map(|k| {
                let y = 0.004 * k as f64;
                vec![seg(2, [0.0, y, 0.0], [1.0, y, 0.0])]
            })
            .collect();
        let f = flicker(&drift, 2, 0.01);
        assert_eq!((f.pop, f.short_lived), (0.0, 0.0));
        // One that jumps by 2τ every frame pops entirely.
        let jump: Vec<Vec<RestSeg>> = (0..7)
            .map(|k| {
                let y = 0.02 * k as f64;
                vec![seg(2, [0.0, y, 0.0], [1.0, y, 0.0])]
            })
            .collect();
        let f = flicker(&jump, 2, 0.01);
        assert_eq!((f.pop, f.short_lived), (1.0, 1.0));
    }

    #[test]
    fn the_best_rigid_motion_undoes_a_rotation_and_translation() {
        let rest: Vec<DVec3> = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [0.0, 0.0, 3.0],
            [1.0, 1.0, 1.0],
        ]
        .map(DVec3::from)
        .to_vec();
        let q = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 2.5);
        let t = DVec3::new(0.3, -4.0, 7.0);
        let posed: Vec<DVec3> = rest.iter().map(|p| q * *p + t).collect();
        let (r, tt) = best_rigid(&rest, &posed).unwrap();
        for (a, b) in rest.iter().zip(&posed) {
            assert!((r * *a + tt - *b).length() < 1e-9);
        }
        assert!(best_rigid(&rest[..2], &posed[..2]).is_none());
    }
}
