// intersections.cl: where faces of a mesh cross each other (Blender Line
// Art's intersection lines), one segment per crossing face pair.
// Layout: src/spec/intersections.rs (IsectSegment mirrored below); the tree
// is the bvh family's (common/bvh_tree.h, built and refitted by
// src/stages/bvh.rs); CPU twin: src/cpu/intersections.rs, operation for
// operation. The host passes -DISECT_STACK (the traversal stack's entries).
// Pair test: Moller 1997 ("A fast triangle-triangle intersection test"),
// interval overlap on the line of the two planes, ends kept in 3-D.
//
// Buffers: pos float[3 V], faces uint[3 F], faces_sorted uint[F], nodes
// BvhNode[F - 1], node_boxes BvhBox[F - 1], leaf_boxes BvhBox[F], groups
// uint[F] (read only when use_groups), out IsectSegment[cap], counters
// uint[4]: segments found (all of them, also those past cap, which are not
// written), pairs tested (saturating), stack overflows, and 1 when the
// segment counter wrapped past UINT_MAX (the host reports it).

typedef struct {
    float a[3];
    float b[3];
    uint faces[2];
} IsectSegment;

// A triangle's corners.
typedef struct {
    float3 p[3];
} IsectTri;

SC_INLINE float3 isect_cross(float3 x, float3 y)
{
    return (float3)(x.y * y.z - x.z * y.y, x.z * y.x - x.x * y.z, x.x * y.y - x.y * y.x);
}

SC_INLINE float isect_dot(float3 x, float3 y) { return x.x * y.x + x.y * y.y + x.z * y.z; }

SC_INLINE float isect_axis(float3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

SC_INLINE bool isect_one_side(float3 d)
{
    return (d.x > 0.0f && d.y > 0.0f && d.z > 0.0f) || (d.x < 0.0f && d.y < 0.0f && d.z < 0.0f);
}

SC_INLINE bool isect_lex_less(float3 p, float3 q)
{
    return p.x < q.x || (p.x == q.x && (p.y < q.y || (p.y == q.y && p.z < q.z)));
}

// The crossing of edge (p, q), distances of strictly opposite signs, from
// its lexicographically first end (cpu::intersections::crossing).
SC_INLINE float3 isect_crossing(float3 p, float dp, float3 q, float dq)
{
    if (isect_lex_less(q, p)) {
        const float3 t = p;
        p = q;
        q = t;
        const float td = dp;
        dp = dq;
        dq = td;
    }
    const float s = dp / (dp - dq);
    return (float3)(p.x + (q.x - p.x) * s, p.y + (q.y - p.y) * s, p.z + (q.z - p.z) * s);
}

SC_INLINE void isect_push(float3 x, float3 *p0, float3 *p1, int *n)
{
    if (*n == 0) *p0 = x;
    else if (*n == 1) *p1 = x;
    *n += 1;
}

// Where triangle t (distances d to the other's plane) meets that plane:
// corners at distance 0, then crossings of edges (0,1), (1,2), (2,0); true
// when that is exactly two points (cpu::intersections::on_plane).
SC_INLINE bool isect_on_plane(IsectTri t, float3 d, float3 *p0, float3 *p1)
{
    const float ds[3] = {d.x, d.y, d.z};
    int n = 0;
    for (int i = 0; i < 3; ++i)
        if (ds[i] == 0.0f) isect_push(t.p[i], p0, p1, &n);
    for (int i = 0; i < 3; ++i) {
        const int j = i == 2 ? 0 : i + 1;
        const bool opposite = (ds[i] < 0.0f && ds[j] > 0.0f) || (ds[i] > 0.0f && ds[j] < 0.0f);
        if (opposite) isect_push(isect_crossing(t.p[i], ds[i], t.p[j], ds[j]), p0, p1, &n);
    }
    return n == 2;
}

// The face's normal divided by its largest absolute component (scale-free);
// false for a zero or non-finite normal (cpu::intersections::normal).
SC_INLINE bool isect_normal(IsectTri t, float3 *n)
{
    const float3 c = isect_cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
    float m = fabs(c.x);
    if (fabs(c.y) > m) m = fabs(c.y);
    if (fabs(c.z) > m) m = fabs(c.z);
    if (!(m > 0.0f) || !isfinite(m)) return false;
    *n = (float3)(c.x / m, c.y / m, c.z / m);
    return true;
}

SC_INLINE float3 isect_distances(IsectTri t, float3 n, float3 p0)
{
    return (float3)(isect_dot(n, t.p[0] - p0), isect_dot(n, t.p[1] - p0),
                    isect_dot(n, t.p[2] - p0));
}

SC_INLINE bool isect_all_finite(float3 a, float3 b)
{
    return isfinite(a.x) && isfinite(a.y) && isfinite(a.z) && isfinite(b.x) && isfinite(b.y) &&
           isfinite(b.z);
}

// The segment where t1 and t2 cross, along n1 x n2 (cpu::intersections::
// triangle_pair): false when they do not cross along a line of positive
// length, are coplanar or degenerate, or the ends are not finite.
SC_INLINE bool isect_pair(IsectTri t1, IsectTri t2, float3 *start, float3 *end)
{
    float3 n1, n2;
    if (!isect_normal(t2, &n2)) return false;
    const float3 d1 = isect_distances(t1, n2, t2.p[0]);
    if (isect_one_side(d1)) return false;
    if (!isect_normal(t1, &n1)) return false;
    const float3 d2 = isect_distances(t2, n1, t1.p[0]);
    if (isect_one_side(d2)) return false;
    if ((d1.x == 0.0f && d1.y == 0.0f && d1.z == 0.0f) ||
        (d2.x == 0.0f && d2.y == 0.0f && d2.z == 0.0f))
        return false;
    const float3 d = isect_cross(n1, n2);
    int k = 0;
    if (fabs(d.y) > fabs(d.x)) k = 1;
    if (fabs(d.z) > fabs(isect_axis(d, k))) k = 2;
    const float dk = isect_axis(d, k);
    if (!(fabs(dk) > 0.0f)) return false;
    float3 p0, p1, q0, q1;
    if (!isect_on_plane(t1, d1, &p0, &p1) || !isect_on_plane(t2, d2, &q0, &q1)) return false;
    if (isect_axis(p1, k) < isect_axis(p0, k)) {
        const float3 t = p0;
        p0 = p1;
        p1 = t;
    }
    if (isect_axis(q1, k) < isect_axis(q0, k)) {
        const float3 t = q0;
        q0 = q1;
        q1 = t;
    }
    float3 s = isect_axis(q0, k) > isect_axis(p0, k) ? q0 : p0;
    float3 e = isect_axis(q1, k) < isect_axis(p1, k) ? q1 : p1;
    if (!(isect_axis(s, k) < isect_axis(e, k))) return false;
    *start = dk < 0.0f ? e : s;
    *end = dk < 0.0f ? s : e;
    return isect_all_finite(*start, *end);
}

SC_INLINE IsectTri isect_tri(__global const float *pos, __global const uint *faces, uint f)
{
    IsectTri t;
    t.p[0] = bvh_vertex(pos, faces[3 * f]);
    t.p[1] = bvh_vertex(pos, faces[3 * f + 1]);
    t.p[2] = bvh_vertex(pos, faces[3 * f + 2]);
    return t;
}

SC_INLINE bool isect_same(float3 a, float3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// A corner position in common (bit for bit, -0 = +0): faces sharing a
// vertex, also in an unwelded soup.
SC_INLINE bool isect_share(IsectTri a, IsectTri b)
{
    bool s = false;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) s = s || isect_same(a.p[i], b.p[j]);
    return s;
}

SC_INLINE bool isect_overlap(BvhBox a, BvhBox b)
{
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y &&
           a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
}

// Adds v to *p, saturating at UINT_MAX.
SC_INLINE void isect_add_saturating(volatile __global uint *p, uint v)
{
    uint old = *p;
    for (;;) {
        uint want = old + v;
        if (want < old) want = 0xffffffffu;
        const uint seen = atomic_cmpxchg(p, old, want);
        if (seen == old) return;
        old = seen;
    }
}

SC_INLINE void isect_append(__global IsectSegment *out, uint cap, volatile __global uint *counters,
                            float3 s, float3 e, uint f, uint g)
{
    const uint slot = atomic_inc(&counters[0]);
    if (slot == 0xffffffffu) counters[3] = 1u;
    if (slot >= cap) return;
    out[slot].a[0] = s.x;
    out[slot].a[1] = s.y;
    out[slot].a[2] = s.z;
    out[slot].b[0] = e.x;
    out[slot].b[1] = e.y;
    out[slot].b[2] = e.z;
    out[slot].faces[0] = f;
    out[slot].faces[1] = g;
}

// One work-item per leaf (n faces; the root is leaf 0 when n == 1): a stack
// traversal with the leaf's box; each leaf of a higher face that shares no
// vertex (and, with use_groups, has another group) gets the pair test.
__kernel void isect_find(uint n, __global const float *pos, __global const uint *faces,
                         __global const uint *faces_sorted, __global const BvhNode *nodes,
                         __global const BvhBox *node_boxes, __global const BvhBox *leaf_boxes,
                         uint use_groups, __global const uint *groups, uint cap,
                         __global IsectSegment *out, volatile __global uint *counters)
{
    GID_OR_RETURN(n);
    const uint f = faces_sorted[gid];
    const BvhBox bx = leaf_boxes[gid];
    const IsectTri t1 = isect_tri(pos, faces, f);
    uint tested = 0u, overflows = 0u;
    uint stack[ISECT_STACK];
    int sp = 0;
    const uint root = n == 1u ? BVH_LEAF : 0u;
    if (isect_overlap(bvh_box_of(node_boxes, leaf_boxes, root), bx)) stack[sp++] = root;
    while (sp > 0) {
        const uint r = stack[--sp];
        if (!(r & BVH_LEAF)) {
            const BvhNode nd = nodes[r];
            const uint kids[2] = {nd.left, nd.right};
            for (int k = 0; k < 2; ++k) {
                if (!isect_overlap(bvh_box_of(node_boxes, leaf_boxes, kids[k]), bx)) continue;
                if (sp == ISECT_STACK) overflows++;
                else stack[sp++] = kids[k];
            }
            continue;
        }
        const uint g = faces_sorted[r & ~BVH_LEAF];
        if (g <= f || (use_groups && groups[f] == groups[g])) continue;
        const IsectTri t2 = isect_tri(pos, faces, g);
        if (isect_share(t1, t2)) continue;
        tested++;
        float3 s, e;
        if (isect_pair(t1, t2, &s, &e)) isect_append(out, cap, counters, s, e, f, g);
    }
    if (tested > 0u) isect_add_saturating(&counters[1], tested);
    if (overflows > 0u) atomic_add(&counters[2], overflows);
}
