// mc_edge.h: the marching-cubes edge rule, shared by marching_cubes.cl
// (soup vertices) and sdf_lines.cl (dense surface samples) so that both place
// a crossing at the same point. A grid edge from value v0 to v1 crosses iso
// when both are finite and exactly one is inside (value < iso, the bit of the
// marching-cubes case); the crossing is at v0 + t (v1 − v0) = iso, t clamped
// to [0, 1] (NaN from ±inf values goes to the lower end). Where a difference
// overflows (finite values beyond ±1.7e38), both are taken of the halved
// values, which halving leaves exact: the same t as unbounded arithmetic
// would round to, instead of 0. CPU twin: cpu::marching_cubes::edge_t.
inline float mc_edge_t(float v0, float v1, float iso)
{
    float n = iso - v0, d = v1 - v0;
    if (isinf(n) || isinf(d)) {
        n = iso * 0.5f - v0 * 0.5f;
        d = v1 * 0.5f - v0 * 0.5f;
    }
    float t = n / d;
    if (!(t >= 0.0f))
        t = 0.0f;
    if (t > 1.0f)
        t = 1.0f;
    return t;
}
