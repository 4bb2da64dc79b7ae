//! CPU twin of `kernels/sdf_lines.cl` (curvature-directed strokes on a
//! scalar volume), with the same step names as the kernels:
//!
//! - [`dense`] (`sdfl_dense`): a point on every grid edge whose ends are on
//!   both sides of iso, placed by the marching-cubes rule
//!   ([`crate::cpu::marching_cubes::mc_vertex`], the same f32 arithmetic as
//!   `kernels/common/mc_edge.h`), so points agree with the device bit for bit;
//! - [`thin`] (`sdfl_cell_count`, `sdfl_cell_fill`, `sdfl_thin_phase`,
//!   `sdfl_thin_compact`): parallel Poisson-disk thinning on a background grid
//!   of cell size r/√3 (a cell holds at most one seed), the 27 phase groups
//!   `(cx mod 3, cy mod 3, cz mod 3)` processed in order (cells of one group
//!   are ≥ 2 cells = 1.15 r apart, so they never conflict); a cell keeps its
//!   highest-priority sample farther than r from every seed kept so far,
//!   priority = [`priority`] of the sample's edge key. Also in f32, so the
//!   kept set and its order (cell order) match the device exactly;
//! - [`gradient`] (`sdfl_gradient`): central differences per voxel, one-sided
//!   at the border, in world units (f64 here, f32 on the device);
//! - [`curvature`] (`sdfl_curvature`): Hessian from central differences of
//!   the trilinearly sampled gradient at distance h (world units, converted
//!   per axis to grid units), principal curvatures and direction in the
//!   tangent plane ([`principal`]);
//! - [`range`] (`sdfl_range`): κ1 min/max over the seeds;
//! - [`trace`] (`sdfl_trace`): RK4 along d1 both ways ([`rk4_step`]), Newton
//!   projection after each step, stop at the stroke's length, umbilic points,
//!   the volume's border or an undefined curvature;
//! - [`strips`] (`sdfl_strips`): tapered triangle strips.
//!
//! [`run`] chains them like the device's `SdfLines::run`.

use crate::cpu::marching_cubes::{grid_gradient, mc_vertex};
use crate::error::Result;
use crate::spec::sdf_lines::*;
// The host steps the device stage shares, under the twin's names too.
pub use crate::spec::sdf_lines::{
    DenseSample, Principal, cell_count, cells_overflow, check_points, dense_overflow, stats,
};
use crate::volume::Volume;
use std::time::Instant;

use super::vec3::{V3, add, cross, dot, len, scale, sub};

fn normalize(a: V3) -> Option<V3> {
    let l = len(a);
    (l > 0.0 && l.is_finite()).then(|| scale(a, 1.0 / l))
}
fn finite(a: V3) -> bool {
    a.iter().all(|c| c.is_finite())
}

/// The per-sample random priority of the thinning: an integer hash of the
/// sample's edge key and the seed (the same mix as the kernel's).
pub fn priority(key: u32, seed: u32) -> u32 {
    let mut h = key ^ seed.wrapping_mul(0x9E37_79B9);
    h = (h ^ (h >> 16)).wrapping_mul(0x7FEB_352D);
    h = (h ^ (h >> 15)).wrapping_mul(0x846C_A68B);
    h ^ (h >> 16)
}

/// The kernels' parameter block for `vol` with the resolved parameters.
pub fn params(vol: &Volume, opts: &SdfLineOptions, r: &Resolved) -> SdflParams {
    params_for(vol.dims, vol.spacing, opts, r)
}

/// The volume's extent in world units from voxel 0 (`(n − 1) · spacing`).
pub fn extent(vol: &Volume) -> [f64; 3] {
    extent_of(vol.dims, vol.spacing)
}

/// Validates the volume and options and returns the dense bound.
pub fn check(vol: &Volume, opts: &SdfLineOptions) -> Result<usize> {
    check_for(vol.dims, opts)
}

/// True when the grid edge from `v0` to `v1` crosses iso: both finite and on
/// different sides (the marching-cubes inside bit `v < iso`).
pub fn crosses(v0: f32, v1: f32, iso: f32) -> bool {
    v0.is_finite() && v1.is_finite() && ((v0 < iso) != (v1 < iso))
}

/// `sdfl_dense`: one sample per crossed grid edge, in key order.
///
/// # Errors
///
/// [`Error::InvalidArgument`] when there are more than `bound` samples
/// (naming the count) or the volume has 2³² / 3 voxels or more.
pub fn dense(vol: &Volume, iso: f32, bound: usize) -> Result<Vec<DenseSample>> {
    check_dims(vol.dims)?;
    let [nx, ny, nz] = vol.dims;
    let sp = vol.spacing.map(|s| s as f32);
    let mut out = Vec::new();
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let g = [x, y, z];
                let lin = vol.index(x, y, z);
                for axis in 0..3 {
                    if g[axis] + 1 >= vol.dims[axis] {
                        continue;
                    }
                    let mut h = g;
                    h[axis] += 1;
                    let (v0, v1) = (vol.value(x, y, z), vol.value(h[0], h[1], h[2]));
                    if !crosses(v0, v1, iso) {
                        continue;
                    }
                    // Edge e = 4·axis of the cell at g runs from g along axis.
                    let v = mc_vertex(vol, iso, g, 4 * axis);
                    out.push(DenseSample {
                        p: [v.p[0] * sp[0], v.p[1] * sp[1], v.p[2] * sp[2]],
                        key: (3 * lin + axis) as u32,
                    });
                }
            }
        }
    }
    if out.len() > bound {
        return Err(dense_overflow(out.len(), bound));
    }
    Ok(out)
}

/// Poisson cell of a local position (f32, as the kernel computes it).
pub fn cell_of(p: [f32; 3], cell: f32, cells: [u32; 4]) -> usize {
    let c: [usize; 3] = std::array::from_fn(|a| {
        let q = (p[a] / cell).floor();
        (q.max(0.0) as usize).min(cells[a] as usize - 1)
    });
    c[0] + cells[0] as usize * (c[1] + cells[1] as usize * c[2])
}

/// Squared distance in f32 with the kernel's operation order (no fused
/// multiply-add: the kernel file turns contraction off).
pub fn dist2(a: [f32; 3], b: [f32; 3]) -> f32 {
    let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    dx * dx + dy * dy + dz * dz
}

/// `sdfl_cell_*` + `sdfl_thin_phase` × 27 + `sdfl_thin_compact`: indices of
/// the kept samples, in cell order. The result depends only on the set of
/// samples (not their order): each cell takes the valid sample of highest
/// priority (ties: the smaller key).
///
/// # Errors
///
/// [`Error::InvalidArgument`] when the grid exceeds `max_cells`.
pub fn thin(samples: &[DenseSample], p: &SdflParams, max_cells: usize, r: f64) -> Result<Vec<u32>> {
    let ncell = cell_count(p, max_cells, r)?;
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); ncell];
    for (i, s) in samples.iter().enumerate() {
        lists[cell_of(s.p, p.cell, p.cells)].push(i as u32);
    }
    let mut kept = vec![NONE; ncell];
    let [gx, gy, gz] = [p.cells[0] as i64, p.cells[1] as i64, p.cells[2] as i64];
    for phase in 0..27i64 {
        let (px, py, pz) = (phase % 3, phase / 3 % 3, phase / 9);
        for cz in (pz..gz).step_by(3) {
            for cy in (py..gy).step_by(3) {
                for cx in (px..gx).step_by(3) {
                    let c = (cx + gx * (cy + gy * cz)) as usize;
                    let mut best = NONE;
                    let mut best_pri = 0u32;
                    for &i in &lists[c] {
                        let s = samples[i as usize];
                        let pri = priority(s.key, p.seed);
                        let better = best == NONE
                            || pri > best_pri
                            || (pri == best_pri && s.key < samples[best as usize].key);
                        if !better {
                            continue;
                        }
                        let mut ok = true;
                        'n: for dz in -2..=2i64 {
                            for dy in -2..=2i64 {
                                for dx in -2..=2i64 {
                                    let (x, y, z) = (cx + dx, cy + dy, cz + dz);
                                    if x < 0 || y < 0 || z < 0 || x >= gx || y >= gy || z >= gz {
                                        continue;
                                    }
                                    let k = kept[(x + gx * (y + gy * z)) as usize];
                                    if k != NONE && dist2(samples[k as usize].p, s.p) < p.r2 {
                                        ok = false;
                                        break 'n;
                                    }
                                }
                            }
                        }
                        if ok {
                            best = i;
                            best_pri = pri;
                        }
                    }
                    kept[c] = best;
                }
            }
        }
    }
    Ok(kept.into_iter().filter(|&k| k != NONE).collect())
}

/// The gradient volume: per voxel, central differences in world units
/// (one-sided at the border, 0 along an axis of one sample), of the raw
/// values (the sign of `inside` is applied when sampling).
pub fn gradient(vol: &Volume) -> Vec<V3> {
    let d = vol.dims;
    let mut out = Vec::with_capacity(vol.voxel_count());
    for z in 0..d[2] {
        for y in 0..d[1] {
            for x in 0..d[0] {
                let g = [x, y, z];
                out.push(grid_gradient(vol, g));
            }
        }
    }
    out
}

/// Trilinear sampling weights at grid coordinates `g` (clamped to the grid):
/// the base voxel and the fractions.
fn tri_setup(dims: [usize; 3], g: V3) -> ([usize; 3], V3) {
    let mut b = [0usize; 3];
    let mut f = [0.0; 3];
    for a in 0..3 {
        let top = dims[a].saturating_sub(2);
        let c = g[a].clamp(0.0, (dims[a] - 1) as f64);
        b[a] = (c.floor() as usize).min(top);
        f[a] = (c - b[a] as f64).clamp(0.0, 1.0);
    }
    (b, f)
}

fn trilinear<T: Copy>(
    dims: [usize; 3],
    g: V3,
    get: impl Fn(usize) -> T,
    acc: impl Fn(&mut [f64; 3], T, f64),
) -> V3 {
    let (b, f) = tri_setup(dims, g);
    let mut s = [0.0; 3];
    for c in 0..8 {
        let o = [c & 1, (c >> 1) & 1, c >> 2];
        let i: [usize; 3] = std::array::from_fn(|a| (b[a] + o[a]).min(dims[a] - 1));
        let w: f64 = (0..3)
            .map(|a| if o[a] == 1 { f[a] } else { 1.0 - f[a] })
            .product();
        acc(&mut s, get(i[0] + dims[0] * (i[1] + dims[1] * i[2])), w);
    }
    s
}

/// Sampling of the field and its gradient at local world positions.
pub struct Field<'a> {
    vol: &'a Volume,
    grad: &'a [V3],
    iso: f64,
    sign: f64,
}

impl<'a> Field<'a> {
    /// A field over `vol` with its [`gradient`] volume.
    pub fn new(vol: &'a Volume, grad: &'a [V3], iso: f32, inside: Inside) -> Field<'a> {
        Field {
            vol,
            grad,
            iso: iso as f64,
            sign: if inside == Inside::Below { 1.0 } else { -1.0 },
        }
    }

    fn grid(&self, p: V3) -> V3 {
        std::array::from_fn(|a| p[a] / self.vol.spacing[a])
    }

    /// sign · (trilinear value − iso): negative inside.
    pub fn value(&self, p: V3) -> f64 {
        let v = trilinear(
            self.vol.dims,
            self.grid(p),
            |i| self.vol.values[i] as f64,
            |s, v, w| s[0] += w * v,
        );
        self.sign * (v[0] - self.iso)
    }

    /// sign · trilinear gradient (world units): points outward.
    pub fn grad(&self, p: V3) -> V3 {
        let g = trilinear(
            self.vol.dims,
            self.grid(p),
            |i| self.grad[i],
            |s, g, w| {
                for a in 0..3 {
                    s[a] += w * g[a];
                }
            },
        );
        scale(g, self.sign)
    }

    /// True when `p` lies in the volume's box (local world).
    pub fn inside_box(&self, p: V3) -> bool {
        (0..3).all(|a| p[a] >= 0.0 && p[a] <= (self.vol.dims[a] - 1) as f64 * self.vol.spacing[a])
    }

    /// The Hessian at `p` from central differences of [`Field::grad`] at
    /// ±h along each axis (world units; clamped to the box, dividing by the
    /// actual distance), symmetrised.
    pub fn hessian(&self, p: V3, h: f64) -> [[f64; 3]; 3] {
        let mut m = [[0.0; 3]; 3];
        for a in 0..3 {
            let top = (self.vol.dims[a] - 1) as f64 * self.vol.spacing[a];
            let (mut xp, mut xm) = (p, p);
            xp[a] = (p[a] + h).min(top);
            xm[a] = (p[a] - h).max(0.0);
            let span = xp[a] - xm[a];
            if span > 0.0 {
                let d = scale(sub(self.grad(xp), self.grad(xm)), 1.0 / span);
                for r in 0..3 {
                    m[r][a] = d[r];
                }
            }
        }
        for (r, c) in [(0, 1), (0, 2), (1, 2)] {
            let s = 0.5 * (m[r][c] + m[c][r]);
            m[r][c] = s;
            m[c][r] = s;
        }
        m
    }

    /// Principal curvatures and direction at `p` ([`principal`] of the
    /// gradient and the Hessian at distance h).
    pub fn curvature(&self, p: V3, h: f64) -> Principal {
        principal(self.grad(p), self.hessian(p, h))
    }
}

/// The tangent basis of unit normal `n`: `u = normalize(n × e)` with `e` the
/// axis least aligned with `n`, `v = n × u` (both unit: the Unity code's
/// unnormalised `u` scaled curvature by |u|²).
pub fn tangent_basis(n: V3) -> (V3, V3) {
    let a = (0..3)
        .min_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[a] = 1.0;
    let u = normalize(cross(n, e)).unwrap_or([1.0, 0.0, 0.0]);
    (u, cross(n, u))
}

/// Principal curvatures and direction from gradient `g` and Hessian `hm` of
/// the field (Kindlmann et al. 2003): the shape operator is
/// `G = P H P / |∇f|` with `P = I − n nᵀ`, `n = ∇f/|∇f|` pointing outward, so
/// convex is positive (Kindlmann's `−P H P/|∇f|` with the inward normal);
/// correct for any |∇f|, not just distances. In the tangent basis
/// ([`tangent_basis`]) `G` is the 2×2 `[[a, b], [b, c]]`; with `T = a + c`
/// and `F² = ‖G‖²_F = a² + 2b² + c²`, `κ1,2 = (T ± √(2F² − T²)) / 2`. The
/// eigenvector of κ1 is `(b, κ1 − a)` or `(κ1 − c, b)`, whichever is longer
/// (one of them is zero when `b = 0`); both vanish only at an umbilic or a
/// flat point, where d1 is `u` (defined, never NaN).
pub fn principal(g: V3, hm: [[f64; 3]; 3]) -> Principal {
    let len = len(g);
    let ok = len > 0.0 && len.is_finite() && hm.iter().flatten().all(|c| c.is_finite());
    if !ok {
        return Principal::default();
    }
    let n = scale(g, 1.0 / len);
    let (u, v) = tangent_basis(n);
    let hv = |x: V3| -> V3 { std::array::from_fn(|r| dot(hm[r], x)) };
    let (hu, hvv) = (hv(u), hv(v));
    let a = dot(u, hu) / len;
    let b = 0.5 * (dot(v, hu) + dot(u, hvv)) / len;
    let c = dot(v, hvv) / len;
    let t = a + c;
    let f2 = a * a + 2.0 * b * b + c * c;
    let d = (2.0 * f2 - t * t).max(0.0).sqrt();
    let (k1, k2) = (0.5 * (t + d), 0.5 * (t - d));
    let e1 = [b, k1 - a];
    let e2 = [k1 - c, b];
    let (n1, n2) = (e1[0] * e1[0] + e1[1] * e1[1], e2[0] * e2[0] + e2[1] * e2[1]);
    let e = if n1 >= n2 { e1 } else { e2 };
    let d1 = normalize(add(scale(u, e[0]), scale(v, e[1]))).unwrap_or(u);
    Principal {
        n,
        k1,
        k2,
        d1,
        valid: true,
    }
}

/// True where the principal direction is taken as undefined:
/// `|κ1 − κ2| < rel · (|κ1| + |κ2|) + abs`.
pub fn umbilic(c: &Principal, rel: f64, abs: f64) -> bool {
    (c.k1 - c.k2).abs() < rel * (c.k1.abs() + c.k2.abs()) + abs
}

/// One RK4 step of length `dt` from `p` along the direction field `dir`
/// (unit vectors, sign-free), every stage's sign aligned with `prev` (the
/// previous step's direction) and every stage sampled at its own point from
/// `p`: `k1 = d(p)`, `k2 = d(p + dt/2 k1)`, `k3 = d(p + dt/2 k2)`,
/// `k4 = d(p + dt k3)` (the Unity code sampled the last stage from an
/// already advanced point). `None` where the field is undefined.
pub fn rk4_step(p: V3, dt: f64, prev: V3, dir: impl Fn(V3) -> Option<V3>) -> Option<V3> {
    let align = |d: V3| {
        if dot(d, prev) < 0.0 {
            scale(d, -1.0)
        } else {
            d
        }
    };
    let k1 = align(dir(p)?);
    let k2 = align(dir(add(p, scale(k1, 0.5 * dt)))?);
    let k3 = align(dir(add(p, scale(k2, 0.5 * dt)))?);
    let k4 = align(dir(add(p, scale(k3, dt)))?);
    let s = add(add(k1, scale(add(k2, k3), 2.0)), k4);
    Some(add(p, scale(s, dt / 6.0)))
}

/// Newton projections of `p` onto the zero set: `p ← p − f ∇f / |∇f|²`.
pub fn project(field: &Field, p: V3, steps: u32) -> V3 {
    let mut p = p;
    for _ in 0..steps {
        let f = field.value(p);
        let g = field.grad(p);
        let g2 = dot(g, g);
        if !(g2 > 0.0 && g2.is_finite() && f.is_finite()) {
            break;
        }
        p = sub(p, scale(g, f / g2));
    }
    p
}

/// `sdfl_range`: κ1 min and max over the valid seeds ((0, 0) when none).
pub fn range(seeds: &[Principal]) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for s in seeds.iter().filter(|s| s.valid && s.k1.is_finite()) {
        lo = lo.min(s.k1);
        hi = hi.max(s.k1);
    }
    if lo > hi { (0.0, 0.0) } else { (lo, hi) }
}

/// The remap factor in [0, 1] of `k1` between `lo` and `hi` (1 when the
/// range is empty).
pub fn remap(k1: f64, lo: f64, hi: f64) -> f64 {
    if hi > lo {
        ((k1 - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// A traced stroke before the strips: points (local world), normals and
/// signed step indices (negative backward), with the seed's length and width.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Traced {
    /// Points from the backward end to the forward end.
    pub points: Vec<V3>,
    /// Outward unit normals.
    pub normals: Vec<V3>,
    /// Signed step index of each point (0 at the seed).
    pub k: Vec<i32>,
    /// Width at the seed.
    pub width: f64,
}

/// Steps each way for a seed of remap factor `t`.
pub fn steps_for(p: &SdflParams, t: f64) -> u32 {
    let len = p.length as f64 * (p.length_low as f64 + (1.0 - p.length_low as f64) * t);
    ((len / 2.0 / p.step as f64 + 0.5).floor() as u32).min(p.max_steps)
}

/// `sdfl_trace` for one seed at local position `p0` with curvature `c0`.
pub fn trace(field: &Field, p: &SdflParams, p0: V3, c0: &Principal, lo: f64, hi: f64) -> Traced {
    let t = remap(c0.k1, lo, hi);
    let width = p.width as f64 * (p.width_low as f64 + (1.0 - p.width_low as f64) * t);
    let mut out = Traced {
        points: vec![p0],
        normals: vec![c0.n],
        k: vec![0],
        width,
    };
    let (rel, abs) = (p.umbilic_rel as f64, p.umbilic_abs as f64);
    if !c0.valid || umbilic(c0, rel, abs) {
        return out;
    }
    let steps = steps_for(p, t);
    let (h, dt) = (p.h as f64, p.step as f64);
    let dir = |q: V3| {
        let c = field.curvature(q, h);
        (c.valid && finite(c.d1)).then_some(c.d1)
    };
    for side in [-1.0f64, 1.0] {
        let mut q = p0;
        let mut prev = scale(c0.d1, side);
        let mut pts = Vec::new();
        for k in 1..=steps {
            let Some(next) = rk4_step(q, dt, prev, dir) else {
                break;
            };
            let next = project(field, next, p.newton);
            if !finite(next) || !field.inside_box(next) {
                break;
            }
            let c = field.curvature(next, h);
            if !c.valid || umbilic(&c, rel, abs) {
                break;
            }
            let Some(d) = normalize(sub(next, q)) else {
                break;
            };
            prev = d;
            q = next;
            pts.push((next, c.n, side as i32 * k as i32));
        }
        if side < 0.0 {
            // Nearest first: each insert at the front pushes the earlier ones back.
            for (q, n, k) in pts {
                out.points.insert(0, q);
                out.normals.insert(0, n);
                out.k.insert(0, k);
            }
        } else {
            for (q, n, k) in pts {
                out.points.push(q);
                out.normals.push(n);
                out.k.push(k);
            }
        }
    }
    out
}

/// `sdfl_strips` for one stroke: widths (each half tapers as
/// `w · (1 − (k/K)²)` over its own `K` steps, so both ends are points) and
/// the strip vertices `p ∓ ½ w (n × t)`, t the central-difference tangent.
pub fn strips(tr: &Traced) -> (Vec<f64>, Vec<V3>) {
    let m = tr.points.len();
    let nb = tr.k.iter().filter(|&&k| k < 0).count() as f64;
    let nf = tr.k.iter().filter(|&&k| k > 0).count() as f64;
    let mut widths = Vec::with_capacity(m);
    let mut verts = Vec::with_capacity(2 * m);
    for j in 0..m {
        let k = tr.k[j] as f64;
        let s = if k < 0.0 {
            k / nb
        } else if k > 0.0 {
            k / nf
        } else {
            0.0
        };
        let w = tr.width * (1.0 - s * s).max(0.0);
        let a = tr.points[j.saturating_sub(1)];
        let b = tr.points[(j + 1).min(m - 1)];
        let n = tr.normals[j];
        let side = normalize(cross(n, sub(b, a))).unwrap_or_else(|| tangent_basis(n).0);
        let p = tr.points[j];
        widths.push(w);
        verts.push(sub(p, scale(side, 0.5 * w)));
        verts.push(add(p, scale(side, 0.5 * w)));
    }
    (widths, verts)
}

/// The whole family on the CPU, like `stages::sdf_lines::SdfLines::run`.
///
/// # Errors
///
/// Invalid options, or a bound exceeded (the message names the count).
pub fn run(vol: &Volume, opts: &SdfLineOptions) -> Result<SdfLinesOutput> {
    let t0 = Instant::now();
    let bound = check(vol, opts)?;
    let samples = dense(vol, opts.iso, bound)?;
    let grad = gradient(vol);
    let field = Field::new(vol, &grad, opts.iso, opts.inside);
    let local = |s: &DenseSample| s.p.map(|c| c as f64);
    let candidates = sampling_candidates(&opts.sampling, vol.spacing);
    let mut sweep = Vec::new();
    let h = if let Sampling::Fixed(h) = opts.sampling {
        h
    } else {
        let r0 = opts
            .spacing
            .unwrap_or(PROVISIONAL_SPACING_VOXELS * voxel_size(vol.spacing));
        let prov = resolve(opts, vol.spacing, candidates[0])?;
        let pp = params(
            vol,
            opts,
            &Resolved {
                spacing: r0,
                ..prov
            },
        );
        let kept = thin(&samples, &pp, opts.max_cells, r0)?;
        for &hc in &candidates {
            let (cv, n) = coefficient_of_variation(kept.iter().filter_map(|&i| {
                let c = field.curvature(local(&samples[i as usize]), hc);
                c.valid.then_some(c.k1)
            }));
            sweep.push(CvPoint {
                distance: hc,
                cv,
                seeds: n,
            });
        }
        pick_sampling(&sweep).unwrap_or(candidates[0])
    };
    let res = resolve(opts, vol.spacing, h)?;
    let p = params(vol, opts, &res);
    let kept = thin(&samples, &p, opts.max_cells, res.spacing)?;
    check_points(kept.len(), &res, opts.max_points)?;
    let curv: Vec<Principal> = kept
        .iter()
        .map(|&i| field.curvature(local(&samples[i as usize]), h))
        .collect();
    let (lo, hi) = range(&curv);
    let world = |q: V3| -> V3 { std::array::from_fn(|a| q[a] + vol.origin[a]) };
    let mut out = SdfLinesOutput::default();
    for (j, &i) in kept.iter().enumerate() {
        let q = local(&samples[i as usize]);
        let c = curv[j];
        out.seeds.push(Seed {
            p: world(q),
            n: c.n,
            k1: c.k1,
            k2: c.k2,
            d1: c.d1,
            valid: c.valid,
        });
        let tr = trace(&field, &p, q, &c, lo, hi);
        if tr.points.len() < 2 {
            continue;
        }
        let (widths, strip) = strips(&tr);
        out.strokes.push(Stroke {
            seed: j,
            centre: tr.k.iter().position(|&k| k == 0).unwrap_or(0),
            points: tr.points.iter().map(|&q| world(q)).collect(),
            normals: tr.normals.clone(),
            widths,
            strip: strip.into_iter().map(world).collect(),
        });
    }
    out.stats = stats(samples.len(), &out, res, sweep, lo, hi);
    out.stats.timing.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
    Ok(out)
}
