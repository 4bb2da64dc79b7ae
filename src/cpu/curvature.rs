//! CPU reference of `kernels/curvature.cl` (f64, sequential, same steps and
//! the same rules: degenerate faces skipped, normalization to unit size,
//! exact or trimesh2-compatible solve). Step functions are public so tests can
//! run the pipeline up to a pass and compare it with the device there.

// The reference mirrors the kernel line by line (indexed loops over corners and
// matrix rows), and `!(x > 0.0)` is deliberate: NaN must fail those tests.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

use crate::mesh::Mesh;
use crate::mesh::topology::max_face;
use crate::spec::curvature::{
    Compat, CurvatureCounts, CurvatureField, CurvatureOptions, DEGEN_AREA_REL, DEGEN_EDGE2,
    Normalization, Precision, degen_height_ulp,
};

use super::vec3::{V3, add, cross, dot, len, scale, sub};

fn normalize(a: V3) -> V3 {
    scale(a, 1.0 / len(a))
}
const fn next3(i: usize) -> usize {
    if i == 2 { 0 } else { i + 1 }
}
const fn prev3(i: usize) -> usize {
    if i == 0 { 2 } else { i - 1 }
}

/// A face's vertices, positions and edges (`e[i]` opposite corner i).
#[derive(Clone, Copy, Debug)]
pub struct Tri {
    /// Vertex indices.
    pub v: [usize; 3],
    /// Edges: `e[i] = p[prev(i)] − p[next(i)]`.
    pub e: [V3; 3],
    /// |p0| + |p1| + |p2| (normalized coordinates).
    pub psum: f64,
}

impl Tri {
    /// Loads face `f`.
    pub fn load(pos: &[V3], face: [u32; 3]) -> Tri {
        let v = face.map(|x| x as usize);
        let p = v.map(|i| pos[i]);
        Tri {
            v,
            e: std::array::from_fn(|i| sub(p[prev3(i)], p[next3(i)])),
            psum: len(p[0]) + len(p[1]) + len(p[2]),
        }
    }

    /// The degenerate-face rule: an edge with squared length ≤ 1e-24 (unit-RMS
    /// coordinates), or 2·area ≤ 5e-8 · Σ edge², or 2·area/√(Σ edge²) below
    /// the rounding of the positions at the computing precision (`ulp` · Σ|p|,
    /// [`degen_height_ulp`]). NaN counts as degenerate.
    pub fn degenerate(&self, ulp: f64) -> bool {
        let l = self.e.map(|e| dot(e, e));
        if !(l[0] > DEGEN_EDGE2 && l[1] > DEGEN_EDGE2 && l[2] > DEGEN_EDGE2) {
            return true;
        }
        let lsum = l[0] + l[1] + l[2];
        let twice_area = len(cross(self.e[0], self.e[1]));
        !(twice_area > DEGEN_AREA_REL * lsum && twice_area > ulp * lsum.sqrt() * self.psum)
    }

    /// Corner-weighted face normal for corner `c`.
    pub fn corner_normal(&self, c: usize) -> V3 {
        let fnrm = cross(self.e[2], self.e[0]);
        let la = dot(self.e[next3(c)], self.e[next3(c)]);
        let lb = dot(self.e[prev3(c)], self.e[prev3(c)]);
        scale(scale(fnrm, 1.0 / la), 1.0 / lb)
    }

    /// Voronoi corner areas (trimesh2's obtuse rule).
    pub fn corner_areas(&self) -> [f64; 3] {
        let e = &self.e;
        let area = 0.5 * len(cross(e[0], e[1]));
        let l2 = e.map(|x| dot(x, x));
        let ew = [
            l2[0] * (l2[1] + l2[2] - l2[0]),
            l2[1] * (l2[2] + l2[0] - l2[1]),
            l2[2] * (l2[0] + l2[1] - l2[2]),
        ];
        let mut ca = [0.0; 3];
        if ew[0] <= 0.0 {
            ca[1] = -0.25 * l2[2] * area / dot(e[0], e[2]);
            ca[2] = -0.25 * l2[1] * area / dot(e[0], e[1]);
            ca[0] = area - ca[1] - ca[2];
        } else if ew[1] <= 0.0 {
            ca[2] = -0.25 * l2[0] * area / dot(e[1], e[0]);
            ca[0] = -0.25 * l2[2] * area / dot(e[1], e[2]);
            ca[1] = area - ca[2] - ca[0];
        } else if ew[2] <= 0.0 {
            ca[0] = -0.25 * l2[1] * area / dot(e[2], e[1]);
            ca[1] = -0.25 * l2[0] * area / dot(e[2], e[0]);
            ca[2] = area - ca[0] - ca[1];
        } else {
            let s = 0.5 * area / (ew[0] + ew[1] + ew[2]);
            for (j, c) in ca.iter_mut().enumerate() {
                *c = s * (ew[next3(j)] + ew[prev3(j)]);
            }
        }
        ca
    }

    /// Face frame (t along e0, b in plane).
    pub fn frame(&self) -> (V3, V3) {
        let t = normalize(self.e[0]);
        let b = normalize(cross(cross(self.e[0], self.e[1]), t));
        (t, b)
    }
}

fn corner_weight(ca: f64, a: f64) -> f64 {
    if a > 0.0 { ca / a } else { 0.0 }
}

fn any_perp(n: V3) -> V3 {
    let a = if n[0].abs() <= n[1].abs() && n[0].abs() <= n[2].abs() {
        [1.0, 0.0, 0.0]
    } else if n[1].abs() <= n[2].abs() {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    normalize(cross(n, a))
}

fn rot_coord_sys(u: V3, v: V3, nn: V3) -> (V3, V3) {
    let on = cross(u, v);
    let ndot = dot(on, nn);
    if ndot <= -1.0 + 1e-6 {
        return (scale(u, -1.0), scale(v, -1.0));
    }
    let perp_old = sub(nn, scale(on, ndot));
    let dperp = scale(add(on, nn), 1.0 / (1.0 + ndot));
    (
        sub(u, scale(dperp, dot(u, perp_old))),
        sub(v, scale(dperp, dot(v, perp_old))),
    )
}

/// The coefficients (u1, v1, u2, v2) that re-express a tensor from frame
/// (ou, ov) in (nu, nv): (nu, nv) rotated into the plane of (ou, ov), dotted
/// with ou and ov. The projection the other way has the coefficients
/// (u1, u2, v1, v2) ([`coef_reverse`]): the minimal rotations between the two
/// planes are each other's inverse (as in `kernels/common/curvature_face.h`).
pub fn proj_coef(ou: V3, ov: V3, nu: V3, nv: V3) -> [f64; 4] {
    let (ru, rv) = rot_coord_sys(nu, nv, cross(ou, ov));
    [dot(ru, ou), dot(ru, ov), dot(rv, ou), dot(rv, ov)]
}

/// The coefficients of the projection opposite to `c`'s.
pub fn coef_reverse(c: [f64; 4]) -> [f64; 4] {
    [c[0], c[2], c[1], c[3]]
}

/// Re-expresses the tensor `k` = (ku, kuv, kv) by the coefficients of [`proj_coef`].
pub fn proj_curv_by(c: [f64; 4], k: V3) -> V3 {
    let [u1, v1, u2, v2] = c;
    [
        k[0] * u1 * u1 + k[1] * (2.0 * u1 * v1) + k[2] * v1 * v1,
        k[0] * u1 * u2 + k[1] * (u1 * v2 + u2 * v1) + k[2] * v1 * v2,
        k[0] * u2 * u2 + k[1] * (2.0 * u2 * v2) + k[2] * v2 * v2,
    ]
}

/// Re-expresses the tensor `k` = (ku, kuv, kv) from frame (ou, ov) in (nu, nv).
pub fn proj_curv(ou: V3, ov: V3, k: V3, nu: V3, nv: V3) -> V3 {
    proj_curv_by(proj_coef(ou, ov, nu, nv), k)
}

/// The same for the derivative tensor (C111, C112, C122, C222).
pub fn proj_dcurv_by(c: [f64; 4], d: [f64; 4]) -> [f64; 4] {
    let [u1, v1, u2, v2] = c;
    [
        d[0] * u1 * u1 * u1
            + d[1] * 3.0 * u1 * u1 * v1
            + d[2] * 3.0 * u1 * v1 * v1
            + d[3] * v1 * v1 * v1,
        d[0] * u1 * u1 * u2
            + d[1] * (u1 * u1 * v2 + 2.0 * u2 * u1 * v1)
            + d[2] * (u2 * v1 * v1 + 2.0 * u1 * v1 * v2)
            + d[3] * v1 * v1 * v2,
        d[0] * u1 * u2 * u2
            + d[1] * (u2 * u2 * v1 + 2.0 * u1 * u2 * v2)
            + d[2] * (u1 * v2 * v2 + 2.0 * u2 * v2 * v1)
            + d[3] * v1 * v2 * v2,
        d[0] * u2 * u2 * u2
            + d[1] * 3.0 * u2 * u2 * v2
            + d[2] * 3.0 * u2 * v2 * v2
            + d[3] * v2 * v2 * v2,
    ]
}

/// Per-face least-squares tensor from normal differences; `None` when a pivot
/// is not positive.
pub fn face_tensor(t: &Tri, ft: V3, fb: V3, n: [V3; 3], compat: Compat) -> Option<V3> {
    let (mut w00, mut w01, mut w22, mut m0, mut m1, mut m2) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for j in 0..3 {
        let (u, v) = (dot(t.e[j], ft), dot(t.e[j], fb));
        w00 += u * u;
        w01 += u * v;
        w22 += v * v;
        let dn = sub(n[prev3(j)], n[next3(j)]);
        let (dnu, dnv) = (dot(dn, ft), dot(dn, fb));
        m0 += dnu * u;
        m1 += dnu * v + dnv * u;
        m2 += dnv * v;
    }
    let (w11, w12) = (w00 + w22, w01);
    // One division per pivot, as in the kernel (kernels/curvature.cl).
    let d0 = w00;
    let r0 = 1.0 / d0;
    let l10 = w01 * r0;
    let d1 = w11 - l10 * w01;
    let r1 = 1.0 / d1;
    let l21 = w12 * r1;
    let d2 = match compat {
        Compat::Trimesh2 => w22,
        Compat::Exact => w22 - l21 * w12,
    };
    if !(d0 > 0.0 && d1 > 0.0 && d2 > 0.0) {
        return None;
    }
    let y1 = m1 - l10 * m0;
    let y2 = m2 - l21 * y1;
    let x2 = y2 / d2;
    let x1 = y1 * r1 - l21 * x2;
    let x0 = m0 * r0 - l10 * x1;
    let x = [x0, x1, x2];
    x.iter().all(|c| c.is_finite()).then_some(x)
}

/// Per-face least-squares derivative tensor; `None` when a pivot is not
/// positive. The 4×4 normal equations [[a b 0 0] [b 2a+c 2b 0] [0 2b a+2c b]
/// [0 0 b c]] (a = Σu², b = Σuv, c = Σv²) are tridiagonal; LDLᵀ unrolled.
pub fn face_dcurv(t: &Tri, ft: V3, fb: V3, fc: [V3; 3]) -> Option<[f64; 4]> {
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    let mut m = [0.0f64; 4];
    for j in 0..3 {
        let d = sub(fc[prev3(j)], fc[next3(j)]);
        let (u, v) = (dot(t.e[j], ft), dot(t.e[j], fb));
        a += u * u;
        b += u * v;
        c += v * v;
        m[0] += u * d[0];
        m[1] += v * d[0] + 2.0 * u * d[1];
        m[2] += 2.0 * v * d[1] + u * d[2];
        m[3] += v * d[2];
    }
    let d0 = a;
    let r0 = 1.0 / d0;
    let l10 = b * r0;
    let d1 = 2.0 * a + c - l10 * b;
    let r1 = 1.0 / d1;
    let l21 = 2.0 * b * r1;
    let d2 = a + 2.0 * c - l21 * (2.0 * b);
    let r2 = 1.0 / d2;
    let l32 = b * r2;
    let d3 = c - l32 * b;
    if !(d0 > 0.0 && d1 > 0.0 && d2 > 0.0 && d3 > 0.0) {
        return None;
    }
    let y1 = m[1] - l10 * m[0];
    let y2 = m[2] - l21 * y1;
    let y3 = m[3] - l32 * y2;
    let x3 = y3 / d3;
    let x2 = y2 * r2 - l32 * x3;
    let x1 = y1 * r1 - l21 * x2;
    let x0 = m[0] * r0 - l10 * x1;
    let x = [x0, x1, x2, x3];
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// State of the reference pipeline, pass by pass (normalized coordinates).
#[derive(Clone, Debug, Default)]
pub struct State {
    /// Normalized positions.
    pub pos: Vec<V3>,
    /// Faces.
    pub faces: Vec<[u32; 3]>,
    /// Owning face per vertex (−1: unreferenced).
    pub owner: Vec<i64>,
    /// Normals (raw sums, unit after `frames`).
    pub normals: Vec<V3>,
    /// Point areas.
    pub areas: Vec<f64>,
    /// First frame vector.
    pub pd1: Vec<V3>,
    /// Second frame vector.
    pub pd2: Vec<V3>,
    /// (ku, kuv, kv).
    pub tensor: Vec<V3>,
    /// (k1, k2).
    pub k: Vec<[f64; 2]>,
    /// Derivative tensor.
    pub dk: Vec<[f64; 4]>,
    /// What was skipped.
    pub counts: CurvatureCounts,
    /// Height threshold of the degenerate-face rule ([`degen_height_ulp`]).
    pub height_ulp: f64,
}

impl State {
    /// Sets up the pipeline on a normalized copy of the mesh, judging faces
    /// by the f64 rounding (as the f64 device does).
    pub fn new(mesh: &Mesh, norm: &Normalization) -> State {
        State::for_precision(mesh, norm, Precision::F64)
    }

    /// As [`State::new`], skipping the faces the device skips at `precision`
    /// (so that the counts of a device run and of its twin agree).
    pub fn for_precision(mesh: &Mesh, norm: &Normalization, precision: Precision) -> State {
        let nv = mesh.n_vertices();
        State {
            pos: mesh
                .positions
                .iter()
                .zip(mesh.referenced())
                .map(|(&p, used)| if used { norm.apply(p) } else { [0.0; 3] })
                .collect(),
            faces: mesh.faces.clone(),
            owner: max_face(nv, &mesh.faces),
            normals: vec![[0.0; 3]; nv],
            areas: vec![0.0; nv],
            pd1: vec![[0.0; 3]; nv],
            pd2: vec![[0.0; 3]; nv],
            tensor: vec![[0.0; 3]; nv],
            k: vec![[0.0; 2]; nv],
            dk: vec![[0.0; 4]; nv],
            counts: CurvatureCounts::default(),
            height_ulp: degen_height_ulp(precision),
        }
    }

    fn tris(&self) -> impl Iterator<Item = Tri> + '_ {
        self.faces.iter().map(|&f| Tri::load(&self.pos, f))
    }

    /// Step `normals_areas`.
    pub fn normals_areas(&mut self) {
        let tris: Vec<Tri> = self.tris().collect();
        for t in tris {
            if t.degenerate(self.height_ulp) {
                self.counts.degenerate_faces += 1;
                continue;
            }
            let ca = t.corner_areas();
            for c in 0..3 {
                let v = t.v[c];
                self.normals[v] = add(self.normals[v], t.corner_normal(c));
                self.areas[v] += ca[c];
            }
        }
    }

    /// `curv_override_normals`: the given normals (a file's stored ones) in
    /// place of the summed face normals, where their f32 length is finite
    /// and non-zero, as the kernel tests it.
    pub fn override_normals(&mut self, normals: &[[f32; 3]]) {
        for (v, n) in normals.iter().enumerate().take(self.normals.len()) {
            let l2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            if l2.is_finite() && l2 > 0.0 {
                self.normals[v] = n.map(f64::from);
            }
        }
    }

    /// Step `frames`: unit normals and initial frames from the owner face.
    pub fn frames(&mut self) {
        for v in 0..self.pos.len() {
            let n = self.normals[v];
            let l = len(n);
            let n = if l > 0.0 && l.is_finite() {
                scale(n, 1.0 / l)
            } else {
                [0.0, 0.0, 1.0]
            };
            self.normals[v] = n;
            if !(self.areas[v] > 0.0) {
                self.counts.vertices_without_curvature += 1;
            }
            let mut p1 = [0.0; 3];
            if self.owner[v] >= 0 {
                let f = self.faces[self.owner[v] as usize].map(|x| x as usize);
                let next = if v == f[0] {
                    f[1]
                } else if v == f[1] {
                    f[2]
                } else {
                    f[0]
                };
                p1 = cross(sub(self.pos[next], self.pos[v]), n);
            }
            let l = len(p1);
            let p1 = if l > 1e-20 && l.is_finite() {
                scale(p1, 1.0 / l)
            } else {
                any_perp(n)
            };
            self.pd1[v] = p1;
            self.pd2[v] = cross(n, p1);
        }
    }

    /// Step `tensor`.
    pub fn tensor(&mut self, compat: Compat) {
        let tris: Vec<Tri> = self.tris().collect();
        for t in tris {
            if t.degenerate(self.height_ulp) {
                continue;
            }
            let (ft, fb) = t.frame();
            let n = t.v.map(|v| self.normals[v]);
            let Some(x) = face_tensor(&t, ft, fb, n, compat) else {
                self.counts.tensor_solves_skipped += 1;
                continue;
            };
            let ca = t.corner_areas();
            for c in 0..3 {
                let v = t.v[c];
                let k = proj_curv(ft, fb, x, self.pd1[v], self.pd2[v]);
                let w = corner_weight(ca[c], self.areas[v]);
                self.tensor[v] = add(self.tensor[v], scale(k, w));
            }
        }
    }

    /// Step `principal`.
    pub fn principal(&mut self, compat: Compat) {
        for v in 0..self.pos.len() {
            let n = self.normals[v];
            let (ru, rv) = rot_coord_sys(self.pd1[v], self.pd2[v], n);
            let [ku, kuv, kv] = self.tensor[v];
            let (mut c, mut s, mut tt) = (1.0, 0.0, 0.0);
            if kuv != 0.0 {
                let h = 0.5 * (kv - ku) / kuv;
                tt = if h < 0.0 {
                    1.0 / (h - (1.0 + h * h).sqrt())
                } else {
                    1.0 / (h + (1.0 + h * h).sqrt())
                };
                c = 1.0 / (1.0 + tt * tt).sqrt();
                s = tt * c;
            }
            let (mut k1, mut k2) = (ku - tt * kuv, kv + tt * kuv);
            let keep = match compat {
                Compat::Trimesh2 => k1.abs() >= k2.abs(),
                Compat::Exact => k1 >= k2,
            };
            let d1 = if keep {
                sub(scale(ru, c), scale(rv, s))
            } else {
                std::mem::swap(&mut k1, &mut k2);
                add(scale(ru, s), scale(rv, c))
            };
            self.pd1[v] = d1;
            self.pd2[v] = cross(n, d1);
            self.k[v] = [k1, k2];
        }
    }

    /// Step `dcurv`.
    pub fn dcurv(&mut self) {
        let tris: Vec<Tri> = self.tris().collect();
        for t in tris {
            if t.degenerate(self.height_ulp) {
                continue;
            }
            let (ft, fb) = t.frame();
            // One set of projection coefficients per corner serves both
            // directions: the vertex tensor into the face frame, the face's
            // result back (see `proj_coef`).
            let q = t.v.map(|v| proj_coef(self.pd1[v], self.pd2[v], ft, fb));
            let fc: [V3; 3] = std::array::from_fn(|c| {
                proj_curv_by(q[c], [self.k[t.v[c]][0], 0.0, self.k[t.v[c]][1]])
            });
            let Some(x) = face_dcurv(&t, ft, fb, fc) else {
                self.counts.dcurv_solves_skipped += 1;
                continue;
            };
            let ca = t.corner_areas();
            for c in 0..3 {
                let v = t.v[c];
                let o = proj_dcurv_by(coef_reverse(q[c]), x);
                let w = corner_weight(ca[c], self.areas[v]);
                for i in 0..4 {
                    self.dk[v][i] += w * o[i];
                }
            }
        }
    }

    /// The field in the mesh's own coordinates.
    pub fn field(&self, norm: &Normalization, with_dcurv: bool) -> CurvatureField {
        let nv = self.pos.len();
        let mut f = CurvatureField {
            normals: self.normals.clone(),
            areas: self.areas.clone(),
            k1: self.k.iter().map(|k| k[0]).collect(),
            k2: self.k.iter().map(|k| k[1]).collect(),
            d1: self.pd1.clone(),
            d2: self.pd2.clone(),
            dk: if with_dcurv {
                self.dk.clone()
            } else {
                vec![[0.0; 4]; nv]
            },
        };
        norm.unapply(&mut f);
        f
    }
}

/// Runs the whole reference pipeline. `opts.accumulate` does not apply (the
/// reference is sequential f64); `opts.precision` only chooses which faces
/// are too thin for that precision's rounding, so that the reference skips
/// the faces the device skips.
pub fn estimate(mesh: &Mesh, opts: &CurvatureOptions) -> (CurvatureField, CurvatureCounts) {
    let norm = Normalization::of_masked(&mesh.positions, Some(&mesh.referenced()));
    let mut s = State::for_precision(mesh, &norm, opts.precision);
    s.normals_areas();
    if let Some(n) = &mesh.normals {
        s.override_normals(n);
    }
    s.frames();
    s.tensor(opts.compat);
    s.principal(opts.compat);
    if opts.dcurv {
        s.dcurv();
    }
    (s.field(&norm, opts.dcurv), s.counts)
}

/// The front door's CPU twin: [`estimate`] with the signature of
/// `shapecue::curvature`, timed as a whole (`timing.wall_ms`; no kernel
/// steps, no device bytes).
///
/// ```
/// use shapecue::mesh::Generated;
/// use shapecue::spec::curvature::CurvatureOptions;
/// let (_, mesh) = Generated::Torus.mesh(2000);
/// let c = shapecue::cpu::curvature::curvature(&mesh, CurvatureOptions::default())?;
/// assert_eq!(c.field.len(), mesh.n_vertices());
/// assert_eq!(c.counts.degenerate_faces, 0);
/// # Ok::<(), shapecue::Error>(())
/// ```
///
/// # Errors
/// None today (the reference cannot fail on a loaded mesh); the `Result`
/// keeps the device form's signature.
pub fn curvature(
    mesh: &Mesh,
    opts: CurvatureOptions,
) -> crate::Result<crate::spec::curvature::Curvature> {
    let t = std::time::Instant::now();
    let (field, counts) = estimate(mesh, &opts);
    let timing = crate::spec::timing::Timing {
        wall_ms: t.elapsed().as_secs_f64() * 1e3,
        ..Default::default()
    };
    Ok(crate::spec::curvature::Curvature {
        field,
        counts,
        timing,
        device_bytes: 0,
    })
}
