// bvh_tree.h: the bvh family's tree as its kernels and the kernels that
// traverse it (kernels/bvh.cl, kernels/intersections.cl) read it. Layout:
// src/spec/bvh.rs (BvhNode, BvhBox, LEAF, NONE; the bvh probe test checks
// sizes and offsets). A child reference is an internal node index, or
// BVH_LEAF | leaf; leaf i is face faces_sorted[i].

#define BVH_LEAF 0x80000000u
#define BVH_NONE 0xffffffffu

typedef struct {
    uint left;
    uint right;
    uint parent;
    uint pad;
} BvhNode;

typedef struct {
    float4 lo;
    float4 hi;
} BvhBox;

// a < b ? a : b as the twin writes it (fmin's choice between -0 and +0 is
// the device's own).
SC_INLINE float bvh_lesser(float a, float b) { return b < a ? b : a; }
SC_INLINE float bvh_greater(float a, float b) { return b > a ? b : a; }

SC_INLINE float3 bvh_vertex(__global const float *pos, uint v)
{
    return (float3)(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]);
}

// The box of child reference c (cpu::bvh::Tree::child_box).
SC_INLINE BvhBox bvh_box_of(__global const BvhBox *node_boxes, __global const BvhBox *leaf_boxes,
                            uint c)
{
    return (c & BVH_LEAF) ? leaf_boxes[c & ~BVH_LEAF] : node_boxes[c];
}
