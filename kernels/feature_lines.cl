// feature_lines.cl: occluding and suggestive contours extracted per face as
// line segments (DeCarlo et al. 2003, 2004; Griffin et al. 2012, §3.8). Host:
// src/stages/feature_lines.rs; CPU twin with the same step names:
// src/cpu/feature_lines.rs.
//   lines_vertex   per vertex  n·v, the radial curvature κr·sin²θ = k1u² + k2v²
//                              (u, v: the view vector in the (d1, d2) frame) and
//                              the suggestive-contour test num = sinθ·D_w κr =
//                              C(w,w,w)/|w|² − 2(n·v)τr²,  τr = (k2 − k1)uv/|w|²
//   lines_face     per face    zero crossings of n·v (contours) and of κr
//                              (suggestive), linearly interpolated on the face's
//                              edges, cut where rtsc's test fails (isoline.h)
// Buffers (V vertices, F faces, S segment capacity):
//   pos, nrm, d1, d2 float[3V]; k float[2V] (k1, k2); dk float[4V] (C111 C112 C122 C222)
//   ndv, kr, sc float[V] (lines_vertex output)
//   seg float[8S]: x0 y0 z0 x1 y1 z1, kind (0 contour, 1 suggestive), strength;
//   ends uint[4S] (isoline.h); counter uint[1]: segments found (all are
//   counted; only the first S written)
// Camera: eye (perspective) or, with ortho = 1, the constant direction `eye`
// towards the viewer. A vertex with n·v exactly 0 counts as front-facing.
// With the test (rtsc's defaults), contours keep their parts with κr ≥ 0
// and suggestive contours, on faces with a corner facing the viewer, their
// parts with sinθ·D_w κr / (n·v) ≥ `sc_thresh` (the threshold already
// divided by the square of the feature size on the host), each faded by
// r / (r + fade) (`fade` likewise scaled; 0: no fade). held uint[F], near
// uint[V], next_held, next_near, low, birth: the coherence of isoline.h
// (held faces test suggestive contours against sc_thresh·low).

inline void view_at(float px, float py, float pz, float ex, float ey, float ez, uint ortho,
                    float *vx, float *vy, float *vz)
{
    float x = ortho ? ex : ex - px, y = ortho ? ey : ey - py, z = ortho ? ez : ez - pz;
    const float l = sqrt(x * x + y * y + z * z);
    const float s = l > 0.0f ? 1.0f / l : 0.0f;
    *vx = x * s;
    *vy = y * s;
    *vz = z * s;
}

__kernel void lines_vertex(uint nv, __global const float *pos, __global const float *nrm,
                           __global const float *d1, __global const float *d2,
                           __global const float *k, __global const float *dk, float ex, float ey,
                           float ez, uint ortho, __global float *ndv, __global float *kr,
                           __global float *sc, uint hermite, __global float *gkr)
{
    GID_OR_RETURN(nv);
    float vx, vy, vz;
    view_at(pos[3 * gid], pos[3 * gid + 1], pos[3 * gid + 2], ex, ey, ez, ortho, &vx, &vy, &vz);
    const float nd = nrm[3 * gid] * vx + nrm[3 * gid + 1] * vy + nrm[3 * gid + 2] * vz;
    const float u = d1[3 * gid] * vx + d1[3 * gid + 1] * vy + d1[3 * gid + 2] * vz;
    const float v = d2[3 * gid] * vx + d2[3 * gid + 1] * vy + d2[3 * gid + 2] * vz;
    const float k1 = k[2 * gid], k2 = k[2 * gid + 1];
    const float u2 = u * u, v2 = v * v, w2 = u2 + v2;
    const float cwww = u2 * (u * dk[4 * gid] + 3.0f * v * dk[4 * gid + 1]) +
                       v2 * (3.0f * u * dk[4 * gid + 2] + v * dk[4 * gid + 3]);
    // Looking straight down the normal (|w| → 0) the radial direction is
    // undefined: no suggestive contour there (num = 0 fails the test).
    const float inv = w2 > 1e-12f ? 1.0f / w2 : 0.0f;
    const float tr = (k2 - k1) * u * v * inv;
    ndv[gid] = nd;
    kr[gid] = k1 * u2 + k2 * v2;
    sc[gid] = w2 > 1e-12f ? cwww * inv - 2.0f * nd * tr * tr : 0.0f;
    if (hermite) {
        const float3 p = vload3(gid, pos);
        const float3 dv = (float3)(ex, ey, ez) - p;
        const float dl = sqrt(dot3s(dv, dv));
        const float rlen = ortho ? 0.0f : (dl > 0.0f ? 1.0f / dl : 0.0f);
        vstore3(grad_kr(vload3(gid, d1), vload3(gid, d2), nd, u, v, k1, k2, vload4(gid, dk), rlen),
                gid, gkr);
    }
}

// Interpolation parameter of the zero crossing of f on the edge a → b.
inline float cross_t(float fa, float fb)
{
    const float d = fa - fb;
    const float t = d != 0.0f ? fa / d : 0.5f;
    return clamp(t, 0.0f, 1.0f);
}

__kernel void lines_face(uint nf, __global const uint *faces, __global const float *pos,
                         __global const float *ndv, __global const float *kr,
                         __global const float *sc, __global const float *gkr,
                         uint want_contours, uint want_suggestive, uint test, uint hermite,
                         float sc_thresh, float fade, uint cap, __global float *seg,
                         __global uint *ends, volatile __global uint *counter,
                         __global const uint *held, __global const uint *near,
                         __global uint *next_held, __global uint *next_near, float low,
                         uint birth)
{
    GID_OR_RETURN(nf);
    uint v[3];
    v[0] = faces[3 * gid];
    v[1] = faces[3 * gid + 1];
    v[2] = faces[3 * gid + 2];
    const uint3 v3 = (uint3)(v[0], v[1], v[2]);
    const uint hb = held[gid], nb = near[v[0]] | near[v[1]] | near[v[2]];
    const uint may = may_draw(hb, nb, birth);
    uint found = 0;
    for (uint kind = 0; kind < 2; ++kind) {
        if ((kind == 0 && !want_contours) || (kind == 1 && !want_suggestive))
            continue;
        float f[3];
        for (uint i = 0; i < 3; ++i)
            f[i] = kind == 0 ? ndv[v[i]] : kr[v[i]];
        // rtsc's draw_isolines: a face draws only where some corner is
        // above zero and some below (a corner at 0 alone crosses nothing).
        if (!((f[0] > 0.0f || f[1] > 0.0f || f[2] > 0.0f) &&
              (f[0] < 0.0f || f[1] < 0.0f || f[2] < 0.0f)))
            continue;
        // The corner whose sign differs from the other two.
        const bool s0 = f[0] >= 0.0f, s1 = f[1] >= 0.0f, s2 = f[2] >= 0.0f;
        if (s0 == s1 && s1 == s2)
            continue;
        // Suggestive contours: none on a face that faces away at every corner.
        if (kind == 1 && ndv[v[0]] <= 0.0f && ndv[v[1]] <= 0.0f && ndv[v[2]] <= 0.0f)
            continue;
        const uint c = (s0 == s1) ? 2 : ((s0 == s2) ? 1 : 0);
        const uint a = (c + 1) % 3, b = (c + 2) % 3;
        const float3 pc = vload3(v[c], pos), ea3 = vload3(v[a], pos) - pc;
        const float3 eb3 = vload3(v[b], pos) - pc;
        float ta, tb;
        if (kind == 1 && hermite) {
            // rtsc's use_hermite: the cubic through κr sin²θ and its gradient.
            const float3 gc = vload3(v[c], gkr);
            ta = zero_hermite(f[c], f[a], dot3s(ea3, gc), dot3s(ea3, vload3(v[a], gkr)));
            tb = zero_hermite(f[c], f[b], dot3s(eb3, gc), dot3s(eb3, vload3(v[b], gkr)));
        } else {
            ta = cross_t(f[c], f[a]);
            tb = cross_t(f[c], f[b]);
        }
        const float3 pa = pc + ta * ea3, pb = pc + tb * eb3;
        // The test at the segment's ends: contours keep κr ≥ 0 (num κr sin²θ,
        // den 1); suggestive contours num = sinθ D_w κr − t (n·v), den = n·v.
        float nc, na, nb, dc = 1.0f, da = 1.0f, db = 1.0f;
        if (kind == 0) {
            nc = kr[v[c]];
            na = kr[v[a]];
            nb = kr[v[b]];
        } else {
            dc = ndv[v[c]];
            da = ndv[v[a]];
            db = ndv[v[b]];
            const float t = held_thr(hb, 1, sc_thresh, low);
            nc = sc[v[c]] - t * dc;
            na = sc[v[a]] - t * da;
            nb = sc[v[b]] - t * db;
        }
        const float n0 = nc + ta * (na - nc), n1 = nc + tb * (nb - nc);
        const float d0 = dc + ta * (da - dc), d1 = dc + tb * (db - dc);
        // The mesh edges the two endpoints lie on, as sorted vertex pairs:
        // neighbouring faces give the same pair for a shared crossing, so
        // segments chain into polylines exactly, by edge.
        const uint2 ea = (uint2)(min(v[c], v[a]), max(v[c], v[a]));
        const uint2 eb = (uint2)(min(v[c], v[b]), max(v[c], v[b]));
        if (emit_tested(pa, pb, ea, eb, gid, n0, n1, d0, d1, test, kind == 0 ? 0.0f : fade,
                        unborn(may, kind), cap, seg, ends, counter))
            found |= 1u << kind;
    }
    mark_found(next_held, next_near, gid, v3, hb, nb, found, may, birth);
}
