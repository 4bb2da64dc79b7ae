// feature_lines_curves.cl: the curvature line families of rtsc (Rusinkiewicz
// and DeCarlo) beside the contours of feature_lines.cl, in the same family.
// Host: src/stages/feature_lines_curves.rs; CPU twin with the same step
// names: src/cpu/feature_lines_curves.rs.
//   lines_pose   per vertex, once per pose: kmax (the principal curvature of
//                larger magnitude), emax (its derivative along its direction,
//                from dcurv), that direction; K = k1k2, H = (k1+k2)/2 and, for
//                Hermite placement, their gradients; with coherence, K's and
//                H's signs, and emax dmax's side, held within a band (signs
//                uint[V], evec float[3V])
//   lines_view   per vertex, once per view: the view-dependent curvature q1
//                and its direction t1 (Judd, Durand & Adelson 2007), v·dmax
//                and (k1² − k2²)(n·v) for principal highlights (DeCarlo &
//                Rusinkiewicz 2007), n·l for isophotes
//   lines_dt1q1  per vertex, once per view: D_t1 q1, q1's derivative along t1
//                measured across the faces around the vertex, projected
//   lines_curves per face: the segments of every requested family
// Ridges and valleys follow Ohtake, Belyaev & Seidel 2004 as rtsc draws them:
// zero crossings of emax where |kmax| is extremal. Apparent ridges are the
// same crossings of (D_t1 q1, t1) with q1 the largest eigenvalue of QᵀQ (a
// squared curvature, as in Judd et al.'s code), Judd's test (q1 increases
// towards the segment at every corner) and no back-face culling. The isoline
// families interpolate a per-vertex value's zero crossing on the face's
// edges: suggestive highlights (κr, cut where −sinθ D_w κr / (n·v) falls
// below its threshold, isoline.h), K = 0, H = 0, D_w κr = 0 (rtsc's: the zero
// set of sinθ D_w κr − t (n·v), t the suggestive-contour threshold) and
// isophotes.
// Buffers (V vertices, F faces, S segment capacity):
//   pos, nrm, d1, d2 float[3V]; k float[2V]; dk float[4V] (C111 C112 C122 C222)
//   ndv, kr, sc float[V]: lines_vertex's n·v, κr sin²θ and suggestive test
//   pose float[8V]: kmax emax dmax.xyz K H 0;  grad float[6V]: ∇K ∇H
//   view float[8V]: q1 t1.xyz v·dmax phtest n·l 0;  dt float[V]: D_t1 q1
//   off uint[V+1], ring uint[3F]: faces around each vertex (face·3 + corner)
//   bnd uint[F]: bit j set when edge (v[j], v[j+1]) has no other face
//   seg float[8S]: x0 y0 z0 x1 y1 z1 family strength; ends uint[4S]: the
//   sorted vertex pair of each endpoint's mesh edge ((v, v) at a vertex,
//   (0xffffffff, face) at a face centre, (LINE_FREE, face) where a test cut
//   the segment); counter uint[1]: all counted
// flags: bit 0 back-face culling, 1 the extremum / test checks, 2 fading,
// 3 Hermite placement of K = 0 and H = 0 (from grad), 4 of the suggestive
// highlights' κr = 0 (from gkr, lines_vertex's ∇(κr sin²θ), float[3V]).
// Thresholds (and sh_fade) arrive divided by the feature size (rv) or its
// square (ar, ph, sh, sc). held uint[F], near uint[V], next_held,
// next_near, low, birth: the coherence of isoline.h; held faces test
// ridges, valleys, apparent ridges and both highlights against their
// threshold times `low` (their strength too).

#define LF_RIDGES 2u
#define LF_VALLEYS 3u
#define LF_APPARENT 4u
#define LF_SUG_HL 5u
#define LF_PRIN_HL 6u
#define LF_ISOPHOTES 7u
#define LF_K_ZERO 8u
#define LF_H_ZERO 9u
#define LF_DWKR_ZERO 10u
#define LF_BOUNDARIES 11u
#define CENTER 0xffffffffu
#define Z3 ((float3)(0.0f))

inline float3 ld3(__global const float *a, uint i) { return vload3(i, a); }

__kernel void lines_pose(uint nv, __global const float *d1, __global const float *d2,
                         __global const float *k, __global const float *dk, uint grads,
                         __global float *pose, __global float *grad, __global uint *signs,
                         __global float *evec, uint sign_mode, float band_k, float band_h,
                         float band_e)
{
    GID_OR_RETURN(nv);
    const float k1 = k[2 * gid], k2 = k[2 * gid + 1];
    const float4 c = vload4(gid, dk);
    const float3 e1 = ld3(d1, gid), e2 = ld3(d2, gid);
    const bool first = fabs(k1) >= fabs(k2);
    const float3 dm = first ? e1 : e2;
    float em = first ? c.x : c.w;
    if (sign_mode != 0) {
        // The same for ridges and valleys: where |emax| is within its band,
        // emax dmax keeps the side of the previous frame's (dmax's sign is
        // the eigen solver's, so the vector is compared, not emax).
        const float3 t = em * dm, tp = vload3(gid, evec);
        if (sign_mode == 2 && fabs(em) < band_e && dot3s(t, tp) < 0.0f)
            em = -em;
        vstore3(em * dm, gid, evec);
    }
    pose[8 * gid] = first ? k1 : k2;
    pose[8 * gid + 1] = em;
    pose[8 * gid + 2] = dm.x;
    pose[8 * gid + 3] = dm.y;
    pose[8 * gid + 4] = dm.z;
    float kg = k1 * k2, km = 0.5f * (k1 + k2);
    if (sign_mode != 0) {
        // Coherence: a Schmitt trigger on the signs of K and H. Within the
        // band around 0, a vertex keeps the sign of the previous frame
        // (mode 2), so that a zero set does not wander with values that
        // only round or jitter about 0; mode 1 (a sequence's first frame)
        // only records the signs.
        const uint s = signs[gid];
        if (sign_mode == 2) {
            if (fabs(kg) < band_k && ((s & 1u) != 0) != (kg < 0.0f))
                kg = -kg;
            if (fabs(km) < band_h && ((s & 2u) != 0) != (km < 0.0f))
                km = -km;
        }
        signs[gid] = (kg < 0.0f ? 1u : 0u) | (km < 0.0f ? 2u : 0u);
    }
    pose[8 * gid + 5] = kg;
    pose[8 * gid + 6] = km;
    pose[8 * gid + 7] = 0.0f;
    if (grads) {
        // ∇k1 = C111 d1 + C112 d2, ∇k2 = C122 d1 + C222 d2.
        const float3 g1 = c.x * e1 + c.y * e2, g2 = c.z * e1 + c.w * e2;
        vstore3(k2 * g1 + k1 * g2, 2 * gid, grad);
        vstore3(0.5f * (g1 + g2), 2 * gid + 1, grad);
    }
}

__kernel void lines_view(uint nv, __global const float *pos, __global const float *nrm,
                         __global const float *d1, __global const float *d2,
                         __global const float *k, __global const float *pose,
                         __global const float *ndv, float ex, float ey, float ez, uint ortho,
                         float lx, float ly, float lz, __global float *view)
{
    GID_OR_RETURN(nv);
    const float3 p = ld3(pos, gid), eye = (float3)(ex, ey, ez);
    float3 v = ortho ? eye : eye - p;
    const float l = length(v);
    v = l > 0.0f ? v / l : (float3)(0.0f);
    const float3 e1 = ld3(d1, gid), e2 = ld3(d2, gid);
    const float k1 = k[2 * gid], k2 = k[2 * gid + 1], nd = ndv[gid];
    const float u = dot(v, e1), w = dot(v, e2), s2 = u * u + w * w;
    // The projected view direction, unit, in the (d1, d2) frame; looking
    // down the normal it is undefined, and sec θ − 1 = 0 removes it.
    const float inv = s2 > 1e-12f ? 1.0f / s2 : 0.0f;
    const float a = u * u * inv, b = u * w * inv, c = w * w * inv;
    const float sm1 = 1.0f / fmax(fabs(nd), 1e-4f) - 1.0f;
    const float q11 = k1 * (1.0f + sm1 * a), q12 = k1 * sm1 * b;
    const float q21 = k2 * sm1 * b, q22 = k2 * (1.0f + sm1 * c);
    const float m1 = q11 * q11 + q21 * q21, m12 = q11 * q12 + q21 * q22;
    const float m2 = q12 * q12 + q22 * q22;
    const float lam = 0.5f * (m1 + m2) + sqrt(0.25f * (m1 - m2) * (m1 - m2) + m12 * m12);
    // Eigenvector of QᵀQ for lam: the better conditioned of two forms.
    float tx = m12, ty = lam - m1;
    const float ox = lam - m2, oy = m12;
    if (ox * ox + oy * oy > tx * tx + ty * ty) {
        tx = ox;
        ty = oy;
    }
    const float tl = sqrt(tx * tx + ty * ty);
    if (tl > 0.0f) {
        tx /= tl;
        ty /= tl;
    } else {
        tx = 1.0f;
        ty = 0.0f;
    }
    const float3 t1 = tx * e1 + ty * e2;
    const float3 dm = vload3(0, pose + 8 * gid + 2);
    // q1 as rtsc (Judd et al.'s code) keeps it: the largest eigenvalue of
    // QᵀQ, the square of the view-dependent curvature's magnitude.
    view[8 * gid] = fmax(lam, 0.0f);
    view[8 * gid + 1] = t1.x;
    view[8 * gid + 2] = t1.y;
    view[8 * gid + 3] = t1.z;
    view[8 * gid + 4] = dot(v, dm);
    view[8 * gid + 5] = fabs(k1 * k1 - k2 * k2) * nd;
    view[8 * gid + 6] = dot(ld3(nrm, gid), (float3)(lx, ly, lz));
    view[8 * gid + 7] = 0.0f;
}

__kernel void lines_dt1q1(uint nv, __global const uint *faces, __global const float *pos,
                          __global const float *nrm, __global const uint *off,
                          __global const uint *ring, __global const float *view,
                          __global const float *ndv, __global float *dt)
{
    GID_OR_RETURN(nv);
    const float3 p0 = ld3(pos, gid);
    const float q0 = view[8 * gid];
    const float3 t1 = vload3(0, view + 8 * gid + 1);
    const float3 t2 = cross(ld3(nrm, gid), t1);
    const float p0t2 = dot(p0, t2), anv = fabs(ndv[gid]);
    float sum = 0.0f;
    uint n = 0;
    for (uint r = off[gid]; r < off[gid + 1] && n < 2; ++r) {
        const uint f = ring[r] / 3, c = ring[r] % 3;
        const uint i1 = faces[3 * f + (c + 1) % 3], i2 = faces[3 * f + (c + 2) % 3];
        const float3 p1 = ld3(pos, i1), p2 = ld3(pos, i2);
        // The point on the opposite edge whose offset from p0 lies along t1.
        const float a1 = dot(p1, t2), a2 = dot(p2, t2);
        const float w1 = (a2 - p0t2) / (a2 - a1);
        if (!(w1 >= 0.0f && w1 < 1.0f))
            continue;
        const float w2 = 1.0f - w1;
        const float3 q = w1 * p1 + w2 * p2;
        const float dist = dot(q - p0, t1) * anv;
        if (!(fabs(dist) > 0.0f))
            continue;
        sum += (w1 * view[8 * i1] + w2 * view[8 * i2] - q0) / dist;
        ++n;
    }
    dt[gid] = n == 2 ? 0.5f * sum : sum;
}

inline uint2 edge_of(uint a, uint b) { return (uint2)(min(a, b), max(a, b)); }

// Strength of a ridge-like end: |k| above the threshold, faded as rtsc.
inline float ridge_strength(float k, float thr, uint fade)
{
    const float x = fmax(k - thr, 0.0f);
    return fade ? (x + thr > 0.0f ? x / (x + thr) : 0.0f) : (x > 0.0f ? 1.0f : 0.0f);
}

// The weight of b on the edge a → b where e changes sign (|e| interpolation).
inline float ridge_w(float ea, float eb)
{
    const float s = fabs(ea) + fabs(eb);
    return s > 0.0f ? fabs(ea) / s : 0.5f;
}

// One ridge-like segment from the crossing on edge i0–i1 to the one on
// i1–i2 (or to the face centre). With `judd`, Judd et al.'s test of apparent
// ridges: the direction of increasing q1 (t0, t1, t2 at i0, i1, i2) points
// towards the segment at every corner, so the segment is a maximum.
inline uint ridge_segment(uint f, uint3 vi, float3 e, float3 kk, __global const float *pos,
                          float thr, uint fade, bool centre, uint fam, bool judd, float3 t0,
                          float3 t1, float3 t2, uint cap, __global float *seg,
                          __global uint *ends, volatile __global uint *counter)
{
    const float3 p0 = ld3(pos, vi.x), p1 = ld3(pos, vi.y), p2 = ld3(pos, vi.z);
    const float w10 = ridge_w(e.x, e.y);
    const float3 pa = p0 + w10 * (p1 - p0);
    const float ka = fabs(kk.x + w10 * (kk.y - kk.x));
    float3 pb;
    float kb;
    uint2 eb;
    if (centre) {
        pb = (p0 + p1 + p2) / 3.0f;
        kb = fabs(kk.x + kk.y + kk.z) / 3.0f;
        eb = (uint2)(CENTER, f);
    } else {
        const float w21 = ridge_w(e.y, e.z);
        pb = p1 + w21 * (p2 - p1);
        kb = fabs(kk.y + w21 * (kk.z - kk.y));
        eb = edge_of(vi.y, vi.z);
    }
    if (!(ka > thr) && !(kb > thr))
        return 0;
    if (judd) {
        // Towards i1 across the segment, in the face's plane.
        const float3 perp = cross(cross(p1 - p0, p2 - p0), pa - pb);
        if (!(dot(t0, perp) > 0.0f && dot(t1, perp) < 0.0f && dot(t2, perp) > 0.0f))
            return 0;
    }
    const float s = 0.5f * (ridge_strength(ka, thr, fade) + ridge_strength(kb, thr, fade));
    const uint2 ea = edge_of(vi.x, vi.y);
    emit(pa, pb, fam, s, (uint4)(ea, eb), cap, seg, ends, counter);
    return 1;
}

// Zero crossings of t_i = sgn·e_i·dir_i across the face (Ohtake et al.'s
// test as rtsc writes it), with the threshold on |k| and, with `test`, the
// extremum check: rtsc's lenient one for ridges and valleys (the direction
// at either end of a crossed edge points across it the right way), Judd et
// al.'s for apparent ridges (`judd`: every corner's direction points towards
// the segment). Returns the segments emitted.
inline uint ridge_face(uint f, uint3 v, float3 e, float3 t0, float3 t1, float3 t2, float3 kk,
                       __global const float *pos, uint test, float thr, uint fade, uint fam,
                       bool judd, uint cap, __global float *seg, __global uint *ends,
                       volatile __global uint *counter)
{
    bool z01 = dot(t0, t1) <= 0.0f, z12 = dot(t1, t2) <= 0.0f, z20 = dot(t2, t0) <= 0.0f;
    if ((uint)z01 + (uint)z12 + (uint)z20 < 2)
        return 0;
    const bool jt = judd && test;
    if (test && !judd) {
        const float3 p0 = ld3(pos, v.x), p1 = ld3(pos, v.y), p2 = ld3(pos, v.z);
        z01 = z01 && (dot(t0, p1 - p0) >= 0.0f || dot(t1, p1 - p0) <= 0.0f);
        z12 = z12 && (dot(t1, p2 - p1) >= 0.0f || dot(t2, p2 - p1) <= 0.0f);
        z20 = z20 && (dot(t2, p0 - p2) >= 0.0f || dot(t0, p0 - p2) <= 0.0f);
        if ((uint)z01 + (uint)z12 + (uint)z20 < 2)
            return 0;
    }
    const uint3 r1 = v.yzx, r2 = v.zxy;
    const float3 e1 = e.yzx, e2 = e.zxy, k1 = kk.yzx, k2 = kk.zxy;
    if (!z01)
        return ridge_segment(f, r1, e1, k1, pos, thr, fade, false, fam, jt, t1, t2, t0, cap, seg,
                             ends, counter);
    if (!z12)
        return ridge_segment(f, r2, e2, k2, pos, thr, fade, false, fam, jt, t2, t0, t1, cap, seg,
                             ends, counter);
    if (!z20)
        return ridge_segment(f, v, e, kk, pos, thr, fade, false, fam, jt, t0, t1, t2, cap, seg,
                             ends, counter);
    uint n = ridge_segment(f, r1, e1, k1, pos, thr, fade, true, fam, jt, t1, t2, t0, cap, seg,
                           ends, counter);
    n += ridge_segment(f, r2, e2, k2, pos, thr, fade, true, fam, jt, t2, t0, t1, cap, seg, ends,
                       counter);
    n += ridge_segment(f, v, e, kk, pos, thr, fade, true, fam, jt, t0, t1, t2, cap, seg, ends,
                       counter);
    return n;
}


// Zero crossing of f on the edge a → b (0 at a), linear.
inline float zero_linear(float fa, float fb)
{
    const float d = fa - fb;
    return clamp(d != 0.0f ? fa / d : 0.5f, 0.0f, 1.0f);
}

// The corner whose sign differs from the other two, or 3 when none does.
// As rtsc's draw_isolines, a face crosses zero only where some corner is
// above it and some below (corners at 0 with the others on one side draw
// nothing: no segment along an edge whose ends are both 0).
inline uint odd_corner(float3 f)
{
    if (!((f.x > 0.0f || f.y > 0.0f || f.z > 0.0f) && (f.x < 0.0f || f.y < 0.0f || f.z < 0.0f)))
        return 3;
    const bool s0 = f.x >= 0.0f, s1 = f.y >= 0.0f, s2 = f.z >= 0.0f;
    if (s0 == s1 && s1 == s2)
        return 3;
    return (s0 == s1) ? 2 : ((s0 == s2) ? 1 : 0);
}

inline float comp(float3 a, uint i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }
inline uint compu(uint3 a, uint i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }

// The zero-crossing segment of f on face v (odd corner c): its ends' edge
// parameters from corner c towards a = c+1 and b = c+2. With gradients
// (hermite; vertex i's at float3 index gstride·i + gsel of g), the cubic
// crossing; else linear.
inline float2 iso_params(uint3 v, float3 f, uint c, __global const float *pos,
                         __global const float *g, uint gstride, uint gsel, uint hermite)
{
    const uint a = (c + 1) % 3, b = (c + 2) % 3;
    const float fc = comp(f, c), fa = comp(f, a), fb = comp(f, b);
    if (!hermite)
        return (float2)(zero_linear(fc, fa), zero_linear(fc, fb));
    const uint ic = compu(v, c), ia = compu(v, a), ib = compu(v, b);
    const float3 pc = ld3(pos, ic), gc = ld3(g, gstride * ic + gsel);
    const float3 ea = ld3(pos, ia) - pc, eb = ld3(pos, ib) - pc;
    const float3 ga = ld3(g, gstride * ia + gsel), gb = ld3(g, gstride * ib + gsel);
    return (float2)(zero_hermite(fc, fa, dot(ea, gc), dot(ea, ga)),
                    zero_hermite(fc, fb, dot(eb, gc), dot(eb, gb)));
}

inline float3 lerp3(float3 a, float3 b, float t) { return a + t * (b - a); }

// The segment of an isoline family through face v at edge parameters tt
// from odd corner c.
inline uint iso_emit(uint3 v, uint c, float2 tt, __global const float *pos, uint fam, float s,
                     uint cap, __global float *seg, __global uint *ends,
                     volatile __global uint *counter)
{
    const uint a = (c + 1) % 3, b = (c + 2) % 3;
    const uint ic = compu(v, c), ia = compu(v, a), ib = compu(v, b);
    const float3 pc = ld3(pos, ic);
    emit(lerp3(pc, ld3(pos, ia), tt.x), lerp3(pc, ld3(pos, ib), tt.y), fam, s,
         (uint4)(edge_of(ic, ia), edge_of(ic, ib)), cap, seg, ends, counter);
    return 1;
}

inline float3 gather3(__global const float *a, uint stride, uint off, uint3 v)
{
    return (float3)(a[stride * v.x + off], a[stride * v.y + off], a[stride * v.z + off]);
}

__kernel void lines_curves(uint nf, __global const uint *faces, __global const float *pos,
                           __global const float *ndv, __global const float *kr,
                           __global const float *sc, __global const float *gkr,
                           __global const float *pose,
                           __global const float *grad, __global const float *view,
                           __global const float *dt, __global const uint *bnd, uint want,
                           uint flags, float rv_thr, float ar_thr, float ph_thr, float sh_thr,
                           float sc_thr, float sh_fade, uint iso_n, uint cap,
                           __global float *seg, __global uint *ends,
                           volatile __global uint *counter, __global const uint *held,
                           __global const uint *near, __global uint *next_held,
                           __global uint *next_near, float low, uint birth)
{
    GID_OR_RETURN(nf);
    const uint3 v = vload3(gid, faces);
    const uint hb = held[gid], nb = near[v.x] | near[v.y] | near[v.z];
    const uint may = may_draw(hb, nb, birth);
    uint drawn = 0;
    const uint cull = flags & 1u, test = (flags >> 1) & 1u, fade = (flags >> 2) & 1u;
    const uint hermite = (flags >> 3) & 1u, hermite_sh = (flags >> 4) & 1u;
    const float3 nd = gather3(ndv, 1, 0, v);
    const bool back = cull && nd.x <= 0.0f && nd.y <= 0.0f && nd.z <= 0.0f;
    if (want & (1u << LF_BOUNDARIES)) {
        // Boundaries are drawn whole (hidden parts are the renderer's).
        const uint m = bnd[gid];
        for (uint j = 0; j < 3; ++j) {
            if (!(m & (1u << j)))
                continue;
            const uint ia = compu(v, j), ib = compu(v, (j + 1) % 3);
            emit(ld3(pos, ia), ld3(pos, ib), LF_BOUNDARIES, 1.0f, (uint4)(ia, ia, ib, ib), cap,
                 seg, ends, counter);
            drawn |= 1u << LF_BOUNDARIES;
        }
    }
    if (want & (1u << LF_APPARENT)) {
        // No back-face culling, as in rtsc (apparent ridges reach contours
        // across faces that are just barely back-facing).
        const float3 q = gather3(view, 8, 0, v), e = gather3(dt, 1, 0, v);
        const float thr = held_thr(hb, LF_APPARENT, ar_thr, low);
        if (q.x > thr || q.y > thr || q.z > thr) {
            const float3 t0 = vload3(0, view + 8 * v.x + 1), t1 = vload3(0, view + 8 * v.y + 1);
            const float3 t2 = vload3(0, view + 8 * v.z + 1);
            if (ridge_face(gid, v, e, e.x * t0, e.y * t1, e.z * t2, q, pos, test, thr, fade,
                           unborn(may, LF_APPARENT), true, cap, seg, ends, counter))
                drawn |= 1u << LF_APPARENT;
        }
    }
    if (back) {
        mark_found(next_held, next_near, gid, v, hb, nb, drawn, may, birth);
        return;
    }
    if (want & ((1u << LF_RIDGES) | (1u << LF_VALLEYS))) {
        const float3 km = gather3(pose, 8, 0, v), em = gather3(pose, 8, 1, v);
        const float3 d0 = vload3(0, pose + 8 * v.x + 2), d1 = vload3(0, pose + 8 * v.y + 2);
        const float3 d2 = vload3(0, pose + 8 * v.z + 2);
        for (uint fam = LF_RIDGES; fam <= LF_VALLEYS; ++fam) {
            if (!(want & (1u << fam)))
                continue;
            // A ridge needs kmax > 0 at every corner, a valley kmax < 0.
            const float sg = fam == LF_RIDGES ? 1.0f : -1.0f;
            if (!(sg * km.x > 0.0f && sg * km.y > 0.0f && sg * km.z > 0.0f))
                continue;
            if (ridge_face(gid, v, em, sg * em.x * d0, sg * em.y * d1, sg * em.z * d2, km, pos,
                           test, held_thr(hb, fam, rv_thr, low), fade, unborn(may, fam), false,
                           cap, seg, ends, counter))
                drawn |= 1u << fam;
        }
    }
    if (want & (1u << LF_PRIN_HL)) {
        const float3 km = gather3(pose, 8, 0, v);
        float3 d[3];
        d[0] = vload3(0, pose + 8 * v.x + 2);
        d[1] = vload3(0, pose + 8 * v.y + 2);
        d[2] = vload3(0, pose + 8 * v.z + 2);
        // Orient the directions by the corner of largest |kmax|; give up
        // where they turn by more than 45°.
        uint r = 0;
        for (uint i = 1; i < 3; ++i)
            r = fabs(comp(km, i)) > fabs(comp(km, r)) ? i : r;
        float3 dots = gather3(view, 8, 4, v);
        bool ok = true;
        float sgn[3];
        for (uint i = 0; i < 3; ++i) {
            const float c = dot(d[i], d[r]);
            sgn[i] = c < 0.0f ? -1.0f : 1.0f;
            ok = ok && fabs(c) >= M_SQRT1_2_F;
        }
        dots *= (float3)(sgn[0], sgn[1], sgn[2]);
        const float3 tst = gather3(view, 8, 5, v);
        const float kmin = min(min(km.x, km.y), km.z), kmax = max(max(km.x, km.y), km.z);
        // Highlight ridges (kmax ≥ 0) and valleys (kmax ≤ 0); untested, once.
        const bool flavour = test ? (kmin >= 0.0f || kmax <= 0.0f) : true;
        const bool z01 = dots.x * dots.y <= 0.0f, z12 = dots.y * dots.z <= 0.0f;
        const bool z20 = dots.z * dots.x <= 0.0f;
        if (ok && flavour && (uint)z01 + (uint)z12 + (uint)z20 >= 2) {
            const float thr = held_thr(hb, LF_PRIN_HL, ph_thr, low);
            const uint fc = unborn(may, LF_PRIN_HL);
            uint n = 0;
            if (!z01)
                n = ridge_segment(gid, v.yzx, dots.yzx, tst.yzx, pos, thr, fade, false, fc, false,
                                  Z3, Z3, Z3, cap, seg, ends, counter);
            else if (!z12)
                n = ridge_segment(gid, v.zxy, dots.zxy, tst.zxy, pos, thr, fade, false, fc, false,
                                  Z3, Z3, Z3, cap, seg, ends, counter);
            else if (!z20)
                n = ridge_segment(gid, v, dots, tst, pos, thr, fade, false, fc, false, Z3, Z3, Z3,
                                  cap, seg, ends, counter);
            if (n)
                drawn |= 1u << LF_PRIN_HL;
        }
    }
    if (want & (1u << LF_SUG_HL)) {
        // κr = 0 where the suggestive test is negated (rtsc's suggestive
        // highlights): −sinθ D_w κr / (n·v) ≥ the threshold, cut at the
        // test's zero crossings and faded as suggestive contours.
        const float3 f = gather3(kr, 1, 0, v);
        const uint c = odd_corner(f);
        if (c < 3) {
            const float2 tt = iso_params(v, f, c, pos, gkr, 1, 0, hermite_sh);
            const uint a = (c + 1) % 3, b = (c + 2) % 3;
            const uint ic = compu(v, c), ia = compu(v, a), ib = compu(v, b);
            const float3 num = -gather3(sc, 1, 0, v) - held_thr(hb, LF_SUG_HL, sh_thr, low) * nd;
            const float n0 = comp(num, c) + tt.x * (comp(num, a) - comp(num, c));
            const float n1 = comp(num, c) + tt.y * (comp(num, b) - comp(num, c));
            const float d0 = comp(nd, c) + tt.x * (comp(nd, a) - comp(nd, c));
            const float d1 = comp(nd, c) + tt.y * (comp(nd, b) - comp(nd, c));
            const float3 pc = ld3(pos, ic);
            if (emit_tested(lerp3(pc, ld3(pos, ia), tt.x), lerp3(pc, ld3(pos, ib), tt.y),
                            edge_of(ic, ia), edge_of(ic, ib), gid, n0, n1, d0, d1, test, sh_fade,
                            unborn(may, LF_SUG_HL), cap, seg, ends, counter))
                drawn |= 1u << LF_SUG_HL;
        }
    }
    for (uint fam = LF_K_ZERO; fam <= LF_DWKR_ZERO; ++fam) {
        if (!(want & (1u << fam)))
            continue;
        const float3 f = fam == LF_K_ZERO   ? gather3(pose, 8, 5, v)
                         : fam == LF_H_ZERO ? gather3(pose, 8, 6, v)
                                            : gather3(sc, 1, 0, v) - sc_thr * nd;
        const uint c = odd_corner(f);
        if (c == 3)
            continue;
        const uint h = hermite && fam != LF_DWKR_ZERO;
        const float2 tt = iso_params(v, f, c, pos, grad, 2, fam == LF_K_ZERO ? 0 : 1, h);
        drawn |= iso_emit(v, c, tt, pos, unborn(may, fam), 1.0f, cap, seg, ends, counter) << fam;
    }
    if ((want & (1u << LF_ISOPHOTES)) && iso_n > 0) {
        // Levels n·l = j / N for |j| < N, as rtsc's lit and unlit isophotes.
        const float3 nl = gather3(view, 8, 6, v);
        const float n = (float)iso_n;
        const float lo = min(min(nl.x, nl.y), nl.z), hi = max(max(nl.x, nl.y), nl.z);
        const int j0 = max((int)floor(lo * n), 1 - (int)iso_n);
        const int j1 = min((int)ceil(hi * n), (int)iso_n - 1);
        for (int j = j0; j <= j1; ++j) {
            const float3 f = nl - (float)j / n;
            const uint c = odd_corner(f);
            if (c == 3)
                continue;
            drawn |= iso_emit(v, c, iso_params(v, f, c, pos, grad, 2, 0, 0), pos, LF_ISOPHOTES,
                              1.0f, cap, seg, ends, counter)
                     << LF_ISOPHOTES;
        }
    }
    mark_found(next_held, next_near, gid, v, hb, nb, drawn, may, birth);
}
