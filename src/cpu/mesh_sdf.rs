//! CPU reference of `kernels/mesh_sdf.cl`: a triangle mesh to a signed
//! distance field (negative inside), with the kernels' steps and names.
//!
//! Distance: exact point-triangle distance within [`BAND_VOXELS`](crate::spec::mesh_sdf::BAND_VOXELS) of the
//! surface ([`band`]: each triangle measures the voxels of its grown box),
//! jump flooding of nearest points beyond it ([`seed`], [`jfa`], Rong & Tan
//! 2006), and an exact pass that descends from each voxel's candidate
//! across edge-adjacent triangles ([`refine`]). Sign: the generalized winding number (Jacobson et al.
//! 2013) estimated from the six axis rays, whose signed crossing counts are
//! found per grid line by exact scan conversion ([`cross`], [`wind`]); see
//! the kernel file's header for why. The arithmetic is the kernels' `f32`,
//! in the same order, so the device matches this twin bit for bit (the
//! kernels are built with correctly rounded division and square root and no
//! contraction). The per-voxel passes run on all cores (scoped threads
//! over voxel ranges); the result does not depend on the split.

use crate::error::Result;
use crate::mesh::Mesh;
use crate::mesh::mesh_sdf::prepare;
use crate::spec::mesh_sdf::{
    FIX_BITS, FIX_ONE, MAX_DESCENT, MeshSdfOptions, NO_TRIANGLE, PreparedMesh, SdfGrid,
};
use crate::volume::Volume;

/// Mesh → signed distance field on the grid of
/// [`crate::mesh::mesh_sdf::prepare`] (world coordinates are the mesh's;
/// negative inside, positive outside, in world units).
///
/// # Errors
///
/// Those of [`prepare`]: a mesh without faces, a bad index, a non-finite
/// coordinate, only degenerate faces, a resolution out of range; and a
/// narrow band above its bound ([`PreparedMesh::band_work`]).
pub fn mesh_to_sdf(mesh: &Mesh, opts: &MeshSdfOptions) -> Result<Volume> {
    let prep = prepare(mesh, opts, "mesh")?;
    prep.band_work()?;
    let values = run(&prep);
    let g = prep.grid;
    Volume::new(g.dims, values, "mesh signed distance")?.with_geometry([g.spacing; 3], g.origin)
}

/// All steps on a prepared mesh: the field's samples (x fastest).
pub fn run(prep: &PreparedMesh) -> Vec<f32> {
    let g = &prep.grid;
    let (_, mut id) = band(prep);
    let mut q = seed(prep, &id);
    for step in g.steps() {
        (q, id) = jfa(prep, step, &q, &id);
    }
    let (dist, _) = refine(prep, &id);
    let mut winding = vec![0i32; g.voxels()];
    for axis in 0..3 {
        let diff = cross(prep, axis);
        wind(g, axis, &diff, &mut winding);
    }
    finish(g, &dist, &winding)
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2]
}

fn cross3(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn axpy(a: [f32; 3], e: [f32; 3], t: f32) -> [f32; 3] {
    [a[0] + e[0] * t, a[1] + e[1] * t, a[2] + e[2] * t]
}

fn d2(a: [f32; 3], b: [f32; 3]) -> f32 {
    let d = sub(a, b);
    dot(d, d)
}

// max then min, like the kernel's fmax/fmin (not clamp, whose NaN rule differs).
#[allow(clippy::manual_clamp)]
fn seg_t(ap: [f32; 3], e: [f32; 3]) -> f32 {
    let ee = dot(e, e);
    if ee > 0.0 {
        (dot(ap, e) / ee).max(0.0).min(1.0)
    } else {
        0.0
    }
}

/// Nearest point to `p` on triangle `(a, b, c)`: the projection onto the
/// plane when it falls inside (all three inward edge tests ≥ 0), else the
/// nearest point of the nearest edge (the first on ties). Degenerate
/// triangles fall to the edges.
pub fn tri_closest(p: [f32; 3], a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [f32; 3] {
    let (e0, e1, e2) = (sub(b, a), sub(c, b), sub(a, c));
    let (ap, bp, cp) = (sub(p, a), sub(p, b), sub(p, c));
    let n = cross3(e0, e1);
    let nn = dot(n, n);
    let inside = nn > 0.0
        && dot(cross3(n, e0), ap) >= 0.0
        && dot(cross3(n, e1), bp) >= 0.0
        && dot(cross3(n, e2), cp) >= 0.0;
    if inside {
        return axpy(p, n, -(dot(n, ap) / nn));
    }
    let q0 = axpy(a, e0, seg_t(ap, e0));
    let q1 = axpy(b, e1, seg_t(bp, e1));
    let q2 = axpy(c, e2, seg_t(cp, e2));
    let (d0, d1, d2v) = (d2(p, q0), d2(p, q1), d2(p, q2));
    let (mut q, mut d) = (q0, d0);
    if d1 < d {
        (q, d) = (q1, d1);
    }
    if d2v < d {
        q = q2;
    }
    q
}

/// Nearest point to grid point `p` on triangle `t` (grid units).
pub fn triangle_closest(prep: &PreparedMesh, p: [f32; 3], t: u32) -> [f32; 3] {
    let f = prep.triangles[t as usize];
    let [a, b, c] = f.map(|v| prep.grid_pos[v as usize]);
    tri_closest(p, a, b, c)
}

/// `(d, t)` replaces `(bd, bt)` when nearer, or as near with a smaller index.
fn better(d: f32, t: u32, bd: f32, bt: u32) -> bool {
    d < bd || (d == bd && t < bt)
}

fn coords(g: &SdfGrid, i: usize) -> [usize; 3] {
    let [nx, ny, _] = g.dims;
    [i % nx, (i / nx) % ny, i / (nx * ny)]
}

fn point(g: &SdfGrid, i: usize) -> [f32; 3] {
    coords(g, i).map(|c| c as f32)
}

/// Runs `f(i)` for every voxel `i` on all cores, in voxel ranges.
fn par_map<T: Send + Copy + Default>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let mut out = vec![T::default(); n];
    let threads = std::thread::available_parallelism().map_or(1, |t| t.get());
    let chunk = n.div_ceil(threads).max(1);
    std::thread::scope(|s| {
        for (c, part) in out.chunks_mut(chunk).enumerate() {
            let f = &f;
            s.spawn(move || {
                for (k, o) in part.iter_mut().enumerate() {
                    *o = f(c * chunk + k);
                }
            });
        }
    });
    out
}

/// `msdf_clear` + `msdf_band_min` + `msdf_band_id`: every triangle measures
/// the voxels of its box grown by [`BAND_VOXELS`](crate::spec::mesh_sdf::BAND_VOXELS); each voxel keeps the
/// smallest squared distance (voxels²) and the smallest triangle index at
/// it (`(inf, NO_TRIANGLE)` for a voxel no triangle measured). Exact
/// wherever the distance is within the band.
pub fn band(prep: &PreparedMesh) -> (Vec<f32>, Vec<u32>) {
    let g = &prep.grid;
    let [nx, ny, _] = g.dims;
    let mut dist = vec![f32::INFINITY; g.voxels()];
    let mut id = vec![NO_TRIANGLE; g.voxels()];
    for t in 0..prep.triangles.len() {
        let (lo, hi) = prep.voxel_range(t);
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let p = [x as f32, y as f32, z as f32];
                    let d = d2(p, triangle_closest(prep, p, t as u32));
                    let v = x + nx * (y + ny * z);
                    if better(d, t as u32, dist[v], id[v]) {
                        (dist[v], id[v]) = (d, t as u32);
                    }
                }
            }
        }
    }
    (dist, id)
}

/// `msdf_seed`: the nearest point (grid units) of each voxel's triangle
/// (infinite where there is none).
pub fn seed(prep: &PreparedMesh, id: &[u32]) -> Vec<[f32; 3]> {
    let g = &prep.grid;
    par_map(g.voxels(), |i| {
        if id[i] == NO_TRIANGLE {
            [f32::INFINITY; 3]
        } else {
            triangle_closest(prep, point(g, i), id[i])
        }
    })
}

/// Calls `f(v)` for the voxel `i` and its in-grid neighbours at ±`step`,
/// z slowest, x fastest (the kernels' order).
fn neighbours(g: &SdfGrid, i: usize, step: usize, mut f: impl FnMut(usize)) {
    let [nx, ny, nz] = g.dims.map(|d| d as i64);
    let [x, y, z] = coords(g, i).map(|c| c as i64);
    let s = step as i64;
    for dz in -1..=1 {
        let qz = z + dz * s;
        if qz < 0 || qz >= nz {
            continue;
        }
        for dy in -1..=1 {
            let qy = y + dy * s;
            if qy < 0 || qy >= ny {
                continue;
            }
            for dx in -1..=1 {
                let qx = x + dx * s;
                if qx < 0 || qx >= nx {
                    continue;
                }
                f((qx + nx * (qy + ny * qz)) as usize);
            }
        }
    }
}

/// `msdf_jfa`: one flooding pass with `step`: each voxel keeps the nearest
/// of its own point and those of its neighbours at ±`step` (point
/// distances; ties to the smaller triangle index).
pub fn jfa(
    prep: &PreparedMesh,
    step: usize,
    q: &[[f32; 3]],
    id: &[u32],
) -> (Vec<[f32; 3]>, Vec<u32>) {
    let g = &prep.grid;
    let pairs = par_map(g.voxels(), |i| {
        let p = point(g, i);
        let (mut bt, mut bq) = (id[i], q[i]);
        let mut bd = if bt == NO_TRIANGLE {
            f32::INFINITY
        } else {
            d2(p, bq)
        };
        neighbours(g, i, step, |v| {
            let t = id[v];
            if t == NO_TRIANGLE {
                return;
            }
            let d = d2(p, q[v]);
            if better(d, t, bd, bt) {
                (bd, bt, bq) = (d, t, q[v]);
            }
        });
        (bq, bt)
    });
    pairs.into_iter().unzip()
}

/// `msdf_refine`: the exact squared distance (voxels²) to the voxel's
/// candidate triangle, improved by a descent across edge-adjacent triangles
/// (at most [`MAX_DESCENT`] steps), and the triangle it ends on.
pub fn refine(prep: &PreparedMesh, id: &[u32]) -> (Vec<f32>, Vec<u32>) {
    let g = &prep.grid;
    let pairs = par_map(g.voxels(), |i| {
        let p = point(g, i);
        let mut bt = id[i];
        let mut bd = if bt == NO_TRIANGLE {
            f32::INFINITY
        } else {
            d2(p, triangle_closest(prep, p, bt))
        };
        let mut it = 0;
        while it < MAX_DESCENT && bt != NO_TRIANGLE {
            let from = bt;
            for t in prep.adjacent[from as usize] {
                if t == NO_TRIANGLE {
                    continue;
                }
                let d = d2(p, triangle_closest(prep, p, t));
                if better(d, t, bd, bt) {
                    (bd, bt) = (d, t);
                }
            }
            if bt == from {
                break;
            }
            it += 1;
        }
        (bd, bt)
    });
    pairs.into_iter().unzip()
}

/// The top-left rule as a symbolic perturbation of the grid point by
/// `(ε, ε²)` in `(u, v)`: whether a point with edge function `e` on the edge
/// with direction `(du, dv)` belongs to the triangle.
fn owns(e: i64, du: i64, dv: i64) -> bool {
    e > 0 || (e == 0 && (dv < 0 || (dv == 0 && du > 0)))
}

/// `msdf_cross`: for the grid lines along `axis`, `+1`/`-1` (the sign of the
/// triangle's normal along `axis`) at the first voxel at or past each
/// crossing (`ceil` of the crossing coordinate, clamped to the line).
pub fn cross(prep: &PreparedMesh, axis: usize) -> Vec<i32> {
    let g = &prep.grid;
    let [nx, ny, _] = g.dims;
    let (ku, kv) = ((axis + 1) % 3, (axis + 2) % 3);
    let one = FIX_ONE;
    let mut diff = vec![0i32; g.voxels()];
    for f in &prep.triangles {
        let [va, mut vb, mut vc] = f.map(|v| v as usize);
        let q = |v: usize, k: usize| i64::from(prep.fixed[v][k]);
        let (au, av) = (q(va, ku), q(va, kv));
        let (mut bu, mut bv) = (q(vb, ku), q(vb, kv));
        let (mut cu, mut cv) = (q(vc, ku), q(vc, kv));
        let mut area = (bu - au) * (cv - av) - (bv - av) * (cu - au);
        if area == 0 {
            continue;
        }
        let mut s = 1;
        if area < 0 {
            (bu, bv, cu, cv) = (cu, cv, bu, bv);
            std::mem::swap(&mut vb, &mut vc);
            area = -area;
            s = -1;
        }
        let (xa, xb, xc) = (
            prep.fixed[va][axis] as f32,
            prep.fixed[vb][axis] as f32,
            prep.fixed[vc][axis] as f32,
        );
        let ar = area as f32;
        let (umin, umax) = (au.min(bu).min(cu), au.max(bu).max(cu));
        let (vmin, vmax) = (av.min(bv).min(cv), av.max(bv).max(cv));
        let j0 = (umin + one - 1) >> FIX_BITS;
        let j1 = (umax >> FIX_BITS).min(g.dims[ku] as i64 - 1);
        let k0 = (vmin + one - 1) >> FIX_BITS;
        let k1 = (vmax >> FIX_BITS).min(g.dims[kv] as i64 - 1);
        for k in k0..=k1 {
            let pv = k << FIX_BITS;
            for j in j0..=j1 {
                let pu = j << FIX_BITS;
                let eab = (bu - au) * (pv - av) - (bv - av) * (pu - au);
                let ebc = (cu - bu) * (pv - bv) - (cv - bv) * (pu - bu);
                let eca = (au - cu) * (pv - cv) - (av - cv) * (pu - cu);
                if !owns(eab, bu - au, bv - av)
                    || !owns(ebc, cu - bu, cv - bv)
                    || !owns(eca, au - cu, av - cv)
                {
                    continue;
                }
                let xf = ((ebc as f32 * xa + eca as f32 * xb) + eab as f32 * xc) / ar;
                let i = ((xf * (1.0 / one as f32)).ceil() as i64).clamp(0, g.dims[axis] as i64 - 1);
                let mut p = [0usize; 3];
                p[axis] = i as usize;
                p[ku] = j as usize;
                p[kv] = k as usize;
                diff[p[0] + nx * (p[1] + ny * p[2])] += s;
            }
        }
    }
    diff
}

/// `msdf_wind`: along each grid line of `axis`, adds `T − 2·C(i)` to
/// `winding` (`C(i)`: the sum of `diff` up to voxel `i`, minus the signed
/// crossing count of the ray towards −axis; `T − C(i)`: the count towards
/// +axis). After the three axes, `winding` is six times the six-ray mean.
pub fn wind(g: &SdfGrid, axis: usize, diff: &[i32], winding: &mut [i32]) {
    let stride = [1, g.dims[0], g.dims[0] * g.dims[1]];
    let (ku, kv) = ((axis + 1) % 3, (axis + 2) % 3);
    for k in 0..g.dims[kv] {
        for j in 0..g.dims[ku] {
            let base = j * stride[ku] + k * stride[kv];
            let line = (0..g.dims[axis]).map(|i| base + i * stride[axis]);
            let total: i32 = line.clone().map(|v| diff[v]).sum();
            let mut run = 0;
            for v in line {
                run += diff[v];
                winding[v] += total - 2 * run;
            }
        }
    }
}

/// `msdf_finish`: `±√d2 · spacing`, negative where the six-ray sum exceeds
/// 3 (a winding number above ½).
pub fn finish(g: &SdfGrid, d2: &[f32], winding: &[i32]) -> Vec<f32> {
    let h = g.spacing as f32;
    d2.iter()
        .zip(winding)
        .map(|(&d2, &w)| {
            let d = d2.sqrt() * h;
            if w > 3 { -d } else { d }
        })
        .collect()
}
