// bvh.cl: a linear BVH over a mesh's faces (Karras 2012, "Maximizing
// parallelism in the construction of BVHs, octrees and k-d trees").
// Layout and constants: src/spec/bvh.rs (BvhQuery mirrored below; BvhNode,
// BvhBox and the tree's helpers in common/bvh_tree.h, shared with
// kernels/intersections.cl); CPU twin: src/cpu/bvh.rs, operation for operation.
// The host passes -DBVH_STACK, -DBVH_EDGE_EPS, -DBVH_END_EPS, -DBVH_BOX_PAD.
// Steps: bvh_morton (codes of the face centroids) -> the project's radix sort
// of (code, face) pairs -> bvh_build (internal nodes) -> bvh_refit (boxes,
// once per pose) -> bvh_occluded (segment queries).

#define BVH_LEAF 0x80000000u
#define BVH_NONE 0xffffffffu
#define BVH_VISIBLE 0u
#define BVH_OCCLUDED 1u
#define BVH_OVERFLOW 2u

typedef struct {
    float4 origin;
    float4 target;
    uint exclude[4];
} BvhQuery;

SC_INLINE uint bvh_expand(uint v)
{
    v &= 0x3ffu;
    v = (v * 0x00010001u) & 0xff0000ffu;
    v = (v * 0x00000101u) & 0x0f00f00fu;
    v = (v * 0x00000011u) & 0xc30c30c3u;
    v = (v * 0x00000005u) & 0x49249249u;
    return v;
}

// MortonFrame::cell: the grid cell of a coordinate sum s.
SC_INLINE uint bvh_cell(float s, float lo3, float scale)
{
    const float v = (s - lo3) * scale;
    if (isnan(v) || v <= 0.0f) return 0u;
    if (v >= 1023.0f) return 1023u;
    return (uint)v;
}

// One work-item per face: keys[f] = Morton code of its centroid, values[f] = f.
__kernel void bvh_morton(uint n, __global const float *pos, __global const uint *faces,
                         float lo3x, float lo3y, float lo3z, float sx, float sy, float sz,
                         __global uint *keys, __global uint *values)
{
    GID_OR_RETURN(n);
    const float3 a = bvh_vertex(pos, faces[3 * gid]);
    const float3 b = bvh_vertex(pos, faces[3 * gid + 1]);
    const float3 c = bvh_vertex(pos, faces[3 * gid + 2]);
    const uint x = bvh_cell(a.x + b.x + c.x, lo3x, sx);
    const uint y = bvh_cell(a.y + b.y + c.y, lo3y, sy);
    const uint z = bvh_cell(a.z + b.z + c.z, lo3z, sz);
    keys[gid] = bvh_expand(x) * 4u + bvh_expand(y) * 2u + bvh_expand(z);
    values[gid] = gid;
}

// Karras's delta(i, j): common prefix of the augmented keys (code, index);
// -1 out of range.
SC_INLINE int bvh_delta(__global const uint *keys, int n, int i, int j)
{
    if (j < 0 || j >= n) return -1;
    const uint a = keys[i], b = keys[j];
    if (a == b) return 32 + (int)clz((uint)i ^ (uint)j);
    return (int)clz(a ^ b);
}

// One work-item per internal node (n - 1 of them): its range and split;
// writes its children and their parents (the root's parent is BVH_NONE).
__kernel void bvh_build(uint n, __global const uint *keys, __global BvhNode *nodes,
                        __global uint *leaf_parent)
{
    GID_OR_RETURN(n - 1u);
    const int N = (int)n, i = (int)gid;
    const int d = bvh_delta(keys, N, i, i + 1) > bvh_delta(keys, N, i, i - 1) ? 1 : -1;
    const int dmin = bvh_delta(keys, N, i, i - d);
    long lmax = 2;
    while (bvh_delta(keys, N, i, (int)(i + lmax * d)) > dmin) lmax *= 2;
    long l = 0;
    for (long t = lmax / 2; t >= 1; t /= 2)
        if (bvh_delta(keys, N, i, (int)(i + (l + t) * d)) > dmin) l += t;
    const int j = (int)(i + l * d);
    const int dnode = bvh_delta(keys, N, i, j);
    long s = 0;
    for (long div = 2;; div *= 2) {
        const long t = (l + div - 1) / div;
        if (bvh_delta(keys, N, i, (int)(i + (s + t) * d)) > dnode) s += t;
        if (t <= 1) break;
    }
    const int gamma = (int)(i + s * d + min(d, 0));
    const uint left = min(i, j) == gamma ? (BVH_LEAF | (uint)gamma) : (uint)gamma;
    const uint right = max(i, j) == gamma + 1 ? (BVH_LEAF | (uint)(gamma + 1)) : (uint)(gamma + 1);
    nodes[i].left = left;
    nodes[i].right = right;
    nodes[i].pad = 0u;
    if (i == 0) nodes[0].parent = BVH_NONE;
    if (left & BVH_LEAF) leaf_parent[left & ~BVH_LEAF] = (uint)i;
    else nodes[left].parent = (uint)i;
    if (right & BVH_LEAF) leaf_parent[right & ~BVH_LEAF] = (uint)i;
    else nodes[right].parent = (uint)i;
}

SC_INLINE BvhBox bvh_union(BvhBox a, BvhBox b)
{
    BvhBox u;
    u.lo = (float4)(bvh_lesser(a.lo.x, b.lo.x), bvh_lesser(a.lo.y, b.lo.y),
                    bvh_lesser(a.lo.z, b.lo.z), 0.0f);
    u.hi = (float4)(bvh_greater(a.hi.x, b.hi.x), bvh_greater(a.hi.y, b.hi.y),
                    bvh_greater(a.hi.z, b.hi.z), 0.0f);
    return u;
}

// A child's box, read through volatile pointers: another work-item wrote it.
SC_INLINE BvhBox bvh_child_box(volatile __global const BvhBox *node_boxes,
                               volatile __global const BvhBox *leaf_boxes, uint c)
{
    volatile __global const BvhBox *src =
        (c & BVH_LEAF) ? leaf_boxes + (c & ~BVH_LEAF) : node_boxes + c;
    BvhBox b;
    b.lo = src->lo;
    b.hi = src->hi;
    return b;
}

// A box padded by BVH_BOX_PAD of its largest extent (cpu::bvh::padded).
SC_INLINE BvhBox bvh_padded(BvhBox b)
{
    const float ext = bvh_greater(bvh_greater(b.hi.x - b.lo.x, b.hi.y - b.lo.y), b.hi.z - b.lo.z);
    const float pad = BVH_BOX_PAD * ext + 1e-30f;
    BvhBox p;
    p.lo = (float4)(b.lo.x - pad, b.lo.y - pad, b.lo.z - pad, 0.0f);
    p.hi = (float4)(b.hi.x + pad, b.hi.y + pad, b.hi.z + pad, 0.0f);
    return p;
}

// One work-item per leaf: the leaf's box, then up the tree; at each node the
// first child to arrive stops (atomic visit counter, zeroed by the host), the
// second computes the node's box from both children's and goes on, and
// writes the children's padded boxes side by side (child_boxes[2 node + k],
// what the queries read).
__kernel void bvh_refit(uint n, __global const float *pos, __global const uint *faces,
                        __global const uint *faces_sorted, __global const BvhNode *nodes,
                        __global const uint *leaf_parent, volatile __global BvhBox *leaf_boxes,
                        volatile __global BvhBox *node_boxes, __global BvhBox *child_boxes,
                        volatile __global uint *visits)
{
    GID_OR_RETURN(n);
    const uint f = faces_sorted[gid];
    const float3 a = bvh_vertex(pos, faces[3 * f]);
    const float3 b = bvh_vertex(pos, faces[3 * f + 1]);
    const float3 c = bvh_vertex(pos, faces[3 * f + 2]);
    BvhBox box;
    box.lo = (float4)(bvh_lesser(bvh_lesser(a.x, b.x), c.x), bvh_lesser(bvh_lesser(a.y, b.y), c.y),
                      bvh_lesser(bvh_lesser(a.z, b.z), c.z), 0.0f);
    box.hi = (float4)(bvh_greater(bvh_greater(a.x, b.x), c.x),
                      bvh_greater(bvh_greater(a.y, b.y), c.y),
                      bvh_greater(bvh_greater(a.z, b.z), c.z), 0.0f);
    leaf_boxes[gid].lo = box.lo;
    leaf_boxes[gid].hi = box.hi;
    uint node = leaf_parent[gid];
    while (node != BVH_NONE) {
        // this child's box is written before the counter says so
        mem_fence(CLK_GLOBAL_MEM_FENCE);
        if (atomic_inc(&visits[node]) == 0u) return;
        mem_fence(CLK_GLOBAL_MEM_FENCE);
        const BvhNode nd = nodes[node];
        const BvhBox l = bvh_child_box(node_boxes, leaf_boxes, nd.left);
        const BvhBox r = bvh_child_box(node_boxes, leaf_boxes, nd.right);
        const BvhBox u = bvh_union(l, r);
        node_boxes[node].lo = u.lo;
        node_boxes[node].hi = u.hi;
        child_boxes[2 * node] = bvh_padded(l);
        child_boxes[2 * node + 1] = bvh_padded(r);
        node = nd.parent;
    }
}

// One axis of the slab test: narrows [tmin, tmax] to where o + t d lies
// between lo and hi; false where the segment misses (the loop body of
// cpu::bvh::padded_hit, written out per axis: no private arrays).
SC_INLINE bool bvh_slab(float lo, float hi, float o, float d, float inv, float *tmin, float *tmax)
{
    if (d == 0.0f) return !(o < lo || o > hi);
    float t1 = (lo - o) * inv;
    float t2 = (hi - o) * inv;
    if (t1 > t2) {
        const float t = t1;
        t1 = t2;
        t2 = t;
    }
    *tmin = bvh_greater(*tmin, t1);
    *tmax = bvh_lesser(*tmax, t2);
    return !(*tmin > *tmax);
}

// Slab test of o + t d, t in [0, 1], against a box padded already
// (bvh_padded; cpu::bvh::padded_hit).
SC_INLINE bool bvh_padded_hit(BvhBox b, float3 o, float3 d, float3 invd)
{
    float tmin = 0.0f, tmax = 1.0f;
    return bvh_slab(b.lo.x, b.hi.x, o.x, d.x, invd.x, &tmin, &tmax) &&
           bvh_slab(b.lo.y, b.hi.y, o.y, d.y, invd.y, &tmin, &tmax) &&
           bvh_slab(b.lo.z, b.hi.z, o.z, d.z, invd.z, &tmin, &tmax);
}

// The slab test against the box padded by BVH_BOX_PAD of its largest extent
// (cpu::bvh::box_hit).
SC_INLINE bool bvh_box_hit(BvhBox b, float3 o, float3 d, float3 invd)
{
    return bvh_padded_hit(bvh_padded(b), o, d, invd);
}

SC_INLINE float3 bvh_cross(float3 x, float3 y)
{
    return (float3)(x.y * y.z - x.z * y.y, x.z * y.x - x.x * y.z, x.x * y.y - x.y * y.x);
}

SC_INLINE float bvh_dot(float3 x, float3 y) { return x.x * y.x + x.y * y.y + x.z * y.z; }

// Moller-Trumbore scaled by det (no division): cpu::bvh::segment_hits_f32.
SC_INLINE bool bvh_segment_hits(float3 o, float3 d, float3 a, float3 b, float3 c)
{
    const float3 e1 = b - a, e2 = c - a;
    const float3 p = bvh_cross(d, e2);
    float det = bvh_dot(e1, p);
    const float3 s = o - a;
    float u = bvh_dot(s, p);
    const float3 q = bvh_cross(s, e1);
    float v = bvh_dot(d, q);
    float t = bvh_dot(e2, q);
    if (det < 0.0f) {
        det = -det;
        u = -u;
        v = -v;
        t = -t;
    }
    if (isnan(det) || det <= 0.0f) return false;
    const float slack = BVH_EDGE_EPS * det;
    const float trim = BVH_END_EPS * det;
    return u >= -slack && v >= -slack && u + v <= det + slack && t > trim && t < det - trim;
}

// Pushes child reference c: BVH_VISIBLE, or BVH_OVERFLOW where the stack is
// full.
SC_INLINE uint bvh_push(uint *stack, int *sp, uint c)
{
    if (*sp == BVH_STACK) return BVH_OVERFLOW;
    stack[(*sp)++] = c;
    return BVH_VISIBLE;
}

// One work-item per query: stack traversal from the root (n faces; root is
// leaf 0 when n == 1), a node's children tested against their padded boxes
// (child_boxes, written by bvh_refit). result[q]: BVH_VISIBLE, BVH_OCCLUDED,
// or BVH_OVERFLOW when the stack was full (counted in counters[0], never
// written past).
__kernel void bvh_occluded(uint nq, uint n, __global const BvhQuery *queries,
                           __global const float *pos, __global const uint *faces,
                           __global const uint *faces_sorted, __global const BvhNode *nodes,
                           __global const BvhBox *node_boxes, __global const BvhBox *leaf_boxes,
                           __global const BvhBox *child_boxes, __global uint *result,
                           volatile __global uint *counters)
{
    GID_OR_RETURN(nq);
    const BvhQuery qu = queries[gid];
    const float3 o = qu.origin.xyz;
    const float3 d = qu.target.xyz - o;
    // The slab test's reciprocals, once per query (1/0 is never used).
    const float3 invd = (float3)(d.x != 0.0f ? 1.0f / d.x : 0.0f, d.y != 0.0f ? 1.0f / d.y : 0.0f,
                                 d.z != 0.0f ? 1.0f / d.z : 0.0f);
    uint out = BVH_VISIBLE;
    uint stack[BVH_STACK];
    int sp = 0;
    const uint root = n == 1u ? BVH_LEAF : 0u;
    if (n > 0u && bvh_box_hit(bvh_box_of(node_boxes, leaf_boxes, root), o, d, invd)) stack[sp++] = root;
    while (sp > 0 && out == BVH_VISIBLE) {
        const uint r = stack[--sp];
        if (r & BVH_LEAF) {
            const uint f = faces_sorted[r & ~BVH_LEAF];
            if (f == qu.exclude[0] || f == qu.exclude[1] || f == qu.exclude[2] ||
                f == qu.exclude[3])
                continue;
            const float3 a = bvh_vertex(pos, faces[3 * f]);
            const float3 b = bvh_vertex(pos, faces[3 * f + 1]);
            const float3 c = bvh_vertex(pos, faces[3 * f + 2]);
            if (bvh_segment_hits(o, d, a, b, c)) out = BVH_OCCLUDED;
            continue;
        }
        const BvhNode nd = nodes[r];
        if (bvh_padded_hit(child_boxes[2 * r], o, d, invd)) out = bvh_push(stack, &sp, nd.left);
        if (out == BVH_VISIBLE && bvh_padded_hit(child_boxes[2 * r + 1], o, d, invd))
            out = bvh_push(stack, &sp, nd.right);
        if (out == BVH_OVERFLOW) atomic_inc(&counters[0]);
    }
    result[gid] = out;
}
