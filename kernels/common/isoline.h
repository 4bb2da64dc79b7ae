// isoline.h: what the two feature-line kernel files share: writing a
// segment, and rtsc's tested isolines (draw_face_isoline2 in Rusinkiewicz and
// DeCarlo's rtsc.cc): the segment where a per-vertex value crosses zero on a
// face is kept only where a test num / den holds (num and den interpolated
// linearly along it), cut at the test's zero crossings, with a fade
// num / (den·fade + num) at each end. CPU twin: `test_pieces`, `test_alpha`
// and `emit_tested` in src/cpu/feature_lines.rs.
// Segment buffers: seg float[8S] (x0 y0 z0 x1 y1 z1 family strength), ends
// uint[4S] (each end's mesh edge as a sorted vertex pair; (LINE_FREE, face)
// for an end inside a face, where a test cut the segment).

#define LINE_FREE 0xfffffffeu

// a · b summed in a fixed order (OpenCL's dot() may be rounded a GPU's own
// way; the twins sum x, y, z in this order).
inline float dot3s(float3 a, float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Zero crossing of the cubic Hermite interpolant with end values fa, fb and
// end derivatives da, db (per unit of the edge parameter), by bisection as
// rtsc: the middle root where the cubic has three in [0, 1].
inline float zero_hermite(float fa, float fb, float da, float db)
{
    if (fa == fb)
        return 0.5f;
    const float a = 2.0f * (fa - fb) + da + db, b = 3.0f * (fb - fa) - 2.0f * da - db;
    const float c = da, d = fa;
    float sl = 0.0f, sr = 1.0f, vl = fa;
    const float disc = 4.0f * b * b - 12.0f * a * c;
    if (disc > 0.0f && a != 0.0f) {
        const float q = sqrt(disc);
        const float r1 = (-2.0f * b + q) / (6.0f * a), r2 = (-2.0f * b - q) / (6.0f * a);
        if (r1 >= 0.0f && r1 <= 1.0f && r2 >= 0.0f && r2 <= 1.0f) {
            const float v1 = ((a * r1 + b) * r1 + c) * r1 + d;
            const float v2 = ((a * r2 + b) * r2 + c) * r2 + d;
            if ((v1 < 0.0f && v2 >= 0.0f) || (v1 > 0.0f && v2 <= 0.0f)) {
                sl = min(r1, r2);
                sr = max(r1, r2);
                vl = r1 < r2 ? v1 : v2;
            }
        }
    }
    for (uint it = 0; it < 10; ++it) {
        const float m = 0.5f * (sl + sr);
        const float vm = ((a * m + b) * m + c) * m + d;
        if ((vl < 0.0f && vm >= 0.0f) || (vl > 0.0f && vm <= 0.0f)) {
            sr = m;
        } else {
            sl = m;
            vl = vm;
        }
    }
    return 0.5f * (sl + sr);
}

// The gradient of κr sin²θ at a vertex (rtsc's `gradkr`), for the Hermite
// placement of suggestive contours and highlights: view direction vd (unit,
// towards the eye), n·v = c, the view vector's components uu, ww in the
// principal frame (e1, e2), curvatures k1, k2, derivative tensor cc =
// (C111, C112, C122, C222), and rlen = 1 / distance to the eye (0 when
// orthographic). 0 looking straight down the normal.
inline float3 grad_kr(float3 e1, float3 e2, float c, float uu, float ww, float k1, float k2,
                      float4 cc, float rlen)
{
    const float s2 = uu * uu + ww * ww;
    if (!(s2 > 1e-12f))
        return (float3)(0.0f);
    const float s = sqrt(s2), csc = 1.0f / s;
    const float u = uu * csc, v = ww * csc;
    const float krn = k1 * u * u + k2 * v * v, tr = u * v * (k2 - k1);
    const float kt = k1 * (1.0f - u * u) + k2 * (1.0f - v * v);
    const float3 w = u * e1 + v * e2, wp = u * e2 - v * e1;
    const float a1 = u * u * cc.x + 2.0f * u * v * cc.y + v * v * cc.z;
    const float a2 = u * u * cc.y + 2.0f * u * v * cc.z + v * v * cc.w;
    float3 g = a1 * e1 + a2 * e2;
    g = g - (2.0f * csc * tr) * (rlen * wp + c * (tr * w + kt * wp));
    g = g * s2;
    g = g - (2.0f * krn * s * c) * (krn * w + tr * wp);
    return g;
}

inline void emit(float3 a, float3 b, uint fam, float s, uint4 e, uint cap, __global float *seg,
                 __global uint *ends, volatile __global uint *counter)
{
    const uint o = atomic_inc(counter);
    if (o >= cap)
        return;
    vstore3(a, 0, seg + 8 * o);
    vstore3(b, 0, seg + 8 * o + 3);
    seg[8 * o + 6] = (float)fam;
    seg[8 * o + 7] = s;
    vstore4(e, o, ends);
}

// The parameters (in [0, 1] along the segment) of the pieces where the test
// holds: num and den of one sign (num ≥ 0 and den ≥ 0, or both < 0), with
// num and den linear between their end values. At most two pieces; returns
// their count.
inline uint test_pieces(float n0, float n1, float d0, float d1, float2 *piece)
{
    float z0 = 2.0f, z1 = 2.0f;
    uint nz = 0;
    if ((n0 >= 0.0f) != (n1 >= 0.0f)) {
        z0 = n0 / (n0 - n1);
        nz = 1;
    }
    if ((d0 >= 0.0f) != (d1 >= 0.0f)) {
        const float z = d0 / (d0 - d1);
        if (nz == 0) {
            z0 = z;
        } else if (z < z0) {
            z1 = z0;
            z0 = z;
        } else {
            z1 = z;
        }
        nz += 1;
    }
    bool valid = (n0 >= 0.0f) == (d0 >= 0.0f);
    float s = 0.0f;
    uint np = 0;
    for (uint i = 0; i <= nz; ++i) {
        const float e = i == nz ? 1.0f : (i == 0 ? z0 : z1);
        if (valid && e > s)
            piece[np++] = (float2)(s, e);
        s = e;
        valid = !valid;
    }
    return np;
}

// rtsc's fade of a tested line at a point: num / (den·fade + num), which is
// r / (r + fade) for r = num / den; 1 without a fade, in [0, 1].
inline float test_alpha(float num, float den, float fade)
{
    if (!(fade > 0.0f))
        return 1.0f;
    const float q = den * fade + num;
    const float a = q != 0.0f ? num / q : 0.0f;
    return a >= 0.0f ? fmin(a, 1.0f) : 0.0f;
}

// The segment pa → pb of face f (its ends on the mesh edges ea, eb), with
// the test's num and den at its ends: without the test the whole segment
// (strength 1), else its tested pieces, each with the mean of its ends'
// fades as its strength. Returns the pieces emitted.
inline uint emit_tested(float3 pa, float3 pb, uint2 ea, uint2 eb, uint f, float na, float nb,
                        float da, float db, uint test, float fade, uint fam, uint cap,
                        __global float *seg, __global uint *ends, volatile __global uint *counter)
{
    if (!test) {
        emit(pa, pb, fam, 1.0f, (uint4)(ea, eb), cap, seg, ends, counter);
        return 1;
    }
    float2 pc[2];
    const uint np = test_pieces(na, nb, da, db, pc);
    for (uint i = 0; i < np; ++i) {
        const float s0 = pc[i].x, s1 = pc[i].y;
        const float n0 = na + s0 * (nb - na), n1 = na + s1 * (nb - na);
        const float d0 = da + s0 * (db - da), d1 = da + s1 * (db - da);
        const float st = 0.5f * (test_alpha(n0, d0, fade) + test_alpha(n1, d1, fade));
        const uint2 e0 = s0 == 0.0f ? ea : (uint2)(LINE_FREE, f);
        const uint2 e1 = s1 == 1.0f ? eb : (uint2)(LINE_FREE, f);
        const float3 q0 = s0 == 0.0f ? pa : pa + s0 * (pb - pa);
        const float3 q1 = s1 == 1.0f ? pb : pa + s1 * (pb - pa);
        emit(q0, q1, fam, st, (uint4)(e0, e1), cap, seg, ends, counter);
    }
    return np;
}

// Coherence over the frames of one pose sequence (Canny's two thresholds,
// and a delay of births). The state, a bit per family (bit = family code):
//   held uint[F]  the families each face drew in the previous frame; such a
//                 face tests a family against its threshold times `low`
//                 (held faces only, not their neighbours: a line cannot
//                 creep along the surface from frame to frame);
//   near uint[V]  at each face's corners, the families it found in the
//                 previous frame (drawn or not; low 16 bits), and those it
//                 found there having found them around it the frame before
//                 too (high 16 bits: established).
// With `birth` = 1 (2), a face draws a family only where it held it, or
// where it was found around it in the previous frame (established there):
// a line that appears away from every line of its family is drawn from its
// second (third) frame, so that blips of one (two) frames are not drawn.
// Contours, isophotes and boundaries are never delayed. A face found but
// not drawn emits its segment with LINE_UNBORN added to its family, which
// the host drops. The next state: next_held (own word, no race), next_near
// (atomic or at the corners: the same bits whatever the order). All zero
// and birth 0 (the first frame, or no coherence): today's lines.
#define LINE_UNBORN 0x100u
#define LINE_UNGATED ((1u << 0) | (1u << 7) | (1u << 11))

inline float held_thr(uint bits, uint fam, float thr, float low)
{
    return ((bits >> fam) & 1u) ? thr * low : thr;
}

// The families face f may draw: all without a delay of births, else those
// it held, those found (established) around it, and the undelayed ones.
inline uint may_draw(uint held, uint near, uint birth)
{
    if (birth == 0)
        return 0xffffffffu;
    return held | (birth == 1 ? (near & 0xffffu) : (near >> 16)) | LINE_UNGATED;
}

// The family code a segment of `fam` is emitted with.
inline uint unborn(uint may, uint fam) { return ((may >> fam) & 1u) ? fam : fam | LINE_UNBORN; }

// Face f (corners v) found families `found`: the drawn ones are held next
// frame; the found ones, and those established, are marked at its corners.
inline void mark_found(__global uint *next_held, __global uint *next_near, uint f, uint3 v,
                       uint held, uint near, uint found, uint may, uint birth)
{
    const uint drawn = found & may;
    if (drawn)
        next_held[f] |= drawn;
    const uint est = birth == 0 ? found : found & ((near & 0xffffu) | held);
    const uint m = found | (est << 16);
    if (m) {
        atomic_or(&next_near[v.x], m);
        atomic_or(&next_near[v.y], m);
        atomic_or(&next_near[v.z], m);
    }
}
