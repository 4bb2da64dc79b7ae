// mesh_sdf.cl: a triangle mesh to a signed distance field on a regular grid
// (negative inside). Host: src/stages/mesh_sdf.rs; CPU twin:
// src/cpu/mesh_sdf.rs; grid, snapping and constants: src/spec/mesh_sdf.rs.
//
// Distance: exact point-triangle distance. A spatial grid of triangles
// (cells of CELL voxels; a triangle is listed in every cell its bounding box
// grown by BAND voxels touches) makes it exact in a narrow band of BAND
// voxels around the surface; beyond it, jump flooding (Rong & Tan 2006, with
// one extra step-1 pass) propagates each voxel's nearest-triangle candidate,
// and every candidate's distance is again the exact point-triangle distance.
// Sign: the generalized winding number (Jacobson et al. 2013) is the mean
// over ray directions of the signed ray-crossing count; here it is estimated
// with the six axis directions ±x ±y ±z. Crossings are found per grid line
// for all voxels at once: each triangle is scan-converted onto the grid
// lines of each axis with exact 64-bit edge functions on fixed-point
// coordinates and a top-left tie rule, so a line through a shared edge or
// vertex is counted exactly once. On a closed mesh the estimate is the exact
// winding number; with a hole, a voxel is misjudged only if three of its six
// rays leave through holes.
//
//   msdf_bin_count  per triangle  count the cells its grown box touches
//   msdf_bin_fill   per triangle  append its index to those cells' lists
//   msdf_band       per voxel     nearest triangle among its cell's list
//   msdf_jfa        per voxel     one jump-flooding pass with step `step`
//   msdf_cross      per triangle  +-1 at the first voxel past each crossing
//   msdf_wind       per grid line prefix sums -> six-ray winding count
//   msdf_finish     per voxel     sign(winding) * distance * spacing
// Buffers (V vertices, T triangles, N voxels, M cells, E list entries):
//   pos float[3V] grid units; fix int[3V] fixed-point grid units (FIX per
//   voxel); tris uint[3T]; counts, offsets, cursor uint[M]; list uint[E];
//   d2 float[N] squared distance in voxels²; id uint[N] candidate triangle
//   (NO_TRI: none); diff int[N]; wind int[N] the sum over the six rays of
//   the signed crossing counts; out float[N].
// Built with -cl-fp32-correctly-rounded-divide-sqrt and contraction off, so
// the f32 arithmetic matches the CPU twin's bit for bit.

#pragma OPENCL FP_CONTRACT OFF

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

// Squared distance from p to the segment from a along e.
SC_INLINE float seg_d2(P3 ap, P3 e)
{
    const float ee = p3_dot(e, e);
    const float t = ee > 0.0f ? fmin(fmax(p3_dot(ap, e) / ee, 0.0f), 1.0f) : 0.0f;
    const P3 q = { e.x * t - ap.x, e.y * t - ap.y, e.z * t - ap.z };
    return p3_dot(q, q);
}

// Squared distance from p to triangle (a, b, c): the plane distance when p
// projects inside (all three inward edge tests >= 0), else the nearest edge.
SC_INLINE float tri_d2(P3 p, P3 a, P3 b, P3 c)
{
    const P3 e0 = p3_sub(b, a), e1 = p3_sub(c, b), e2 = p3_sub(a, c);
    const P3 ap = p3_sub(p, a), bp = p3_sub(p, b), cp = p3_sub(p, c);
    const P3 n = p3_cross(e0, e1);
    const float nn = p3_dot(n, n);
    const bool inside = nn > 0.0f && p3_dot(p3_cross(n, e0), ap) >= 0.0f &&
                        p3_dot(p3_cross(n, e1), bp) >= 0.0f && p3_dot(p3_cross(n, e2), cp) >= 0.0f;
    if (inside) {
        const float s = p3_dot(n, ap);
        return s * s / nn;
    }
    return fmin(fmin(seg_d2(ap, e0), seg_d2(bp, e1)), seg_d2(cp, e2));
}

SC_INLINE float tri_d2_id(P3 p, __global const uint *tris, __global const float *pos, uint t)
{
    return tri_d2(p, p3_load(pos, tris[3 * t]), p3_load(pos, tris[3 * t + 1]),
                  p3_load(pos, tris[3 * t + 2]));
}

// The cell range of triangle t's bounding box grown by `band` voxels.
SC_INLINE void cell_range(uint t, __global const uint *tris, __global const float *pos,
                          float band, float cell, int cx, int cy, int cz, int *lo, int *hi)
{
    const int cd[3] = { cx, cy, cz };
    for (int k = 0; k < 3; ++k) {
        const float a = pos[3 * tris[3 * t] + k], b = pos[3 * tris[3 * t + 1] + k],
                    c = pos[3 * tris[3 * t + 2] + k];
        const float mn = fmin(fmin(a, b), c), mx = fmax(fmax(a, b), c);
        lo[k] = clamp((int)floor((mn - band) / cell), 0, cd[k] - 1);
        hi[k] = clamp((int)floor((mx + band) / cell), 0, cd[k] - 1);
    }
}

__kernel void msdf_bin_count(uint ntri, __global const uint *tris, __global const float *pos,
                             float band, float cell, int cx, int cy, int cz,
                             __global uint *counts)
{
    GID_OR_RETURN(ntri);
    int lo[3], hi[3];
    cell_range(gid, tris, pos, band, cell, cx, cy, cz, lo, hi);
    for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x)
                atomic_inc(&counts[x + cx * (y + cy * z)]);
}

__kernel void msdf_bin_fill(uint ntri, __global const uint *tris, __global const float *pos,
                            float band, float cell, int cx, int cy, int cz,
                            __global const uint *offsets, __global uint *cursor,
                            __global uint *list)
{
    GID_OR_RETURN(ntri);
    int lo[3], hi[3];
    cell_range(gid, tris, pos, band, cell, cx, cy, cz, lo, hi);
    for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x) {
                const uint c = x + cx * (y + cy * z);
                list[offsets[c] + atomic_inc(&cursor[c])] = gid;
            }
}

// Candidate (d, t) replaces (bd, bt) when nearer, or as near with a smaller
// index: the result does not depend on list order or work-item schedule.
#define BETTER(d, t, bd, bt) ((d) < (bd) || ((d) == (bd) && (t) < (bt)))

__kernel void msdf_band(uint nvox, int nx, int ny, int cdiv, int cx, int cy,
                        __global const uint *counts, __global const uint *offsets,
                        __global const uint *list, __global const uint *tris,
                        __global const float *pos, __global float *d2, __global uint *id)
{
    GID_OR_RETURN(nvox);
    const int x = gid % nx, y = (gid / nx) % ny, z = gid / (nx * ny);
    const P3 p = { (float)x, (float)y, (float)z };
    const uint c = x / cdiv + cx * (y / cdiv + cy * (z / cdiv));
    const uint o = offsets[c], n = counts[c];
    float bd = INFINITY;
    uint bt = NO_TRI;
    for (uint k = 0; k < n; ++k) {
        const uint t = list[o + k];
        const float d = tri_d2_id(p, tris, pos, t);
        if (BETTER(d, t, bd, bt)) {
            bd = d;
            bt = t;
        }
    }
    d2[gid] = bd;
    id[gid] = bt;
}

__kernel void msdf_jfa(uint nvox, int nx, int ny, int nz, int step, float band2,
                       __global const float *d2_in, __global const uint *id_in,
                       __global float *d2_out, __global uint *id_out,
                       __global const uint *tris, __global const float *pos)
{
    GID_OR_RETURN(nvox);
    float bd = d2_in[gid];
    uint bt = id_in[gid];
    if (bd > band2) {
        const int x = gid % nx, y = (gid / nx) % ny, z = gid / (nx * ny);
        const P3 p = { (float)x, (float)y, (float)z };
        uint last = bt;
        for (int dz = -1; dz <= 1; ++dz) {
            const int qz = z + dz * step;
            if (qz < 0 || qz >= nz) continue;
            for (int dy = -1; dy <= 1; ++dy) {
                const int qy = y + dy * step;
                if (qy < 0 || qy >= ny) continue;
                for (int dx = -1; dx <= 1; ++dx) {
                    const int qx = x + dx * step;
                    if (qx < 0 || qx >= nx) continue;
                    const uint t = id_in[qx + nx * (qy + ny * qz)];
                    // Neighbours mostly share candidates: skip repeats.
                    if (t == NO_TRI || t == bt || t == last) continue;
                    last = t;
                    const float d = tri_d2_id(p, tris, pos, t);
                    if (BETTER(d, t, bd, bt)) {
                        bd = d;
                        bt = t;
                    }
                }
            }
        }
    }
    d2_out[gid] = bd;
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
