//! CPU reference of `kernels/feature_lines_curves.cl` (same steps, same f32
//! arithmetic): [`lines_pose`] once per pose, [`lines_view`] and
//! [`lines_dt1q1`] once per view, then [`lines_curves`] per face. The
//! per-view inputs n·v, κr and the suggestive test come from
//! [`super::feature_lines::lines_vertex`]. Segments come out in face order;
//! the device's order is that of its atomic counter, so tests compare sorted
//! lists.

pub use super::feature_lines::zero_hermite;
use super::feature_lines::{
    Hold, VertexTerms, drop_unborn, emit_tested, held_thr, odd_corner, unborn,
};
use crate::spec::feature_lines::{CurveOptions, LineFamily, LineInputs, Segment};
pub use crate::spec::feature_lines::{ScaledThresholds, boundary_mask};
use crate::spec::view::View;

type V3 = [f32; 3];

fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn mul(s: f32, a: V3) -> V3 {
    a.map(|c| s * c)
}
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn lerp(a: V3, b: V3, t: f32) -> V3 {
    add(a, mul(t, sub(b, a)))
}

/// Per-pose terms of `lines_pose`, per vertex.
#[derive(Clone, Debug, Default)]
pub struct PoseTerms {
    /// The principal curvature of larger magnitude.
    pub kmax: Vec<f32>,
    /// Its derivative along its own direction (C111 or C222).
    pub emax: Vec<f32>,
    /// Its direction.
    pub dmax: Vec<V3>,
    /// Gaussian curvature k1·k2.
    pub gauss: Vec<f32>,
    /// Mean curvature (k1 + k2)/2.
    pub mean: Vec<f32>,
    /// ∇K and ∇H (empty unless asked for).
    pub grad: Vec<[V3; 2]>,
}

/// `lines_pose`: kmax, emax, dmax, K, H and, with `grads`, ∇K and ∇H.
pub fn lines_pose(x: &LineInputs, grads: bool) -> PoseTerms {
    lines_pose_held(x, grads, (&mut [], &mut []), 0, [0.0; 3])
}

/// [`lines_pose`] with coherence's Schmitt trigger on the signs of K and H
/// and the side of emax dmax (kernels/feature_lines_curves.cl):
/// `sign_mode` 0 off, 1 records them in `signs` and `evec` (a sequence's
/// first frame), 2 keeps each vertex's sign of the previous frame where
/// |K| < `bands[0]` (|H| < `bands[1]`), and emax dmax's side where |emax| <
/// `bands[2]`.
// Mirrors the kernel lines_pose argument for argument (signs and evec as
// `state`, band_k, band_h, band_e as `bands`; its outputs returned).
pub fn lines_pose_held(
    x: &LineInputs,
    grads: bool,
    (signs, evec): (&mut [u32], &mut [V3]),
    sign_mode: u32,
    [band_k, band_h, band_e]: [f32; 3],
) -> PoseTerms {
    let mut t = PoseTerms::default();
    for i in 0..x.k.len() {
        let [k1, k2] = x.k[i];
        let c = x.dk[i];
        let first = k1.abs() >= k2.abs();
        t.kmax.push(if first { k1 } else { k2 });
        let dm = if first { x.d1[i] } else { x.d2[i] };
        let mut em = if first { c[0] } else { c[3] };
        if let Some(tp) = evec.get_mut(i).filter(|_| sign_mode != 0) {
            if sign_mode == 2 && em.abs() < band_e && dot(mul(em, dm), *tp) < 0.0 {
                em = -em;
            }
            *tp = mul(em, dm);
        }
        t.emax.push(em);
        t.dmax.push(dm);
        let (mut kg, mut km) = (k1 * k2, 0.5 * (k1 + k2));
        if let Some(held) = signs.get_mut(i).filter(|_| sign_mode != 0) {
            let s = *held;
            if sign_mode == 2 {
                if kg.abs() < band_k && ((s & 1) != 0) != (kg < 0.0) {
                    kg = -kg;
                }
                if km.abs() < band_h && ((s & 2) != 0) != (km < 0.0) {
                    km = -km;
                }
            }
            *held = u32::from(kg < 0.0) | (u32::from(km < 0.0) << 1);
        }
        t.gauss.push(kg);
        t.mean.push(km);
        if grads {
            let g1 = add(mul(c[0], x.d1[i]), mul(c[1], x.d2[i]));
            let g2 = add(mul(c[2], x.d1[i]), mul(c[3], x.d2[i]));
            t.grad
                .push([add(mul(k2, g1), mul(k1, g2)), mul(0.5, add(g1, g2))]);
        }
    }
    t
}

/// Per-view terms of `lines_view`, per vertex.
#[derive(Clone, Debug, Default)]
pub struct ViewTerms {
    /// q1 as rtsc and Judd et al.'s code keep it: the largest eigenvalue
    /// of QᵀQ, the square of the view-dependent curvature's magnitude (≥ 0).
    pub q1: Vec<f32>,
    /// Its direction t1, world coordinates (sign arbitrary).
    pub t1: Vec<V3>,
    /// v · dmax.
    pub phdot: Vec<f32>,
    /// |k1² − k2²| (n·v), the principal-highlight strength.
    pub phtest: Vec<f32>,
    /// n·l.
    pub ndl: Vec<f32>,
}

/// `lines_view` from `view`, with n·v from `lines_vertex` and the unit
/// light direction `light`.
pub fn lines_view(
    x: &LineInputs,
    pose: &PoseTerms,
    t: &VertexTerms,
    view: View,
    light: V3,
) -> ViewTerms {
    let (eye, ortho) = (view.line_eye(), view.ortho);
    let mut o = ViewTerms::default();
    for i in 0..x.pos.len() {
        let mut v = if ortho { eye } else { sub(eye, x.pos[i]) };
        let l = dot(v, v).sqrt();
        v = if l > 0.0 { v.map(|c| c / l) } else { [0.0; 3] };
        let (e1, e2) = (x.d1[i], x.d2[i]);
        let [k1, k2] = x.k[i];
        let nd = t.ndv[i];
        let (u, w) = (dot(v, e1), dot(v, e2));
        let s2 = u * u + w * w;
        let inv = if s2 > 1e-12 { 1.0 / s2 } else { 0.0 };
        let (a, b, c) = (u * u * inv, u * w * inv, w * w * inv);
        let sm1 = 1.0 / nd.abs().max(1e-4) - 1.0;
        let (q11, q12) = (k1 * (1.0 + sm1 * a), k1 * sm1 * b);
        let (q21, q22) = (k2 * sm1 * b, k2 * (1.0 + sm1 * c));
        let m1 = q11 * q11 + q21 * q21;
        let m12 = q11 * q12 + q21 * q22;
        let m2 = q12 * q12 + q22 * q22;
        let lam = 0.5 * (m1 + m2) + (0.25 * (m1 - m2) * (m1 - m2) + m12 * m12).sqrt();
        let (mut tx, mut ty) = (m12, lam - m1);
        let (ox, oy) = (lam - m2, m12);
        if ox * ox + oy * oy > tx * tx + ty * ty {
            (tx, ty) = (ox, oy);
        }
        let tl = (tx * tx + ty * ty).sqrt();
        (tx, ty) = if tl > 0.0 {
            (tx / tl, ty / tl)
        } else {
            (1.0, 0.0)
        };
        o.q1.push(lam.max(0.0));
        o.t1.push(add(mul(tx, e1), mul(ty, e2)));
        o.phdot.push(dot(v, pose.dmax[i]));
        o.phtest.push((k1 * k1 - k2 * k2).abs() * nd);
        o.ndl.push(dot(x.nrm[i], light));
    }
    o
}

/// `lines_dt1q1`: D_t1 q1 per vertex, from the faces around each vertex
/// (`off`, `ring`: [`crate::mesh::topology::one_rings`]).
pub fn lines_dt1q1(
    faces: &[[u32; 3]],
    x: &LineInputs,
    off: &[u32],
    ring: &[u32],
    vt: &ViewTerms,
    t: &VertexTerms,
) -> Vec<f32> {
    (0..x.pos.len())
        .map(|i| {
            let p0 = x.pos[i];
            let q0 = vt.q1[i];
            let t1 = vt.t1[i];
            let t2 = cross(x.nrm[i], t1);
            let (p0t2, anv) = (dot(p0, t2), t.ndv[i].abs());
            let (mut sum, mut n) = (0.0f32, 0);
            for &r in &ring[off[i] as usize..off[i + 1] as usize] {
                if n >= 2 {
                    break;
                }
                let (f, c) = ((r / 3) as usize, (r % 3) as usize);
                let (i1, i2) = (
                    faces[f][(c + 1) % 3] as usize,
                    faces[f][(c + 2) % 3] as usize,
                );
                let (p1, p2) = (x.pos[i1], x.pos[i2]);
                let (a1, a2) = (dot(p1, t2), dot(p2, t2));
                let w1 = (a2 - p0t2) / (a2 - a1);
                if !((0.0..1.0).contains(&w1)) {
                    continue;
                }
                let w2 = 1.0 - w1;
                let q = add(mul(w1, p1), mul(w2, p2));
                let dist = dot(sub(q, p0), t1) * anv;
                if dist.abs().is_nan() || dist.abs() <= 0.0 {
                    continue;
                }
                sum += (w1 * vt.q1[i1] + w2 * vt.q1[i2] - q0) / dist;
                n += 1;
            }
            if n == 2 { 0.5 * sum } else { sum }
        })
        .collect()
}

/// Everything `lines_curves` reads besides the faces and positions.
pub struct CurveTerms<'a> {
    /// `lines_vertex`'s output.
    pub vertex: &'a VertexTerms,
    /// `lines_pose`'s output.
    pub pose: &'a PoseTerms,
    /// `lines_view`'s output.
    pub view: &'a ViewTerms,
    /// `lines_dt1q1`'s output.
    pub dt: &'a [f32],
    /// [`boundary_mask`].
    pub bnd: &'a [u32],
}

struct Out<'a> {
    segs: &'a mut Vec<Segment>,
    /// The families the face may draw ([`Hold::face`]): the others are
    /// emitted with [`super::feature_lines::LINE_UNBORN`].
    may: u32,
}

impl Out<'_> {
    fn emit(&mut self, a: V3, b: V3, fam: LineFamily, s: f32, e: [[u32; 2]; 2]) {
        let code = unborn(self.may, fam as u32);
        self.segs.push(Segment::new(a, b, code, s, e));
    }
}

const CENTER: u32 = u32::MAX;

fn edge_of(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

fn ridge_strength(k: f32, thr: f32, fade: bool) -> f32 {
    let x = (k - thr).max(0.0);
    if fade {
        if x + thr > 0.0 { x / (x + thr) } else { 0.0 }
    } else if x > 0.0 {
        1.0
    } else {
        0.0
    }
}

fn ridge_w(ea: f32, eb: f32) -> f32 {
    let s = ea.abs() + eb.abs();
    if s > 0.0 { ea.abs() / s } else { 0.5 }
}

/// One ridge-like segment; with `judd` (the directions of increasing q1 at
/// the three corners), Judd et al.'s test of apparent ridges.
// Mirrors ridge_segment of kernels/feature_lines_curves.cl argument for
// argument (its outputs as `out`; judd with t0, t1, t2 as one Option).
#[allow(clippy::too_many_arguments)]
fn ridge_segment(
    out: &mut Out,
    f: u32,
    vi: [u32; 3],
    e: [f32; 3],
    kk: [f32; 3],
    pos: &[V3],
    thr: f32,
    fade: bool,
    centre: bool,
    fam: LineFamily,
    judd: Option<[V3; 3]>,
) {
    let p = vi.map(|i| pos[i as usize]);
    let w10 = ridge_w(e[0], e[1]);
    let pa = add(p[0], mul(w10, sub(p[1], p[0])));
    let ka = (kk[0] + w10 * (kk[1] - kk[0])).abs();
    let (pb, kb, eb) = if centre {
        (
            add(add(p[0], p[1]), p[2]).map(|c| c / 3.0),
            (kk[0] + kk[1] + kk[2]).abs() / 3.0,
            [CENTER, f],
        )
    } else {
        let w21 = ridge_w(e[1], e[2]);
        (
            add(p[1], mul(w21, sub(p[2], p[1]))),
            (kk[1] + w21 * (kk[2] - kk[1])).abs(),
            edge_of(vi[1], vi[2]),
        )
    };
    if ka.partial_cmp(&thr) != Some(std::cmp::Ordering::Greater)
        && kb.partial_cmp(&thr) != Some(std::cmp::Ordering::Greater)
    {
        return;
    }
    if let Some(t) = judd {
        let perp = cross(cross(sub(p[1], p[0]), sub(p[2], p[0])), sub(pa, pb));
        if !(dot(t[0], perp) > 0.0 && dot(t[1], perp) < 0.0 && dot(t[2], perp) > 0.0) {
            return;
        }
    }
    let s = 0.5 * (ridge_strength(ka, thr, fade) + ridge_strength(kb, thr, fade));
    out.emit(pa, pb, fam, s, [edge_of(vi[0], vi[1]), eb]);
}

fn rot1<T: Copy>(a: [T; 3]) -> [T; 3] {
    [a[1], a[2], a[0]]
}
fn rot2<T: Copy>(a: [T; 3]) -> [T; 3] {
    [a[2], a[0], a[1]]
}

/// The ridge-like segments of face `f` (corners `v`) where the directions
/// `t` at its corners flip.
// Mirrors ridge_face of kernels/feature_lines_curves.cl argument for
// argument (its outputs as `out`; t0, t1, t2 as `t`).
#[allow(clippy::too_many_arguments)]
fn ridge_face(
    out: &mut Out,
    f: u32,
    v: [u32; 3],
    e: [f32; 3],
    t: [V3; 3],
    kk: [f32; 3],
    pos: &[V3],
    test: bool,
    thr: f32,
    fade: bool,
    fam: LineFamily,
    judd: bool,
) {
    let mut z01 = dot(t[0], t[1]) <= 0.0;
    let mut z12 = dot(t[1], t[2]) <= 0.0;
    let mut z20 = dot(t[2], t[0]) <= 0.0;
    if (z01 as u32 + z12 as u32 + z20 as u32) < 2 {
        return;
    }
    if test && !judd {
        let p = v.map(|i| pos[i as usize]);
        let (d01, d12, d20) = (sub(p[1], p[0]), sub(p[2], p[1]), sub(p[0], p[2]));
        z01 = z01 && (dot(t[0], d01) >= 0.0 || dot(t[1], d01) <= 0.0);
        z12 = z12 && (dot(t[1], d12) >= 0.0 || dot(t[2], d12) <= 0.0);
        z20 = z20 && (dot(t[2], d20) >= 0.0 || dot(t[0], d20) <= 0.0);
        if (z01 as u32 + z12 as u32 + z20 as u32) < 2 {
            return;
        }
    }
    let (r1, e1, k1) = (rot1(v), rot1(e), rot1(kk));
    let (r2, e2, k2) = (rot2(v), rot2(e), rot2(kk));
    let jt = |t: [V3; 3]| (judd && test).then_some(t);
    let (j0, j1, j2) = (jt(t), jt(rot1(t)), jt(rot2(t)));
    if !z01 {
        ridge_segment(out, f, r1, e1, k1, pos, thr, fade, false, fam, j1);
    } else if !z12 {
        ridge_segment(out, f, r2, e2, k2, pos, thr, fade, false, fam, j2);
    } else if !z20 {
        ridge_segment(out, f, v, e, kk, pos, thr, fade, false, fam, j0);
    } else {
        ridge_segment(out, f, r1, e1, k1, pos, thr, fade, true, fam, j1);
        ridge_segment(out, f, r2, e2, k2, pos, thr, fade, true, fam, j2);
        ridge_segment(out, f, v, e, kk, pos, thr, fade, true, fam, j0);
    }
}

fn zero_linear(fa: f32, fb: f32) -> f32 {
    let d = fa - fb;
    (if d != 0.0 { fa / d } else { 0.5 }).clamp(0.0, 1.0)
}

fn iso_params(
    v: [u32; 3],
    f: [f32; 3],
    c: usize,
    pos: &[V3],
    grad: Option<(&[[V3; 2]], usize)>,
) -> (f32, f32) {
    let (a, b) = ((c + 1) % 3, (c + 2) % 3);
    match grad {
        None => (zero_linear(f[c], f[a]), zero_linear(f[c], f[b])),
        Some((g, sel)) => {
            let (ic, ia, ib) = (v[c] as usize, v[a] as usize, v[b] as usize);
            let pc = pos[ic];
            let (ea, eb) = (sub(pos[ia], pc), sub(pos[ib], pc));
            let gc = g[ic][sel];
            (
                zero_hermite(f[c], f[a], dot(ea, gc), dot(ea, g[ia][sel])),
                zero_hermite(f[c], f[b], dot(eb, gc), dot(eb, g[ib][sel])),
            )
        }
    }
}

fn iso_emit(
    out: &mut Out,
    v: [u32; 3],
    c: usize,
    tt: (f32, f32),
    pos: &[V3],
    fam: LineFamily,
    s: f32,
) {
    let (a, b) = ((c + 1) % 3, (c + 2) % 3);
    let pc = pos[v[c] as usize];
    out.emit(
        lerp(pc, pos[v[a] as usize], tt.0),
        lerp(pc, pos[v[b] as usize], tt.1),
        fam,
        s,
        [edge_of(v[c], v[a]), edge_of(v[c], v[b])],
    );
}

/// `lines_curves`: the segments of `o.families` (the contours excluded);
/// held faces (`hold`) test ridges, valleys, apparent ridges and both
/// highlights against their threshold times its `low`.
// Mirrors the kernel lines_curves (held, next and low as `hold`).
pub fn lines_curves(
    faces: &[[u32; 3]],
    pos: &[V3],
    x: &CurveTerms,
    o: &CurveOptions,
    thr: ScaledThresholds,
    hold: &mut Hold,
) -> Vec<Segment> {
    let mut segs = Vec::new();
    for (fi, face) in faces.iter().enumerate() {
        let before = segs.len();
        let state = hold.face(fi, *face);
        let mut out = Out {
            segs: &mut segs,
            may: state.2,
        };
        curve_face(
            &mut out,
            &CurveFace {
                fi,
                v: *face,
                pos,
                x,
                o,
                thr,
                held: state.0,
                low: hold.low,
            },
        );
        let found = (segs[before..].iter()).fold(0, |b, s| b | 1 << (s.family & 0xff));
        hold.mark(fi, *face, state, found);
    }
    drop_unborn(&mut segs);
    segs
}

/// The families of one face of [`lines_curves`], in the kernel's order.
fn curve_face(out: &mut Out, f: &CurveFace) {
    let (o, x) = (f.o, f.x);
    let want = o.families;
    {
        if want.has(LineFamily::Boundaries) {
            f.boundaries(out);
        }
        if want.has(LineFamily::ApparentRidges) {
            f.apparent_ridges(out);
        }
        if o.cull && f.g(&x.vertex.ndv).iter().all(|&n| n <= 0.0) {
            return;
        }
        f.ridges_valleys(out);
        if want.has(LineFamily::PrincipalHighlights) {
            f.principal_highlights(out);
        }
        if want.has(LineFamily::SuggestiveHighlights) {
            f.suggestive_highlights(out);
        }
        f.zero_sets(out);
        if want.has(LineFamily::Isophotes) && o.isophotes > 0 {
            f.isophotes(out);
        }
    }
}

/// One face of [`lines_curves`] and what its families read; its methods
/// are the families, in the kernel's order.
struct CurveFace<'a> {
    /// Face index and corners.
    fi: usize,
    v: [u32; 3],
    pos: &'a [V3],
    x: &'a CurveTerms<'a>,
    o: &'a CurveOptions,
    thr: ScaledThresholds,
    /// The families the face drew in the previous frame and the fraction
    /// of a threshold they are tested at ([`Hold::face`]).
    held: u32,
    low: f32,
}

impl CurveFace<'_> {
    /// `fam`'s threshold `thr` on this face ([`held_thr`]).
    fn thr_of(&self, fam: LineFamily, thr: f32) -> f32 {
        held_thr(self.held, fam as u32, thr, self.low)
    }

    /// The corners' values of a per-vertex array.
    fn g(&self, a: &[f32]) -> [f32; 3] {
        self.v.map(|i| a[i as usize])
    }

    /// The face's edges marked as boundary edges.
    fn boundaries(&self, out: &mut Out) {
        let (v, pos) = (self.v, self.pos);
        for j in 0..3 {
            if self.x.bnd[self.fi] & (1 << j) != 0 {
                let (ia, ib) = (v[j], v[(j + 1) % 3]);
                out.emit(
                    pos[ia as usize],
                    pos[ib as usize],
                    LineFamily::Boundaries,
                    1.0,
                    [[ia, ia], [ib, ib]],
                );
            }
        }
    }

    /// Apparent ridges (not culled, as in rtsc).
    fn apparent_ridges(&self, out: &mut Out) {
        let (v, wt, thr) = (self.v, self.x.view, self.thr);
        let q = self.g(&wt.q1);
        let e = self.g(self.x.dt);
        let fam = LineFamily::ApparentRidges;
        let ar = self.thr_of(fam, thr.ar);
        if q.iter().any(|&qq| qq > ar) {
            let t = [0, 1, 2].map(|i| mul(e[i], wt.t1[v[i] as usize]));
            let (f, pos, test, fade) = (self.fi as u32, self.pos, self.o.test, self.o.fade);
            ridge_face(out, f, v, e, t, q, pos, test, ar, fade, fam, true);
        }
    }

    /// Ridges and valleys, where the face's κmax all have their sign.
    fn ridges_valleys(&self, out: &mut Out) {
        let (v, pt) = (self.v, self.x.pose);
        let km = self.g(&pt.kmax);
        let dm = v.map(|i| pt.dmax[i as usize]);
        let (f, pos, test, fade) = (self.fi as u32, self.pos, self.o.test, self.o.fade);
        for (fam, sg) in [(LineFamily::Ridges, 1.0f32), (LineFamily::Valleys, -1.0)] {
            if !self.o.families.has(fam) || !km.iter().all(|&k| sg * k > 0.0) {
                continue;
            }
            let em = self.g(&pt.emax);
            let t = [0, 1, 2].map(|i| mul(sg * em[i], dm[i]));
            ridge_face(
                out,
                f,
                v,
                em,
                t,
                km,
                pos,
                test,
                self.thr_of(fam, self.thr.rv),
                fade,
                fam,
                false,
            );
        }
    }

    /// Principal highlights: where the view terms' dots flip across the
    /// face, its κmax directions agreeing.
    fn principal_highlights(&self, out: &mut Out) {
        let (v, pt, wt) = (self.v, self.x.pose, self.x.view);
        let km = self.g(&pt.kmax);
        let dm = v.map(|i| pt.dmax[i as usize]);
        let mut r = 0;
        for i in 1..3 {
            if km[i].abs() > km[r].abs() {
                r = i;
            }
        }
        let mut ok = true;
        let mut dots = self.g(&wt.phdot);
        for i in 0..3 {
            let c = dot(dm[i], dm[r]);
            if c < 0.0 {
                dots[i] *= -1.0;
            }
            ok = ok && c.abs() >= std::f32::consts::FRAC_1_SQRT_2;
        }
        let tst = self.g(&wt.phtest);
        let kmin = km[0].min(km[1]).min(km[2]);
        let kmax = km[0].max(km[1]).max(km[2]);
        let flavour = !self.o.test || kmin >= 0.0 || kmax <= 0.0;
        let z01 = dots[0] * dots[1] <= 0.0;
        let z12 = dots[1] * dots[2] <= 0.0;
        let z20 = dots[2] * dots[0] <= 0.0;
        if ok && flavour && (z01 as u32 + z12 as u32 + z20 as u32) >= 2 {
            let fam = LineFamily::PrincipalHighlights;
            let f = self.fi as u32;
            let (rv, rd, rt) = if !z01 {
                (rot1(v), rot1(dots), rot1(tst))
            } else if !z12 {
                (rot2(v), rot2(dots), rot2(tst))
            } else {
                (v, dots, tst)
            };
            if !(z01 && z12 && z20) {
                let (pos, ph, fade) = (self.pos, self.thr_of(fam, self.thr.ph), self.o.fade);
                ridge_segment(out, f, rv, rd, rt, pos, ph, fade, false, fam, None);
            }
        }
    }

    /// Suggestive highlights: the zero set of κr, tested (and faded) by
    /// sinθ D_w κr against the threshold.
    fn suggestive_highlights(&self, out: &mut Out) {
        let (v, pos, vt, thr) = (self.v, self.pos, self.x.vertex, self.thr);
        let f = self.g(&vt.kr);
        let Some(c) = odd_corner(f) else { return };
        let tt = if self.o.hermite {
            // rtsc's Hermite placement from the gradient of κr sin²θ.
            let (a, b) = ((c + 1) % 3, (c + 2) % 3);
            let (ic, ia, ib) = (v[c] as usize, v[a] as usize, v[b] as usize);
            let (ea, eb) = (sub(pos[ia], pos[ic]), sub(pos[ib], pos[ic]));
            let gk = &vt.gkr;
            (
                zero_hermite(f[c], f[a], dot(ea, gk[ic]), dot(ea, gk[ia])),
                zero_hermite(f[c], f[b], dot(eb, gk[ic]), dot(eb, gk[ib])),
            )
        } else {
            iso_params(v, f, c, pos, None)
        };
        let (a, b) = ((c + 1) % 3, (c + 2) % 3);
        let nd = self.g(&vt.ndv);
        let s3 = self.g(&vt.sc);
        let sh = self.thr_of(LineFamily::SuggestiveHighlights, thr.sh);
        let num: [f32; 3] = std::array::from_fn(|i| -s3[i] - sh * nd[i]);
        let ends = [
            num[c] + tt.0 * (num[a] - num[c]),
            num[c] + tt.1 * (num[b] - num[c]),
            nd[c] + tt.0 * (nd[a] - nd[c]),
            nd[c] + tt.1 * (nd[b] - nd[c]),
        ];
        let pc = pos[v[c] as usize];
        emit_tested(
            out.segs,
            (
                lerp(pc, pos[v[a] as usize], tt.0),
                lerp(pc, pos[v[b] as usize], tt.1),
            ),
            (edge_of(v[c], v[a]), edge_of(v[c], v[b])),
            self.fi as u32,
            ends,
            self.o.test,
            thr.sh_fade,
            unborn(out.may, LineFamily::SuggestiveHighlights as u32),
        );
    }

    /// The zero sets of K, H and D_w κr (against the suggestive-contour
    /// threshold), K and H placed by Hermite fits where asked.
    fn zero_sets(&self, out: &mut Out) {
        let (v, pt, o) = (self.v, self.x.pose, self.o);
        for fam in [LineFamily::KZero, LineFamily::HZero, LineFamily::DwkrZero] {
            if !o.families.has(fam) {
                continue;
            }
            let f = match fam {
                LineFamily::KZero => self.g(&pt.gauss),
                LineFamily::HZero => self.g(&pt.mean),
                _ => {
                    let (s3, nd) = (self.g(&self.x.vertex.sc), self.g(&self.x.vertex.ndv));
                    std::array::from_fn(|i| s3[i] - self.thr.sc * nd[i])
                }
            };
            let Some(c) = odd_corner(f) else { continue };
            let grad = (o.hermite_kh && fam != LineFamily::DwkrZero)
                .then(|| (&pt.grad[..], if fam == LineFamily::KZero { 0 } else { 1 }));
            let tt = iso_params(v, f, c, self.pos, grad);
            iso_emit(out, v, c, tt, self.pos, fam, 1.0);
        }
    }

    /// Isophotes: the levels j / n of n·l crossing the face.
    fn isophotes(&self, out: &mut Out) {
        let (v, isophotes) = (self.v, self.o.isophotes);
        let nl = self.g(&self.x.view.ndl);
        let n = isophotes as f32;
        let lo = nl[0].min(nl[1]).min(nl[2]);
        let hi = nl[0].max(nl[1]).max(nl[2]);
        let j0 = ((lo * n).floor() as i32).max(1 - isophotes as i32);
        let j1 = ((hi * n).ceil() as i32).min(isophotes as i32 - 1);
        for j in j0..=j1 {
            let f = nl.map(|c| c - j as f32 / n);
            if let Some(c) = odd_corner(f) {
                let tt = iso_params(v, f, c, self.pos, None);
                iso_emit(out, v, c, tt, self.pos, LineFamily::Isophotes, 1.0);
            }
        }
    }
}
