//! CPU reference of `kernels/feature_lines.cl` (same steps, same f32
//! arithmetic order): `lines_vertex` then `lines_face`. Segments come out in
//! face order; the device's order is that of its atomic counter, so tests
//! compare canonically sorted segment lists.

use crate::spec::feature_lines::LineInputs;
use crate::spec::feature_lines::{LINE_FREE, Segment};
use crate::spec::view::View;

/// Per-vertex values of `lines_vertex`: n·v, κr·sin²θ and the suggestive test.
pub struct VertexTerms {
    /// n·v.
    pub ndv: Vec<f32>,
    /// k1u² + k2v².
    pub kr: Vec<f32>,
    /// sinθ · D_w κr.
    pub sc: Vec<f32>,
    /// The gradient of κr sin²θ ([`grad_kr`]; the device writes it only for
    /// Hermite placement).
    pub gkr: Vec<[f32; 3]>,
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
        gkr: Vec::with_capacity(n),
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
        let rlen = if ortho || l <= 0.0 { 0.0 } else { 1.0 / l };
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
        t.gkr
            .push(grad_kr(x.d1[i], x.d2[i], nd, u, w, k1, k2, c, rlen));
    }
    t
}

/// The cubic Hermite crossing on an edge (rtsc's bisection).
pub fn zero_hermite(fa: f32, fb: f32, da: f32, db: f32) -> f32 {
    if fa == fb {
        return 0.5;
    }
    let a = 2.0 * (fa - fb) + da + db;
    let b = 3.0 * (fb - fa) - 2.0 * da - db;
    let (c, d) = (da, fa);
    let (mut sl, mut sr, mut vl) = (0.0f32, 1.0f32, fa);
    let disc = 4.0 * b * b - 12.0 * a * c;
    if disc > 0.0 && a != 0.0 {
        let q = disc.sqrt();
        let (r1, r2) = ((-2.0 * b + q) / (6.0 * a), (-2.0 * b - q) / (6.0 * a));
        if (0.0..=1.0).contains(&r1) && (0.0..=1.0).contains(&r2) {
            let v1 = ((a * r1 + b) * r1 + c) * r1 + d;
            let v2 = ((a * r2 + b) * r2 + c) * r2 + d;
            if (v1 < 0.0 && v2 >= 0.0) || (v1 > 0.0 && v2 <= 0.0) {
                sl = r1.min(r2);
                sr = r1.max(r2);
                vl = if r1 < r2 { v1 } else { v2 };
            }
        }
    }
    for _ in 0..10 {
        let m = 0.5 * (sl + sr);
        let vm = ((a * m + b) * m + c) * m + d;
        if (vl < 0.0 && vm >= 0.0) || (vl > 0.0 && vm <= 0.0) {
            sr = m;
        } else {
            sl = m;
            vl = vm;
        }
    }
    0.5 * (sl + sr)
}

/// `grad_kr` of kernels/common/isoline.h: the gradient of κr sin²θ (rtsc's
/// `gradkr`), for the Hermite placement of suggestive contours and
/// highlights; `uu`, `ww` the view vector's components along e1, e2, `c`
/// n·v, `rlen` 1 / distance to the eye (0 orthographic).
// Mirrors grad_kr of kernels/common/isoline.h argument for argument.
#[allow(clippy::too_many_arguments)]
pub fn grad_kr(
    e1: [f32; 3],
    e2: [f32; 3],
    c: f32,
    uu: f32,
    ww: f32,
    k1: f32,
    k2: f32,
    cc: [f32; 4],
    rlen: f32,
) -> [f32; 3] {
    let s2 = uu * uu + ww * ww;
    if s2.is_nan() || s2 <= 1e-12 {
        return [0.0; 3];
    }
    let s = s2.sqrt();
    let csc = 1.0 / s;
    let (u, v) = (uu * csc, ww * csc);
    let krn = k1 * u * u + k2 * v * v;
    let tr = u * v * (k2 - k1);
    let kt = k1 * (1.0 - u * u) + k2 * (1.0 - v * v);
    let w: [f32; 3] = std::array::from_fn(|i| u * e1[i] + v * e2[i]);
    let wp: [f32; 3] = std::array::from_fn(|i| u * e2[i] - v * e1[i]);
    let a1 = u * u * cc[0] + 2.0 * u * v * cc[1] + v * v * cc[2];
    let a2 = u * u * cc[1] + 2.0 * u * v * cc[2] + v * v * cc[3];
    let f1 = 2.0 * csc * tr;
    let f2 = 2.0 * krn * s * c;
    std::array::from_fn(|i| {
        let mut g = a1 * e1[i] + a2 * e2[i];
        g -= f1 * (rlen * wp[i] + c * (tr * w[i] + kt * wp[i]));
        g *= s2;
        g - f2 * (krn * w[i] + tr * wp[i])
    })
}

fn cross_t(fa: f32, fb: f32) -> f32 {
    let d = fa - fb;
    let t = if d != 0.0 { fa / d } else { 0.5 };
    t.clamp(0.0, 1.0)
}

/// `test_pieces` of kernels/common/isoline.h: the parameters (in [0, 1]
/// along a segment) of its pieces where num and den have one sign (num ≥ 0
/// and den ≥ 0, or both < 0), num and den linear between their end values.
pub fn test_pieces(n0: f32, n1: f32, d0: f32, d1: f32) -> Vec<[f32; 2]> {
    let mut z = Vec::with_capacity(2);
    if (n0 >= 0.0) != (n1 >= 0.0) {
        z.push(n0 / (n0 - n1));
    }
    if (d0 >= 0.0) != (d1 >= 0.0) {
        let x = d0 / (d0 - d1);
        if z.first().is_some_and(|&z0| x < z0) {
            z.insert(0, x);
        } else {
            z.push(x);
        }
    }
    let mut valid = (n0 >= 0.0) == (d0 >= 0.0);
    let mut s = 0.0f32;
    let mut out = Vec::with_capacity(2);
    for e in z.into_iter().chain([1.0]) {
        if valid && e > s {
            out.push([s, e]);
        }
        s = e;
        valid = !valid;
    }
    out
}

/// `test_alpha` of kernels/common/isoline.h: rtsc's fade num / (den·fade +
/// num) (r / (r + fade) for r = num / den), 1 without a fade, in [0, 1].
pub fn test_alpha(num: f32, den: f32, fade: f32) -> f32 {
    if fade.is_nan() || fade <= 0.0 {
        return 1.0;
    }
    let q = den * fade + num;
    let a = if q != 0.0 { num / q } else { 0.0 };
    if a >= 0.0 { a.min(1.0) } else { 0.0 }
}

/// `emit_tested` of kernels/common/isoline.h: the segment `pa → pb` of face
/// `f` (its ends on the mesh edges `ea`, `eb`) whole (without the test), or
/// its tested pieces, each with the mean of its ends' fades as strength.
/// Returns the pieces emitted.
// Mirrors emit_tested of kernels/common/isoline.h argument for argument
// (pairs grouped; its outputs as `out`).
#[allow(clippy::too_many_arguments)]
pub fn emit_tested(
    out: &mut Vec<Segment>,
    (pa, pb): ([f32; 3], [f32; 3]),
    (ea, eb): ([u32; 2], [u32; 2]),
    f: u32,
    [na, nb, da, db]: [f32; 4],
    test: bool,
    fade: f32,
    fam: u32,
) -> usize {
    if !test {
        out.push(Segment::new(pa, pb, fam, 1.0, [ea, eb]));
        return 1;
    }
    let pieces = test_pieces(na, nb, da, db);
    for &[s0, s1] in &pieces {
        let (n0, n1) = (na + s0 * (nb - na), na + s1 * (nb - na));
        let (d0, d1) = (da + s0 * (db - da), da + s1 * (db - da));
        let st = 0.5 * (test_alpha(n0, d0, fade) + test_alpha(n1, d1, fade));
        let at = |s: f32| -> [f32; 3] { std::array::from_fn(|i| pa[i] + s * (pb[i] - pa[i])) };
        let q0 = if s0 == 0.0 { pa } else { at(s0) };
        let q1 = if s1 == 1.0 { pb } else { at(s1) };
        let e0 = if s0 == 0.0 { ea } else { [LINE_FREE, f] };
        let e1 = if s1 == 1.0 { eb } else { [LINE_FREE, f] };
        out.push(Segment::new(q0, q1, fam, st, [e0, e1]));
    }
    pieces.len()
}

pub use crate::spec::coherence::{LINE_UNBORN, LINE_UNGATED};

/// A family's threshold on a face holding bits `bits`: times `low` where
/// the face holds the family.
pub fn held_thr(bits: u32, fam: u32, thr: f32, low: f32) -> f32 {
    if (bits >> fam) & 1 != 0 {
        thr * low
    } else {
        thr
    }
}

/// The families a face may draw (`may_draw` of isoline.h).
pub fn may_draw(held: u32, near: u32, birth: u32) -> u32 {
    match birth {
        0 => u32::MAX,
        1 => held | (near & 0xffff) | LINE_UNGATED,
        _ => held | (near >> 16) | LINE_UNGATED,
    }
}

/// The family code a segment of `fam` is emitted with.
pub fn unborn(may: u32, fam: u32) -> u32 {
    if (may >> fam) & 1 != 0 {
        fam
    } else {
        fam | LINE_UNBORN
    }
}

/// The coherence state of one frame's extraction, as the kernels take it
/// (kernels/common/isoline.h): the previous frame's families per face
/// (`held`) and at the corners (`near`), empty for none; the marks this
/// frame makes (`next_held`, `next_near`, OR-ed in; empty: not kept); the
/// fraction of a threshold a held face tests against; the delay of births
/// in frames (0: none, and on a sequence's first frame).
pub struct Hold<'a> {
    /// The families each face drew in the previous frame.
    pub held: &'a [u32],
    /// The families found around each vertex in the previous frame (low 16
    /// bits) and established there (high 16 bits).
    pub near: &'a [u32],
    /// This frame's `held`.
    pub next_held: &'a mut [u32],
    /// This frame's `near`.
    pub next_near: &'a mut [u32],
    /// The fraction of its threshold a held face's family is tested against.
    pub low: f32,
    /// The delay of births in frames (0, 1 or 2).
    pub birth: u32,
}

impl Hold<'_> {
    /// No coherence: nothing held, nothing marked.
    pub fn none() -> Hold<'static> {
        Hold {
            held: &[],
            near: &[],
            next_held: &mut [],
            next_near: &mut [],
            low: 1.0,
            birth: 0,
        }
    }

    /// Face `f`'s (corners `v`) held families, the families found around
    /// it, and those it may draw.
    pub fn face(&self, f: usize, v: [u32; 3]) -> (u32, u32, u32) {
        let held = self.held.get(f).copied().unwrap_or(0);
        let near = match self.near.is_empty() {
            true => 0,
            false => v.iter().fold(0, |b, &i| b | self.near[i as usize]),
        };
        (held, near, may_draw(held, near, self.birth))
    }

    /// `mark_found` of isoline.h: face `f` (corners `v`) found `found`.
    pub fn mark(&mut self, f: usize, v: [u32; 3], (held, near, may): (u32, u32, u32), found: u32) {
        if let Some(m) = self.next_held.get_mut(f) {
            *m |= found & may;
        }
        let est = if self.birth == 0 {
            found
        } else {
            found & ((near & 0xffff) | held)
        };
        if !self.next_near.is_empty() {
            for i in v {
                self.next_near[i as usize] |= found | (est << 16);
            }
        }
    }
}

/// Drops the segments found but not drawn (a delayed birth).
pub fn drop_unborn(segs: &mut Vec<Segment>) {
    segs.retain(|s| s.family & LINE_UNBORN == 0);
}

/// `lines_face`: segments of the requested kinds, with rtsc's tests when
/// `test` (contours: κr ≥ 0; suggestive contours: sinθ D_w κr / (n·v) ≥
/// `sc_thresh`, faded by `fade`), suggestive contours placed by rtsc's
/// Hermite fit when `hermite`; held faces (`hold`) test suggestive
/// contours against `sc_thresh` times its `low`, and births are delayed as
/// it says (the segments found but not drawn are dropped).
// Mirrors the kernel lines_face of kernels/feature_lines.cl argument for
// argument (ndv, kr, sc, gkr as `t`, the two wants as `want`, held, near,
// next_held, next_near, low and birth as `hold`; its outputs returned).
#[allow(clippy::too_many_arguments)]
pub fn lines_face(
    faces: &[[u32; 3]],
    pos: &[[f32; 3]],
    t: &VertexTerms,
    want: [bool; 2],
    test: bool,
    hermite: bool,
    sc_thresh: f32,
    fade: f32,
    hold: &mut Hold,
) -> Vec<Segment> {
    let mut out = Vec::new();
    for (fi, f) in faces.iter().enumerate() {
        let v = f.map(|i| i as usize);
        let state = hold.face(fi, *f);
        let (hb, _, may) = state;
        let mut found = 0u32;
        for kind in 0..2u32 {
            if !want[kind as usize] {
                continue;
            }
            let fv = v.map(|i| if kind == 0 { t.ndv[i] } else { t.kr[i] });
            let Some(c) = odd_corner(fv) else { continue };
            if kind == 1 && v.iter().all(|&i| t.ndv[i] <= 0.0) {
                continue;
            }
            let (a, b) = ((c + 1) % 3, (c + 2) % 3);
            let pc = pos[v[c]];
            let ea: [f32; 3] = std::array::from_fn(|i| pos[v[a]][i] - pc[i]);
            let eb: [f32; 3] = std::array::from_fn(|i| pos[v[b]][i] - pc[i]);
            let (ta, tb) = if kind == 1 && hermite {
                let g = |i: usize| t.gkr[v[i]];
                (
                    zero_hermite(fv[c], fv[a], dot(ea, g(c)), dot(ea, g(a))),
                    zero_hermite(fv[c], fv[b], dot(eb, g(c)), dot(eb, g(b))),
                )
            } else {
                (cross_t(fv[c], fv[a]), cross_t(fv[c], fv[b]))
            };
            let lerp = |t: f32, p: usize| -> [f32; 3] {
                let e = if p == a { ea } else { eb };
                std::array::from_fn(|i| pc[i] + t * e[i])
            };
            let (num, den): ([f32; 3], [f32; 3]) = if kind == 0 {
                (v.map(|i| t.kr[i]), [1.0; 3])
            } else {
                let d = v.map(|i| t.ndv[i]);
                let th = held_thr(hb, 1, sc_thresh, hold.low);
                (std::array::from_fn(|j| t.sc[v[j]] - th * d[j]), d)
            };
            let li = |x: [f32; 3], t: f32, p: usize| x[c] + t * (x[p] - x[c]);
            let ends = [
                li(num, ta, a),
                li(num, tb, b),
                li(den, ta, a),
                li(den, tb, b),
            ];
            let edge = |p: usize| [v[c].min(v[p]) as u32, v[c].max(v[p]) as u32];
            let n = emit_tested(
                &mut out,
                (lerp(ta, a), lerp(tb, b)),
                (edge(a), edge(b)),
                fi as u32,
                ends,
                test,
                if kind == 0 { 0.0 } else { fade },
                unborn(may, kind),
            );
            if n > 0 {
                found |= 1 << kind;
            }
        }
        hold.mark(fi, *f, state, found);
    }
    drop_unborn(&mut out);
    out
}

/// rtsc's draw_isolines test: some corner above zero and some below.
pub(crate) fn crosses_zero(f: [f32; 3]) -> bool {
    f.iter().any(|&x| x > 0.0) && f.iter().any(|&x| x < 0.0)
}

/// The corner whose sign (≥ 0 or < 0) differs from the other two, where
/// `f` crosses zero ([`crosses_zero`]); `odd_corner` of
/// kernels/feature_lines_curves.cl (inline in `lines_face`).
pub(crate) fn odd_corner(f: [f32; 3]) -> Option<usize> {
    if !crosses_zero(f) {
        return None;
    }
    let s = f.map(|x| x >= 0.0);
    if s[0] == s[1] && s[1] == s[2] {
        None
    } else if s[0] == s[1] {
        Some(2)
    } else if s[0] == s[2] {
        Some(1)
    } else {
        Some(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_are_where_num_and_den_agree_in_sign() {
        // num from −1 to 1, den 1: the second half.
        assert_eq!(test_pieces(-1.0, 1.0, 1.0, 1.0), vec![[0.5, 1.0]]);
        // Both positive: whole; both negative num with positive den: none.
        assert_eq!(test_pieces(1.0, 2.0, 1.0, 1.0), vec![[0.0, 1.0]]);
        assert!(test_pieces(-1.0, -2.0, 1.0, 1.0).is_empty());
        // num and den both negative: valid (rtsc's sign rule).
        assert_eq!(test_pieces(-1.0, -2.0, -1.0, -1.0), vec![[0.0, 1.0]]);
        // num crosses at 0.25, den at 0.75: valid before 0.25 and after 0.75.
        assert_eq!(
            test_pieces(1.0, -3.0, 3.0, -1.0),
            vec![[0.0, 0.25], [0.75, 1.0]]
        );
        // Invalid at the start, valid between the two crossings.
        assert_eq!(test_pieces(-1.0, 3.0, 3.0, -1.0), vec![[0.25, 0.75]]);
    }

    #[test]
    fn the_fade_is_rtsc_s() {
        // r / (r + fade) with r = num / den.
        assert!((test_alpha(2.0, 1.0, 1.0) - 2.0 / 3.0).abs() < 1e-7);
        assert!((test_alpha(0.3, 3.0, 0.1) - 0.5).abs() < 1e-7);
        assert_eq!(test_alpha(0.0, 1.0, 0.5), 0.0);
        // num and den both negative: r = 0.5 > 0.
        assert!((test_alpha(-1.0, -2.0, 0.5) - 0.5).abs() < 1e-7);
        // No fade: full strength; NaN input: 0, never NaN.
        assert_eq!(test_alpha(0.2, 1.0, 0.0), 1.0);
        assert_eq!(test_alpha(f32::NAN, 1.0, 0.5), 0.0);
    }

    #[test]
    fn hermite_crossings_of_a_cubic_are_exact() {
        // f(t) = t³ − 0.4 t² − ... with a single root at 0.3 built as
        // (t − 0.3)(t² + 1): values and derivatives at 0 and 1.
        let f = |t: f32| (t - 0.3) * (t * t + 1.0);
        let df = |t: f32| (t * t + 1.0) + 2.0 * t * (t - 0.3);
        let z = zero_hermite(f(0.0), f(1.0), df(0.0), df(1.0));
        assert!((z - 0.3).abs() < 1e-3, "{z}");
        // A straight line: the linear crossing.
        let z = zero_hermite(-1.0, 3.0, 4.0, 4.0);
        assert!((z - 0.25).abs() < 1e-3, "{z}");
    }
}
