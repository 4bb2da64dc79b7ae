// mesh_sdf.cl: a triangle mesh to a signed distance field on a regular grid
// (negative inside). Host: src/stages/mesh_sdf.rs; CPU twin:
// src/cpu/mesh_sdf.rs; grid, snapping and constants: src/spec/mesh_sdf.rs.
//
// Distance: exact point-triangle distance in a narrow band: each triangle
// measures every voxel of its bounding box grown by BAND voxels (atomic min
// of the squared distance, then of the triangle index among the nearest).
// Beyond it, jump flooding (Rong & Tan 2006) propagates each voxel's
// nearest surface point and its triangle, comparing plain point distances;
// a last pass measures each voxel's candidate triangle exactly and walks to
// edge-adjacent triangles while they are nearer (adj uint[3T]), which
// repairs the flooding's wrong candidates (on a sphere mesh the error is
// then the chordal error, see tests/mesh_sdf.rs).
// Sign: the generalized winding number (Jacobson et al. 2013), estimated
// with the six axis rays ±x ±y ±z; crossings are found per grid line for all
// voxels at once, each triangle scan-converted onto the grid lines of each
// axis (exact 64-bit edge functions on fixed-point coordinates, a top-left
// tie rule: a shared edge or vertex counts once). Exact on a closed mesh.
//
//   msdf_clear      per voxel     d2 = +inf, id = none
//   msdf_band_min   per triangle  atomic min of d2 over its grown box
//   msdf_band_id    per triangle  atomic min of its index where it is nearest
//   msdf_seed       per voxel     nearest point q of the voxel's triangle
//   msdf_jfa        per voxel     one flooding pass with step `step` on (q, id)
//   msdf_refine     per voxel     exact distance to its triangle, then descent
//                                 across edge-adjacent triangles
//   msdf_cross      per triangle  +-1 at the first voxel past each crossing
//   msdf_wind       per grid line prefix sums -> six-ray winding count
//   msdf_finish     per voxel     sign(winding) * distance * spacing
// Buffers (V vertices, T triangles, N voxels):
//   pos float[3V] grid units; fix int[3V] fixed-point grid units (FIX per
//   voxel); tris uint[3T]; d2 float[N] squared distance in voxels² (as uint
//   bits for the atomics: non-negative floats order like their bits);
//   id uint[N] triangle (NO_TRI: none); q float[3N] nearest point (grid
//   units); diff int[N]; wind int[N] the sum over the six rays of the
//   signed crossing counts; out float[N].
// Built with common/strict.h (contraction off, correctly rounded divide and
// square root), so the f32 arithmetic matches the CPU twin's bit for bit.

#define NO_TRI 0xffffffffu

typedef struct { float x, y, z; } P3;

SC_INLINE P3 p3_load(__global const float *pos, uint v)
{
    P3 r = { pos[3 * v], pos[3 * v + 1], pos[3 * v + 2] };
    return r;
}

SC_INLINE P3 p3_sub(P3 a, P3 b)
{
    P3 r = { a.x - b.x, a.y - b.y, a.z - b.z };
    return r;
}

SC_INLINE float p3_dot(P3 a, P3 b) { return (a.x * b.x + a.y * b.y) + a.z * b.z; }

SC_INLINE P3 p3_cross(P3 a, P3 b)
{
    P3 r = { a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x };
    return r;
}

SC_INLINE float seg_t(P3 ap, P3 e)
{
    const float ee = p3_dot(e, e);
    return ee > 0.0f ? fmin(fmax(p3_dot(ap, e) / ee, 0.0f), 1.0f) : 0.0f;
}

SC_INLINE P3 p3_axpy(P3 a, P3 e, float t)
{
    P3 r = { a.x + e.x * t, a.y + e.y * t, a.z + e.z * t };
    return r;
}

SC_INLINE float p3_d2(P3 a, P3 b)
{
    const P3 d = p3_sub(a, b);
    return p3_dot(d, d);
}

// Nearest point to p on triangle (a, b, c): the projection onto the plane
// when it falls inside (all three inward edge tests >= 0), else the nearest
// point of the nearest edge (first edge on ties). Degenerate triangles fall
// to the edges.
SC_INLINE P3 tri_closest(P3 p, P3 a, P3 b, P3 c)
{
    const P3 e0 = p3_sub(b, a), e1 = p3_sub(c, b), e2 = p3_sub(a, c);
    const P3 ap = p3_sub(p, a), bp = p3_sub(p, b), cp = p3_sub(p, c);
    const P3 n = p3_cross(e0, e1);
    const float nn = p3_dot(n, n);
    const bool inside = nn > 0.0f && p3_dot(p3_cross(n, e0), ap) >= 0.0f &&
                        p3_dot(p3_cross(n, e1), bp) >= 0.0f && p3_dot(p3_cross(n, e2), cp) >= 0.0f;
    if (inside) return p3_axpy(p, n, -(p3_dot(n, ap) / nn));
    const P3 q0 = p3_axpy(a, e0, seg_t(ap, e0));
    const P3 q1 = p3_axpy(b, e1, seg_t(bp, e1));
    const P3 q2 = p3_axpy(c, e2, seg_t(cp, e2));
    const float d0 = p3_d2(p, q0), d1 = p3_d2(p, q1), d2 = p3_d2(p, q2);
    P3 q = q0;
    float d = d0;
    if (d1 < d) { q = q1; d = d1; }
    if (d2 < d) q = q2;
    return q;
}

SC_INLINE P3 tri_closest_id(P3 p, __global const uint *tris, __global const float *pos, uint t)
{
    return tri_closest(p, p3_load(pos, tris[3 * t]), p3_load(pos, tris[3 * t + 1]),
                       p3_load(pos, tris[3 * t + 2]));
}

// The voxel range of triangle t's bounding box grown by `band` voxels.
SC_INLINE void voxel_range(uint t, __global const uint *tris, __global const float *pos,
                           float band, int nx, int ny, int nz, int *lo, int *hi)
{
    const int nd[3] = { nx, ny, nz };
    for (int k = 0; k < 3; ++k) {
        const float a = pos[3 * tris[3 * t] + k], b = pos[3 * tris[3 * t + 1] + k],
                    c = pos[3 * tris[3 * t + 2] + k];
        const float mn = fmin(fmin(a, b), c), mx = fmax(fmax(a, b), c);
        lo[k] = clamp((int)ceil(mn - band), 0, nd[k] - 1);
        hi[k] = clamp((int)floor(mx + band), 0, nd[k] - 1);
    }
}

__kernel void msdf_clear(uint nvox, __global uint *d2, __global uint *id)
{
    GID_OR_RETURN(nvox);
    d2[gid] = as_uint(INFINITY);
    id[gid] = NO_TRI;
}

__kernel void msdf_band_min(uint ntri, int nx, int ny, int nz, float band,
                            __global const uint *tris, __global const float *pos,
                            __global uint *d2)
{
    GID_OR_RETURN(ntri);
    int lo[3], hi[3];
    voxel_range(gid, tris, pos, band, nx, ny, nz, lo, hi);
    const P3 a = p3_load(pos, tris[3 * gid]), b = p3_load(pos, tris[3 * gid + 1]),
             c = p3_load(pos, tris[3 * gid + 2]);
    for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x) {
                const P3 p = { (float)x, (float)y, (float)z };
                const float d = p3_d2(p, tri_closest(p, a, b, c));
                atomic_min(&d2[x + nx * (y + ny * z)], as_uint(d));
            }
}

__kernel void msdf_band_id(uint ntri, int nx, int ny, int nz, float band,
                           __global const uint *tris, __global const float *pos,
                           __global const uint *d2, __global uint *id)
{
    GID_OR_RETURN(ntri);
    int lo[3], hi[3];
    voxel_range(gid, tris, pos, band, nx, ny, nz, lo, hi);
    const P3 a = p3_load(pos, tris[3 * gid]), b = p3_load(pos, tris[3 * gid + 1]),
             c = p3_load(pos, tris[3 * gid + 2]);
    for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x) {
                const P3 p = { (float)x, (float)y, (float)z };
                const uint v = x + nx * (y + ny * z);
                if (as_uint(p3_d2(p, tri_closest(p, a, b, c))) == d2[v]) atomic_min(&id[v], gid);
            }
}

__kernel void msdf_seed(uint nvox, int nx, int ny, __global const uint *id,
                        __global const uint *tris, __global const float *pos, __global float *q)
{
    GID_OR_RETURN(nvox);
    const int x = gid % nx, y = (gid / nx) % ny, z = gid / (nx * ny);
    const uint t = id[gid];
    P3 r = { INFINITY, INFINITY, INFINITY };
    if (t != NO_TRI) {
        const P3 p = { (float)x, (float)y, (float)z };
        r = tri_closest_id(p, tris, pos, t);
    }
    q[3 * gid] = r.x;
    q[3 * gid + 1] = r.y;
    q[3 * gid + 2] = r.z;
}

// Candidate (d, t) replaces (bd, bt) when nearer, or as near with a smaller
// index: the result does not depend on the order of the candidates.
#define BETTER(d, t, bd, bt) ((d) < (bd) || ((d) == (bd) && (t) < (bt)))

__kernel void msdf_jfa(uint nvox, int nx, int ny, int nz, int step,
                       __global const float *q_in, __global const uint *id_in,
                       __global float *q_out, __global uint *id_out)
{
    GID_OR_RETURN(nvox);
    const int x = gid % nx, y = (gid / nx) % ny, z = gid / (nx * ny);
    const P3 p = { (float)x, (float)y, (float)z };
    uint bt = id_in[gid];
    P3 bq = p3_load(q_in, gid);
    float bd = bt == NO_TRI ? INFINITY : p3_d2(p, bq);
    for (int dz = -1; dz <= 1; ++dz) {
        const int qz = z + dz * step;
        if (qz < 0 || qz >= nz) continue;
        for (int dy = -1; dy <= 1; ++dy) {
            const int qy = y + dy * step;
            if (qy < 0 || qy >= ny) continue;
            for (int dx = -1; dx <= 1; ++dx) {
                const int qx = x + dx * step;
                if (qx < 0 || qx >= nx) continue;
                const uint v = qx + nx * (qy + ny * qz);
                const uint t = id_in[v];
                if (t == NO_TRI) continue;
                const P3 c = p3_load(q_in, v);
                const float d = p3_d2(p, c);
                if (BETTER(d, t, bd, bt)) {
                    bd = d;
                    bt = t;
                    bq = c;
                }
            }
        }
    }
    q_out[3 * gid] = bq.x;
    q_out[3 * gid + 1] = bq.y;
    q_out[3 * gid + 2] = bq.z;
    id_out[gid] = bt;
}

__kernel void msdf_refine(uint nvox, int nx, int ny, int nz, __global const uint *id,
                          __global const uint *tris, __global const float *pos,
                          __global const uint *adj, uint max_descent,
                          __global float *d2, __global uint *id_out)
{
    GID_OR_RETURN(nvox);
    const int x = gid % nx, y = (gid / nx) % ny, z = gid / (nx * ny);
    const P3 p = { (float)x, (float)y, (float)z };
    uint bt = id[gid];
    float bd = bt == NO_TRI ? INFINITY : p3_d2(p, tri_closest_id(p, tris, pos, bt));
    // Descent across edge-adjacent triangles: on a smooth surface the
    // nearest triangle is next to a nearly nearest one.
    for (uint it = 0; it < max_descent && bt != NO_TRI; ++it) {
        const uint from = bt;
        for (int k = 0; k < 3; ++k) {
            const uint t = adj[3 * from + k];
            if (t == NO_TRI) continue;
            const float d = p3_d2(p, tri_closest_id(p, tris, pos, t));
            if (BETTER(d, t, bd, bt)) {
                bd = d;
                bt = t;
            }
        }
        if (bt == from) break;
    }
    d2[gid] = bd;
    id_out[gid] = bt;
}

// The top-left rule as a symbolic perturbation: a grid point on an edge
// counts as if moved by (ε, ε²) in (u, v); exactly one of two triangles
// sharing an edge (or one triangle of a fan around a vertex) then owns it.
SC_INLINE bool owns(long e, long du, long dv)
{
    return e > 0 || (e == 0 && (dv < 0 || (dv == 0 && du > 0)));
}

__kernel void msdf_cross(uint ntri, int axis, int nx, int ny, int nz, __global const uint *tris,
                         __global const int *fix, __global int *diff)
{
    GID_OR_RETURN(ntri);
    const int nd[3] = { nx, ny, nz };
    const int ku = (axis + 1) % 3, kv = (axis + 2) % 3;
    uint va = tris[3 * gid], vb = tris[3 * gid + 1], vc = tris[3 * gid + 2];
    const long au = fix[3 * va + ku], av = fix[3 * va + kv];
    long bu = fix[3 * vb + ku], bv = fix[3 * vb + kv];
    long cu = fix[3 * vc + ku], cv = fix[3 * vc + kv];
    long area = (bu - au) * (cv - av) - (bv - av) * (cu - au);
    if (area == 0) return; // edge-on: no line crosses it (symbolically)
    int s = 1;
    if (area < 0) { // make it counter-clockwise; the crossing sign is -1
        long tu = bu, tv = bv;
        bu = cu; bv = cv; cu = tu; cv = tv;
        uint tw = vb; vb = vc; vc = tw;
        area = -area;
        s = -1;
    }
    const float xa = (float)fix[3 * va + axis], xb = (float)fix[3 * vb + axis],
                xc = (float)fix[3 * vc + axis];
    const float ar = (float)area;
    const long one = 1L << SC_FIX_BITS;
    const long umin = min(min(au, bu), cu), umax = max(max(au, bu), cu);
    const long vmin = min(min(av, bv), cv), vmax = max(max(av, bv), cv);
    const int j0 = (int)((umin + one - 1) >> SC_FIX_BITS), j1 = min((int)(umax >> SC_FIX_BITS), nd[ku] - 1);
    const int k0 = (int)((vmin + one - 1) >> SC_FIX_BITS), k1 = min((int)(vmax >> SC_FIX_BITS), nd[kv] - 1);
    for (int k = k0; k <= k1; ++k) {
        const long pv = (long)k << SC_FIX_BITS;
        for (int j = j0; j <= j1; ++j) {
            const long pu = (long)j << SC_FIX_BITS;
            const long eab = (bu - au) * (pv - av) - (bv - av) * (pu - au);
            const long ebc = (cu - bu) * (pv - bv) - (cv - bv) * (pu - bu);
            const long eca = (au - cu) * (pv - cv) - (av - cv) * (pu - cu);
            if (!owns(eab, bu - au, bv - av) || !owns(ebc, cu - bu, cv - bv) ||
                !owns(eca, au - cu, av - cv))
                continue;
            const float xf = (((float)ebc * xa + (float)eca * xb) + (float)eab * xc) / ar;
            const int i = clamp((int)ceil(xf * (1.0f / (float)one)), 0, nd[axis] - 1);
            int q[3];
            q[axis] = i;
            q[ku] = j;
            q[kv] = k;
            atomic_add(&diff[q[0] + nx * (q[1] + ny * q[2])], s);
        }
    }
}

// One work-item per grid line along `axis`: C(i) = sum of diff up to i is
// minus the -axis ray's signed count, T - C(i) the +axis ray's (T: the
// line's total), so the pair adds T - 2 C(i) to the six-ray sum.
__kernel void msdf_wind(uint nlines, int axis, int nx, int ny, int nz,
                        __global const int *diff, __global int *wind)
{
    GID_OR_RETURN(nlines);
    const int nd[3] = { nx, ny, nz };
    const int stride[3] = { 1, nx, nx * ny };
    const int ku = (axis + 1) % 3, kv = (axis + 2) % 3;
    const int j = gid % nd[ku], k = gid / nd[ku];
    const int base = j * stride[ku] + k * stride[kv], st = stride[axis], n = nd[axis];
    int total = 0;
    for (int i = 0; i < n; ++i) total += diff[base + i * st];
    int run = 0;
    for (int i = 0; i < n; ++i) {
        run += diff[base + i * st];
        wind[base + i * st] += total - 2 * run;
    }
}

// Inside where the six-ray sum exceeds 3 (winding number above 1/2).
__kernel void msdf_finish(uint nvox, float h, __global const float *d2,
                          __global const int *wind, __global float *out)
{
    GID_OR_RETURN(nvox);
    const float d = sqrt(d2[gid]) * h;
    out[gid] = wind[gid] > 3 ? -d : d;
}
