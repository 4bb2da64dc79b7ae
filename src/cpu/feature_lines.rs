//! CPU reference of `kernels/feature_lines.cl` (same steps, same f32
//! arithmetic order): `lines_vertex` then `lines_face`. Segments come out in
//! face order; the device's order is that of its atomic counter, so tests
//! compare canonically sorted segment lists.

use crate::spec::feature_lines::LineInputs;
use crate::spec::feature_lines::Segment;
use crate::spec::view::View;

/// Per-vertex values of `lines_vertex`: n·v, κr·sin²θ and the suggestive test.
pub struct VertexTerms {
    /// n·v.
    pub ndv: Vec<f32>,
    /// k1u² + k2v².
    pub kr: Vec<f32>,
    /// sinθ · D_w κr.
    pub sc: Vec<f32>,
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `lines_vertex`, seen from `view` (a [`crate::spec::view::View`], or the
/// eye-only [`View`]).
pub fn lines_vertex(x: &LineInputs, view: View) -> VertexTerms {
    let (eye, ortho) = (view.line_eye(), view.ortho);
    let n = x.pos.len();
    let mut t = VertexTerms {
        ndv: Vec::with_capacity(n),
        kr: Vec::with_capacity(n),
        sc: Vec::with_capacity(n),
    };
    for i in 0..n {
        let p = x.pos[i];
        let mut v = if ortho {
            eye
        } else {
            [eye[0] - p[0], eye[1] - p[1], eye[2] - p[2]]
        };
        let l = dot(v, v).sqrt();
        let s = if l > 0.0 { 1.0 / l } else { 0.0 };
        v = v.map(|c| c * s);
        let nd = dot(x.nrm[i], v);
        let (u, w) = (dot(x.d1[i], v), dot(x.d2[i], v));
        let [k1, k2] = x.k[i];
        let (u2, w2) = (u * u, w * w);
        let ww = u2 + w2;
        let c = x.dk[i];
        let cwww = u2 * (u * c[0] + 3.0 * w * c[1]) + w2 * (3.0 * u * c[2] + w * c[3]);
        let inv = if ww > 1e-12 { 1.0 / ww } else { 0.0 };
        let tr = (k2 - k1) * u * w * inv;
        t.ndv.push(nd);
        t.kr.push(k1 * u2 + k2 * w2);
        t.sc.push(if ww > 1e-12 {
            cwww * inv - 2.0 * nd * tr * tr
        } else {
            0.0
        });
    }
    t
}

fn cross_t(fa: f32, fb: f32) -> f32 {
    let d = fa - fb;
    let t = if d != 0.0 { fa / d } else { 0.5 };
    t.clamp(0.0, 1.0)
}

/// `lines_face`: segments of the requested kinds.
pub fn lines_face(
    faces: &[[u32; 3]],
    pos: &[[f32; 3]],
    t: &VertexTerms,
    want: [bool; 2],
    sc_thresh: f32,
    fade: f32,
) -> Vec<Segment> {
    let mut out = Vec::new();
    for f in faces {
        let v = f.map(|i| i as usize);
        for kind in 0..2u32 {
            if !want[kind as usize] {
                continue;
            }
            let fv = v.map(|i| if kind == 0 { t.ndv[i] } else { t.kr[i] });
            let s = fv.map(|x| x >= 0.0);
            if s[0] == s[1] && s[1] == s[2] {
                continue;
            }
            let c = if s[0] == s[1] {
                2
            } else if s[0] == s[2] {
                1
            } else {
                0
            };
            let (a, b) = ((c + 1) % 3, (c + 2) % 3);
            let (ta, tb) = (cross_t(fv[c], fv[a]), cross_t(fv[c], fv[b]));
            let lerp = |t: f32, p: usize| -> [f32; 3] {
                let pc = pos[v[c]];
                std::array::from_fn(|i| pc[i] + t * (pos[v[p]][i] - pc[i]))
            };
            let mut strength = 1.0;
            if kind == 1 {
                let li = |arr: &[f32], t: f32, p: usize| arr[v[c]] + t * (arr[v[p]] - arr[v[c]]);
                let nd = 0.5 * (li(&t.ndv, ta, a) + li(&t.ndv, tb, b));
                let num = 0.5 * (li(&t.sc, ta, a) + li(&t.sc, tb, b));
                if nd.is_nan() || nd <= 0.0 || num.is_nan() || num <= sc_thresh * nd {
                    continue;
                }
                strength = if fade > 0.0 {
                    (nd / fade).min(1.0)
                } else {
                    1.0
                };
            }
            let edge = |p: usize| [v[c].min(v[p]) as u32, v[c].max(v[p]) as u32];
            out.push((lerp(ta, a), lerp(tb, b), kind, strength, [edge(a), edge(b)]));
        }
    }
    out
}
