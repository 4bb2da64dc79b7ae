// ao.cl: ambient occlusion from curvature (Griffin et al. 2012, §2.3, equations 10-12):
// the surface near a vertex is the quadric z = ½(κ1x² + κ2y²) along the
// normal, and AO is the cosine-weighted fraction of the hemisphere of radius R
// above it that the quadric does not block. Host: src/stages/ao.rs; CPU twin:
// src/cpu/ao.rs.
// Shared with the host (src/spec/ao.rs): the mode numbers (AoMode::code),
// AO_SAMPLES and its directions, the table side LUT_N and the table itself.
//
// Derivation used here (per tangent direction φ, normal curvature κ(φ) =
// k1cos²φ + k2sin²φ; our k are positive where the surface is convex with
// outward normals, i.e. bends away from the normal): with q = −κ(φ)R, a ray
// at polar angle θ meets the quadric inside the hemisphere when θ > θc, cosθc
// = q / (1 + √(1 + q²)) (q > 0; no occlusion for q ≤ 0). Integrating cosθ
// over the visible directions: AO = (1/2π) ∫ (1 − cos²θc(φ)) dφ, in [0, 1];
// 1 on a plane or a convex point, → 0 at the bottom of an ever sharper bowl.
// The radius is emulated by scaling the curvatures (q uses kR).
//   ao_vertex   per vertex   one of three accuracy levels (mode):
//     0 poly   Griffin et al.'s fit along the table's diagonal, s = (k1 + k2)R:
//              AO = 1.0 − 0.0022s² + 0.0776s + 0.7369 as quoted, clamped to [0, 1]
//     1 lut    bilinear lookup in an N×N table of the integral over
//              (t1, t2) = (x/(1+|x|)) of (k1R, k2R), built on the host
//     2 exact  the integral by the midpoint rule, 256 directions on [0, π/2]
//              (the integrand is even and π-periodic in φ)
// Buffers: k float[2V] (k1, k2); lut float[N·N]; dirs float[2·256]; ao float[V].
// Non-finite curvature gives AO = 1 (no information); huge curvatures stay
// finite (see visible()).

#define AO_SAMPLES 256

// Beyond 1e18, 1 + √(1 + q²) rounds to q in f32 (and q² would overflow).
inline float visible(float q)
{
    if (!(q > 0.0f))
        return 1.0f;
    const float c = q < 1e18f ? q / (1.0f + sqrt(1.0f + q * q)) : 1.0f;
    return 1.0f - c * c;
}

// dirs: (cos²φ, sin²φ) of the AO_SAMPLES midpoints, computed once on the host.
inline float ao_exact(float a, float b, __global const float *dirs)
{
    float sum = 0.0f;
    for (uint i = 0; i < AO_SAMPLES; ++i)
        sum += visible(-(a * dirs[2 * i] + b * dirs[2 * i + 1]));
    return sum / AO_SAMPLES;
}

inline float lut_coord(float x, uint n)
{
    const float t = x / (1.0f + fabs(x)); // (−1, 1)
    return clamp((t + 1.0f) * 0.5f * (float)(n - 1), 0.0f, (float)(n - 1));
}

__kernel void ao_vertex(uint nv, __global const float *k, float radius, uint mode,
                        __global const float *lut, uint n, __global const float *dirs,
                        __global float *ao)
{
    GID_OR_RETURN(nv);
    const float a = k[2 * gid] * radius, b = k[2 * gid + 1] * radius;
    float r;
    if (!isfinite(a) || !isfinite(b)) {
        r = 1.0f;
    } else if (mode == 0) {
        const float s = a + b;
        r = 1.0f - 0.0022f * s * s + 0.0776f * s + 0.7369f;
    } else if (mode == 1) {
        const float u = lut_coord(a, n), v = lut_coord(b, n);
        const uint i = min((uint)u, n - 2), j = min((uint)v, n - 2);
        const float fu = u - (float)i, fv = v - (float)j;
        const float l00 = lut[i * n + j], l10 = lut[(i + 1) * n + j];
        const float l01 = lut[i * n + j + 1], l11 = lut[(i + 1) * n + j + 1];
        r = (1.0f - fu) * ((1.0f - fv) * l00 + fv * l01) + fu * ((1.0f - fv) * l10 + fv * l11);
    } else {
        r = ao_exact(a, b, dirs);
    }
    ao[gid] = clamp(r, 0.0f, 1.0f);
}
