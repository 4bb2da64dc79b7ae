// sdf_lines.cl: curvature-directed strokes on a scalar volume (Interrante's
// strokes as run on the GPU by the *Curvature-Directed Rendering* write-up;
// curvature after Kindlmann et al. 2003). Host: src/stages/sdf_lines.rs;
// CPU twin with the same step names: src/cpu/sdf_lines.rs (f32 where results
// must match bit for bit: dense samples and thinning; f64 from the gradient on).
//
//   sdfl_dense          per grid point   a sample on each crossed grid edge (appended, counter, bound)
//   sdfl_cell_count     per sample       its Poisson cell; atomic count per cell
//   (scan.cl)                            cell offsets
//   sdfl_cell_fill      per sample       cell lists (order inside a cell is free: see thin_phase)
//   sdfl_thin_phase     per cell of one of the 27 phase groups (cx%3, cy%3, cz%3)
//   sdfl_thin_flags     per cell         1 where a seed was kept;  (scan.cl) seed offsets
//   sdfl_thin_compact   per cell         seeds in cell order (deterministic)
//   sdfl_gradient       per voxel        central differences, one-sided at the border (world units)
//   sdfl_curvature      per seed         normal, k1, k2, d1 from the Hessian at distance h
//   sdfl_range          per seed         k1 min/max with atomic_min/max on order-preserving keys
//   sdfl_trace          per seed         RK4 along d1 both ways, Newton projection
//   sdfl_strips         per stroke       tapered triangle strip (2 vertices per point)
//
// Buffers (N voxels, D dense samples (cap), C cells, S seeds, K = 2·max_steps + 1 slots per stroke):
//   vol float[N]; grad float[3N] (world units, raw values: the inside sign is applied when sampling)
//   pos float[3D] local world (world − origin); key uint[D] = 3·g + axis; counter uint[1]
//   cell uint[D], cell_count / cell_fill / cell_off uint[C], items uint[D], kept uint[C] (NONE = empty)
//   seeds uint[S], seed_pos float[3S], curv float[9S] (n.xyz, k1, k2, d1.xyz, valid)
//   range uint[2] (ordered keys of k1 min, max)
//   pts float[4SK] (xyz, signed step index), nrm float[4SK], meta uint[4S] (first, count, nb, nf),
//   wid float[S], nverts uint[S], voff uint[S]; strip float[4V] (xyz, width), overflow uint[1]
//
// Built with common/strict.h (no contraction, correctly rounded divide and
// square root), so distances and cell indices are exactly the CPU twin's.

#define NONE 0xFFFFFFFFu

// Mirrors spec::sdf_lines::SdflParams (112 bytes; checked by sdfl_probe).
typedef struct {
    uint dims[4];
    float spacing[4];
    uint cells[4];
    float iso, sign, h, step, cell, r2, umbilic_rel, umbilic_abs;
    float length, width, length_low, width_low;
    uint seed, max_steps, newton, pad;
} SdflParams;

__kernel void sdfl_probe(__global uint *out)
{
    out[0] = sizeof(SdflParams);
    out[1] = __builtin_offsetof(SdflParams, iso);
    out[2] = __builtin_offsetof(SdflParams, length);
    out[3] = __builtin_offsetof(SdflParams, seed);
}

// ---------------------------------------------------------------- dense samples

__kernel void sdfl_dense(uint n, __constant SdflParams *P, __global const float *vol, uint cap,
                         __global float *pos, __global uint *key,
                         volatile __global uint *counter)
{
    GID_OR_RETURN(n);
    const uint nx = P->dims[0], ny = P->dims[1];
    const uint g[3] = {gid % nx, (gid / nx) % ny, gid / (nx * ny)};
    const uint step[3] = {1u, nx, nx * ny};
    const float iso = P->iso;
    const float v0 = vol[gid];
    for (uint axis = 0; axis < 3; ++axis) {
        if (g[axis] + 1 >= P->dims[axis])
            continue;
        const float v1 = vol[gid + step[axis]];
        if (!(isfinite(v0) && isfinite(v1)) || ((v0 < iso) == (v1 < iso)))
            continue;
        const float t = mc_edge_t(v0, v1, iso);
        const uint slot = atomic_inc(&counter[0]);
        if (slot >= cap)
            continue;
        for (uint a = 0; a < 3; ++a) {
            const float c = a == axis ? (float)g[a] + t : (float)g[a];
            pos[3 * slot + a] = c * P->spacing[a];
        }
        key[slot] = 3 * gid + axis;
    }
}

// ---------------------------------------------------------------- Poisson-disk thinning

// Same integer mix as cpu::sdf_lines::priority.
inline uint sdfl_priority(uint key, uint seed)
{
    uint h = key ^ (seed * 0x9E3779B9u);
    h = (h ^ (h >> 16)) * 0x7FEB352Du;
    h = (h ^ (h >> 15)) * 0x846CA68Bu;
    return h ^ (h >> 16);
}

inline uint cell_of(__constant SdflParams *P, __global const float *pos, uint i)
{
    uint c[3];
    for (uint a = 0; a < 3; ++a) {
        const float q = floor(pos[3 * i + a] / P->cell);
        c[a] = min((uint)max(q, 0.0f), P->cells[a] - 1);
    }
    return c[0] + P->cells[0] * (c[1] + P->cells[1] * c[2]);
}

inline float dist2(__global const float *pos, uint i, uint j)
{
    const float dx = pos[3 * i] - pos[3 * j];
    const float dy = pos[3 * i + 1] - pos[3 * j + 1];
    const float dz = pos[3 * i + 2] - pos[3 * j + 2];
    return dx * dx + dy * dy + dz * dz;
}

__kernel void sdfl_cell_count(uint n, __constant SdflParams *P, __global const float *pos,
                              __global uint *cell, volatile __global uint *count)
{
    GID_OR_RETURN(n);
    const uint c = cell_of(P, pos, gid);
    cell[gid] = c;
    atomic_inc(&count[c]);
}

__kernel void sdfl_cell_fill(uint n, __global const uint *cell, __global const uint *off,
                             volatile __global uint *fill, __global uint *items)
{
    GID_OR_RETURN(n);
    const uint c = cell[gid];
    items[off[c] + atomic_inc(&fill[c])] = gid;
}

// One cell of phase group (px, py, pz): keeps its valid sample of highest
// priority (ties: smaller key), valid = farther than r from every seed kept
// in the 5×5×5 neighbourhood (r = √3 cells). Cells of one group are 3 apart
// on some axis, so none reads a cell another work-item of this launch writes:
// the result does not depend on the schedule, nor on the order of a cell's list.
__kernel void sdfl_thin_phase(uint n, __constant SdflParams *P, uint px, uint py, uint pz,
                              __global const float *pos, __global const uint *key,
                              __global const uint *off, __global const uint *count,
                              __global const uint *items, __global uint *kept)
{
    GID_OR_RETURN(n);
    const int gx = (int)P->cells[0], gy = (int)P->cells[1], gz = (int)P->cells[2];
    const uint nxp = (P->cells[0] - px + 2) / 3, nyp = (P->cells[1] - py + 2) / 3;
    const int cx = (int)(px + 3 * (gid % nxp));
    const int cy = (int)(py + 3 * ((gid / nxp) % nyp));
    const int cz = (int)(pz + 3 * (gid / (nxp * nyp)));
    if (cx >= gx || cy >= gy || cz >= gz)
        return;
    const uint c = (uint)(cx + gx * (cy + gy * cz));
    uint best = NONE, best_pri = 0, best_key = 0;
    const float r2 = P->r2;
    for (uint m = 0; m < count[c]; ++m) {
        const uint i = items[off[c] + m];
        const uint k = key[i];
        const uint pri = sdfl_priority(k, P->seed);
        if (!(best == NONE || pri > best_pri || (pri == best_pri && k < best_key)))
            continue;
        bool ok = true;
        for (int dz = -2; dz <= 2 && ok; ++dz)
            for (int dy = -2; dy <= 2 && ok; ++dy)
                for (int dx = -2; dx <= 2 && ok; ++dx) {
                    const int x = cx + dx, y = cy + dy, z = cz + dz;
                    if (x < 0 || y < 0 || z < 0 || x >= gx || y >= gy || z >= gz)
                        continue;
                    const uint kk = kept[x + gx * (y + gy * z)];
                    if (kk != NONE && dist2(pos, kk, i) < r2)
                        ok = false;
                }
        if (ok) {
            best = i;
            best_pri = pri;
            best_key = k;
        }
    }
    kept[c] = best;
}

__kernel void sdfl_thin_flags(uint n, __global const uint *kept, __global uint *flags)
{
    GID_OR_RETURN(n);
    flags[gid] = kept[gid] != NONE;
}

__kernel void sdfl_thin_compact(uint n, __global const uint *kept, __global const uint *off,
                                __global const float *pos, __global uint *seeds,
                                __global float *seed_pos)
{
    GID_OR_RETURN(n);
    const uint k = kept[gid];
    if (k == NONE)
        return;
    const uint s = off[gid];
    seeds[s] = k;
    for (uint a = 0; a < 3; ++a)
        seed_pos[3 * s + a] = pos[3 * k + a];
}

// ---------------------------------------------------------------- gradient

__kernel void sdfl_gradient(uint n, __constant SdflParams *P, __global const float *vol,
                            __global float *grad)
{
    GID_OR_RETURN(n);
    const uint nx = P->dims[0], ny = P->dims[1];
    const uint g[3] = {gid % nx, (gid / nx) % ny, gid / (nx * ny)};
    const uint step[3] = {1u, nx, nx * ny};
    for (uint a = 0; a < 3; ++a) {
        const uint lo = g[a] > 0 ? 1u : 0u, hi = g[a] + 1 < P->dims[a] ? 1u : 0u;
        float d = 0.0f;
        if (lo + hi > 0)
            d = (vol[gid + hi * step[a]] - vol[gid - lo * step[a]]) /
                ((float)(lo + hi) * P->spacing[a]);
        grad[3 * gid + a] = d;
    }
}

// ---------------------------------------------------------------- sampling and curvature

typedef struct {
    uint b[3];
    float f[3];
} Tri;

SC_INLINE Tri tri_setup(__constant SdflParams *P, const float *p)
{
    Tri t;
    for (uint a = 0; a < 3; ++a) {
        const uint d = P->dims[a];
        const uint top = d >= 2 ? d - 2 : 0;
        const float g = clamp(p[a] / P->spacing[a], 0.0f, (float)(d - 1));
        t.b[a] = min((uint)floor(g), top);
        t.f[a] = clamp(g - (float)t.b[a], 0.0f, 1.0f);
    }
    return t;
}

// sign · (trilinear value − iso) at local world p.
SC_INLINE float field_value(__constant SdflParams *P, __global const float *vol, const float *p)
{
    const Tri t = tri_setup(P, p);
    float s = 0.0f;
    for (uint c = 0; c < 8; ++c) {
        const uint o0 = c & 1, o1 = (c >> 1) & 1, o2 = c >> 2;
        const uint x = min(t.b[0] + o0, P->dims[0] - 1), y = min(t.b[1] + o1, P->dims[1] - 1),
                   z = min(t.b[2] + o2, P->dims[2] - 1);
        const float w = (o0 ? t.f[0] : 1.0f - t.f[0]) * (o1 ? t.f[1] : 1.0f - t.f[1]) *
                        (o2 ? t.f[2] : 1.0f - t.f[2]);
        s += w * vol[x + P->dims[0] * (y + P->dims[1] * z)];
    }
    return P->sign * (s - P->iso);
}

// sign · trilinear gradient (world units, outward) at local world p.
SC_INLINE void field_grad(__constant SdflParams *P, __global const float *grad, const float *p,
                          float *out)
{
    const Tri t = tri_setup(P, p);
    out[0] = out[1] = out[2] = 0.0f;
    for (uint c = 0; c < 8; ++c) {
        const uint o0 = c & 1, o1 = (c >> 1) & 1, o2 = c >> 2;
        const uint x = min(t.b[0] + o0, P->dims[0] - 1), y = min(t.b[1] + o1, P->dims[1] - 1),
                   z = min(t.b[2] + o2, P->dims[2] - 1);
        const float w = (o0 ? t.f[0] : 1.0f - t.f[0]) * (o1 ? t.f[1] : 1.0f - t.f[1]) *
                        (o2 ? t.f[2] : 1.0f - t.f[2]);
        const uint i = 3 * (x + P->dims[0] * (y + P->dims[1] * z));
        out[0] += w * grad[i];
        out[1] += w * grad[i + 1];
        out[2] += w * grad[i + 2];
    }
    for (uint a = 0; a < 3; ++a)
        out[a] *= P->sign;
}

typedef struct {
    float n[3];
    float k1, k2;
    float d1[3];
    bool valid;
} Principal;

// Principal curvatures and direction from gradient g and Hessian H (row
// major), as cpu::sdf_lines::principal: G = P H P / |g| in the unit tangent
// basis u = normalize(n × e_min), v = n × u; k = (T ± sqrt(2F² − T²)) / 2;
// eigenvector (b, k1 − a) or (k1 − c, b), the longer; u at umbilic points.
SC_INLINE Principal principal(const float *g, const float *H)
{
    Principal r;
    r.valid = false;
    r.k1 = r.k2 = 0.0f;
    for (uint a = 0; a < 3; ++a)
        r.n[a] = r.d1[a] = 0.0f;
    const float len = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    bool ok = len > 0.0f && isfinite(len);
    for (uint i = 0; i < 9; ++i)
        ok = ok && isfinite(H[i]);
    if (!ok)
        return r;
    const float n[3] = {g[0] / len, g[1] / len, g[2] / len};
    const float ax = fabs(n[0]), ay = fabs(n[1]), az = fabs(n[2]);
    const uint m = (ax <= ay && ax <= az) ? 0 : (ay <= az ? 1 : 2);
    const float e[3] = {m == 0 ? 1.0f : 0.0f, m == 1 ? 1.0f : 0.0f, m == 2 ? 1.0f : 0.0f};
    float u[3] = {n[1] * e[2] - n[2] * e[1], n[2] * e[0] - n[0] * e[2], n[0] * e[1] - n[1] * e[0]};
    const float ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (uint a = 0; a < 3; ++a)
        u[a] = ul > 0.0f ? u[a] / ul : (a == 0 ? 1.0f : 0.0f);
    const float v[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2],
                        n[0] * u[1] - n[1] * u[0]};
    float hu[3], hv[3];
    for (uint i = 0; i < 3; ++i) {
        hu[i] = H[3 * i] * u[0] + H[3 * i + 1] * u[1] + H[3 * i + 2] * u[2];
        hv[i] = H[3 * i] * v[0] + H[3 * i + 1] * v[1] + H[3 * i + 2] * v[2];
    }
    const float a = (u[0] * hu[0] + u[1] * hu[1] + u[2] * hu[2]) / len;
    const float b = 0.5f * ((v[0] * hu[0] + v[1] * hu[1] + v[2] * hu[2]) +
                            (u[0] * hv[0] + u[1] * hv[1] + u[2] * hv[2])) / len;
    const float c = (v[0] * hv[0] + v[1] * hv[1] + v[2] * hv[2]) / len;
    const float T = a + c;
    const float F2 = a * a + 2.0f * b * b + c * c;
    const float D = sqrt(max(2.0f * F2 - T * T, 0.0f));
    r.k1 = 0.5f * (T + D);
    r.k2 = 0.5f * (T - D);
    const float e1x = b, e1y = r.k1 - a, e2x = r.k1 - c, e2y = b;
    const bool first = e1x * e1x + e1y * e1y >= e2x * e2x + e2y * e2y;
    const float ex = first ? e1x : e2x, ey = first ? e1y : e2y;
    float d[3];
    for (uint i = 0; i < 3; ++i)
        d[i] = ex * u[i] + ey * v[i];
    const float dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const bool dok = dl > 0.0f && isfinite(dl);
    for (uint i = 0; i < 3; ++i) {
        r.n[i] = n[i];
        r.d1[i] = dok ? d[i] / dl : u[i];
    }
    r.valid = true;
    return r;
}

// Hessian at p from central differences of the sampled gradient at ±h along
// each axis (world units; clamped to the box, divided by the actual span),
// symmetrised; then principal().
SC_INLINE Principal curvature_at(__constant SdflParams *P, __global const float *grad,
                                 const float *p, float h)
{
    float H[9], g[3];
    for (uint a = 0; a < 3; ++a) {
        const float top = (float)(P->dims[a] - 1) * P->spacing[a];
        float xp[3] = {p[0], p[1], p[2]}, xm[3] = {p[0], p[1], p[2]};
        xp[a] = min(p[a] + h, top);
        xm[a] = max(p[a] - h, 0.0f);
        const float span = xp[a] - xm[a];
        float gp[3], gm[3];
        field_grad(P, grad, xp, gp);
        field_grad(P, grad, xm, gm);
        for (uint r = 0; r < 3; ++r)
            H[3 * r + a] = span > 0.0f ? (gp[r] - gm[r]) / span : 0.0f;
    }
    for (uint r = 0; r < 3; ++r)
        for (uint c = r + 1; c < 3; ++c) {
            const float s = 0.5f * (H[3 * r + c] + H[3 * c + r]);
            H[3 * r + c] = s;
            H[3 * c + r] = s;
        }
    field_grad(P, grad, p, g);
    return principal(g, H);
}

inline void store_principal(__global float *out, uint i, Principal c)
{
    for (uint a = 0; a < 3; ++a) {
        out[9 * i + a] = c.n[a];
        out[9 * i + 5 + a] = c.d1[a];
    }
    out[9 * i + 3] = c.k1;
    out[9 * i + 4] = c.k2;
    out[9 * i + 8] = c.valid ? 1.0f : 0.0f;
}

// Test probe: principal() of given gradients and Hessians.
__kernel void sdfl_principal_probe(uint n, __global const float *g, __global const float *H,
                                   __global float *out)
{
    GID_OR_RETURN(n);
    float gg[3], hh[9];
    for (uint a = 0; a < 3; ++a)
        gg[a] = g[3 * gid + a];
    for (uint a = 0; a < 9; ++a)
        hh[a] = H[9 * gid + a];
    store_principal(out, gid, principal(gg, hh));
}

__kernel void sdfl_curvature(uint n, __constant SdflParams *P, __global const float *grad,
                             float h, __global const float *pts, __global float *curv)
{
    GID_OR_RETURN(n);
    const float p[3] = {pts[3 * gid], pts[3 * gid + 1], pts[3 * gid + 2]};
    store_principal(curv, gid, curvature_at(P, grad, p, h));
}

// ---------------------------------------------------------------- k1 range

// Order-preserving map of floats to uints (for atomic_min/max).
inline uint ordered(float f)
{
    const uint u = as_uint(f);
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

inline float unordered(uint k)
{
    return as_float((k & 0x80000000u) ? (k & 0x7FFFFFFFu) : ~k);
}

__kernel void sdfl_range(uint n, __global const float *curv, volatile __global uint *range)
{
    GID_OR_RETURN(n);
    const float k1 = curv[9 * gid + 3];
    if (curv[9 * gid + 8] == 0.0f || !isfinite(k1))
        return;
    atomic_min(&range[0], ordered(k1));
    atomic_max(&range[1], ordered(k1));
}

// ---------------------------------------------------------------- tracing

inline bool umbilic(Principal c, __constant SdflParams *P)
{
    return fabs(c.k1 - c.k2) < P->umbilic_rel * (fabs(c.k1) + fabs(c.k2)) + P->umbilic_abs;
}

// d1 at q with its sign aligned with prev; false where undefined.
SC_INLINE bool stage(__constant SdflParams *P, __global const float *grad, const float *q,
                     const float *prev, float *k)
{
    const Principal c = curvature_at(P, grad, q, P->h);
    if (!c.valid)
        return false;
    const float s = c.d1[0] * prev[0] + c.d1[1] * prev[1] + c.d1[2] * prev[2] < 0.0f ? -1.0f
                                                                                      : 1.0f;
    for (uint a = 0; a < 3; ++a)
        k[a] = s * c.d1[a];
    return isfinite(k[0]) && isfinite(k[1]) && isfinite(k[2]);
}

inline float remap(float k1, float lo, float hi)
{
    return hi > lo ? clamp((k1 - lo) / (hi - lo), 0.0f, 1.0f) : 1.0f;
}

__kernel void sdfl_trace(uint n, __constant SdflParams *P, __global const float *vol,
                         __global const float *grad, __global const float *seed_pos,
                         __global const float *curv, __global const uint *range,
                         __global float *pts, __global float *nrm, __global uint *meta,
                         __global float *wid, __global uint *nverts)
{
    GID_OR_RETURN(n);
    const uint K = 2 * P->max_steps + 1, centre = P->max_steps;
    const ulong base = (ulong)gid * K;
    float lo = 0.0f, hi = 0.0f;
    if (range[0] <= range[1]) {
        lo = unordered(range[0]);
        hi = unordered(range[1]);
    }
    Principal c0;
    for (uint a = 0; a < 3; ++a) {
        c0.n[a] = curv[9 * gid + a];
        c0.d1[a] = curv[9 * gid + 5 + a];
    }
    c0.k1 = curv[9 * gid + 3];
    c0.k2 = curv[9 * gid + 4];
    c0.valid = curv[9 * gid + 8] != 0.0f;
    const float t = remap(c0.k1, lo, hi);
    wid[gid] = P->width * (P->width_low + (1.0f - P->width_low) * t);
    const float p0[3] = {seed_pos[3 * gid], seed_pos[3 * gid + 1], seed_pos[3 * gid + 2]};
    for (uint a = 0; a < 3; ++a) {
        pts[4 * (base + centre) + a] = p0[a];
        nrm[4 * (base + centre) + a] = c0.n[a];
    }
    pts[4 * (base + centre) + 3] = 0.0f;
    nrm[4 * (base + centre) + 3] = 0.0f;
    uint nside[2] = {0, 0};
    if (c0.valid && !umbilic(c0, P)) {
        const float len = P->length * (P->length_low + (1.0f - P->length_low) * t);
        const uint steps = min((uint)floor(len / 2.0f / P->step + 0.5f), P->max_steps);
        const float dt = P->step;
        for (uint side = 0; side < 2; ++side) {
            const float sgn = side == 0 ? -1.0f : 1.0f;
            float q[3] = {p0[0], p0[1], p0[2]};
            float prev[3] = {sgn * c0.d1[0], sgn * c0.d1[1], sgn * c0.d1[2]};
            uint k = 1;
            for (; k <= steps; ++k) {
                float k1[3], k2[3], k3[3], k4[3], x[3];
                if (!stage(P, grad, q, prev, k1))
                    break;
                for (uint a = 0; a < 3; ++a)
                    x[a] = q[a] + 0.5f * dt * k1[a];
                if (!stage(P, grad, x, prev, k2))
                    break;
                for (uint a = 0; a < 3; ++a)
                    x[a] = q[a] + 0.5f * dt * k2[a];
                if (!stage(P, grad, x, prev, k3))
                    break;
                for (uint a = 0; a < 3; ++a)
                    x[a] = q[a] + dt * k3[a];
                if (!stage(P, grad, x, prev, k4))
                    break;
                float nx[3];
                for (uint a = 0; a < 3; ++a)
                    nx[a] = q[a] + (k1[a] + 2.0f * (k2[a] + k3[a]) + k4[a]) * (dt / 6.0f);
                // Newton projection back onto the surface.
                for (uint it = 0; it < P->newton; ++it) {
                    const float f = field_value(P, vol, nx);
                    float g[3];
                    field_grad(P, grad, nx, g);
                    const float g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
                    if (!(g2 > 0.0f && isfinite(g2) && isfinite(f)))
                        break;
                    for (uint a = 0; a < 3; ++a)
                        nx[a] -= g[a] * (f / g2);
                }
                bool inbox = true;
                for (uint a = 0; a < 3; ++a)
                    inbox = inbox && isfinite(nx[a]) && nx[a] >= 0.0f &&
                            nx[a] <= (float)(P->dims[a] - 1) * P->spacing[a];
                if (!inbox)
                    break;
                const Principal c = curvature_at(P, grad, nx, P->h);
                if (!c.valid || umbilic(c, P))
                    break;
                const float d[3] = {nx[0] - q[0], nx[1] - q[1], nx[2] - q[2]};
                const float dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                if (!(dl > 0.0f && isfinite(dl)))
                    break;
                const ulong slot = base + (side == 0 ? centre - k : centre + k);
                for (uint a = 0; a < 3; ++a) {
                    prev[a] = d[a] / dl;
                    q[a] = nx[a];
                    pts[4 * slot + a] = nx[a];
                    nrm[4 * slot + a] = c.n[a];
                }
                pts[4 * slot + 3] = sgn * (float)k;
                nrm[4 * slot + 3] = 0.0f;
            }
            nside[side] = k - 1;
        }
    }
    const uint count = nside[0] + nside[1] + 1;
    meta[4 * gid] = centre - nside[0];
    meta[4 * gid + 1] = count;
    meta[4 * gid + 2] = nside[0];
    meta[4 * gid + 3] = nside[1];
    nverts[gid] = count >= 2 ? 2 * count : 0;
}

// ---------------------------------------------------------------- strips

// Two vertices per point, p ∓ ½ w (n × t), t the central-difference tangent;
// each half tapers as w · (1 − (k/K)²) over its own K steps.
__kernel void sdfl_strips(uint n, __constant SdflParams *P, __global const float *pts,
                          __global const float *nrm, __global const uint *meta,
                          __global const float *wid, __global const uint *nverts,
                          __global const uint *voff, uint cap, __global float *strip,
                          volatile __global uint *overflow)
{
    GID_OR_RETURN(n);
    const uint nv = nverts[gid];
    if (nv == 0)
        return;
    if (voff[gid] + nv > cap) {
        atomic_add(&overflow[0], nv);
        return;
    }
    const uint K = 2 * P->max_steps + 1;
    const ulong base = (ulong)gid * K + meta[4 * gid];
    const uint count = meta[4 * gid + 1];
    const float nb = (float)meta[4 * gid + 2], nf = (float)meta[4 * gid + 3];
    for (uint j = 0; j < count; ++j) {
        const ulong s = base + j, sa = base + (j > 0 ? j - 1 : 0),
                    sb = base + (j + 1 < count ? j + 1 : count - 1);
        const float k = pts[4 * s + 3];
        const float f = k < 0.0f ? k / nb : (k > 0.0f ? k / nf : 0.0f);
        const float w = wid[gid] * max(1.0f - f * f, 0.0f);
        float t[3], nn[3], side[3];
        for (uint a = 0; a < 3; ++a) {
            t[a] = pts[4 * sb + a] - pts[4 * sa + a];
            nn[a] = nrm[4 * s + a];
        }
        side[0] = nn[1] * t[2] - nn[2] * t[1];
        side[1] = nn[2] * t[0] - nn[0] * t[2];
        side[2] = nn[0] * t[1] - nn[1] * t[0];
        const float sl = sqrt(side[0] * side[0] + side[1] * side[1] + side[2] * side[2]);
        if (sl > 0.0f && isfinite(sl)) {
            for (uint a = 0; a < 3; ++a)
                side[a] /= sl;
        } else {
            side[0] = 1.0f;
            side[1] = side[2] = 0.0f;
        }
        const uint o = voff[gid] + 2 * j;
        for (uint a = 0; a < 3; ++a) {
            strip[4 * o + a] = pts[4 * s + a] - 0.5f * w * side[a];
            strip[4 * (o + 1) + a] = pts[4 * s + a] + 0.5f * w * side[a];
        }
        strip[4 * o + 3] = w;
        strip[4 * (o + 1) + 3] = w;
    }
}
