// curvature.cl: per-vertex normals, point areas, principal curvatures and
// directions, and the curvature derivative of a triangle mesh.
//
// Follows Griffin et al. 2012 (§3.6), the GPU form of Rusinkiewicz 2004 as
// implemented in trimesh2 2.16. Host: src/stages/curvature/; CPU twin with the
// same step names: src/cpu/curvature.rs. Passes:
//   curv_max_face        per face   owner[v] = largest face id using v (atomic_max); topology only
//   curv_normals_areas   per face   Σ corner-weighted face normals, Σ Voronoi corner areas
//   curv_frames          per vertex normalise n; initial frame (pd1, pd2) from the owner face
//   curv_tensor          per face   least squares on normal differences, projected into each
//                                   vertex frame, weighted by corner / point area, Σ
//   curv_principal       per vertex diagonalise (ku, kuv, kv): k1, k2, d1, d2
//   curv_dcurv           per face   the same on curvature differences: C111 C112 C122 C222
// This file holds what both accumulation schemes share: types, the per-vertex
// passes, the position loads. A program holds one scheme's one-ring passes:
// kernels/curvature_atomic.cl (float atomics per face) without -DSC_GATHER,
// kernels/curvature_gather.cl (corners per face, then ring sums per vertex;
// bitwise reproducible) with it. Face geometry: common/curvature_face.h.
// With -DSC_LANES=N (2 to 16; the host picks the device's native width on
// CPUs) a work-item handles N consecutive faces or vertices as OpenCL vectors
// (common/curvature_lanes.h), with the bits of one lane; why and what it
// gained: docs/notes/curvature-kernels.md.
// Buffers (V vertices, F faces; REAL is float or double, see real.h; with
// lanes V and F are rounded up to 16, the faces' padding repeats the last face):
//   pos   REAL[3V+1]  centred, unit RMS radius; one real of padding (ld_pos)
//   faces uint[3F]    vertex indices             owner int[V] (−1: unused vertex)
//   nrm   REAL[3V]    normal (summed, then unit)  area  REAL[V]  point area
//   pd1, pd2 REAL[3V] initial frame, then principal directions
//   tens  REAL[3V]    (ku, kuv, kv)   kk REAL[2V] (k1, k2)   dk REAL[4V] derivative
//   rec   REAL[16V]   with lanes: vertex records (REC_* in curvature_lanes.h)
//   counters uint[4]  degenerate faces, vertices without area, tensor and
//                     dcurv solves skipped (CurvatureCounts order)
// Degenerate faces (an edge below 1e-12 of the RMS radius, 2A below 5e-8 Σ
// edge², or a height below the rounding of the positions) are skipped in
// every pass and counted once, as in the CPU twin; so are least-squares
// systems with a non-positive pivot. Nothing here writes NaN.
// Options (mirrored in src/spec/curvature.rs): -DSC_GATHER, -DSC_LANES=N,
// -DSC_DOUBLE, -DSC_COMPAT (trimesh2 2.16: third pivot Σv², |k1| ≥ |k2|
// ordering), -DSC_PAIR_ADDS and -DSC_NATIVE_ATOMICS (common/atomics.h).

// Mirrored by the DEGEN_* constants of src/spec/curvature.rs (the CPU twin uses them).
#define DEGEN_AREA_REL RL(5e-8)                  // × (l0² + l1² + l2²)
#define DEGEN_EDGE2 RL(1e-24)
// Heights below DEGEN_HEIGHT_ULP × (|p0|+|p1|+|p2|) are under the rounding of
// the positions at the precision computed in: 2^-23 (f32), 2^-52 (f64).
#ifdef SC_DOUBLE
#define DEGEN_HEIGHT_ULP RL(2.220446049250313080847e-16)
#else
#define DEGEN_HEIGHT_ULP RL(1.1920928955078125e-7)
#endif

// ---------------------------------------------------------------------------
// Types. The geometry of kernels/common/curvature_face.h is instantiated on
// scalars for every kernel and, with SC_LANES > 1 (CPU devices; the host
// picks the count), on vectors of SC_LANES lanes for the per-face kernels of
// either scheme and for curv_frames and curv_principal, which then handle
// SC_LANES consecutive faces or vertices per work-item.

#ifndef SC_LANES
#define SC_LANES 1
#endif
#if SC_LANES != 1 && SC_LANES != 2 && SC_LANES != 4 && SC_LANES != 8 && SC_LANES != 16
#error "SC_LANES must be 1, 2, 4, 8 or 16"
#endif
#if SC_LANES > 1
#define SC_OL __attribute__((overloadable))
// Lanes wider than the target's registers (16 floats without AVX-512) pass
// vectors differently between functions; every helper is inlined, so the
// note is moot.
#pragma clang diagnostic ignored "-Wpsabi"
#else
#define SC_OL
#endif

SC_OL SC_INLINE REAL ld1(__global const REAL *a, uint i) { return a[i]; }
SC_OL SC_INLINE uint ldu(__global const uint *a, uint i) { return a[i]; }

#define GT REAL
#define GM int
#define GI uint
#define GV3 V3
#define GV4 V4
#define GTri Tri
#include "common/curvature_face.h"
#undef GT
#undef GM
#undef GI
#undef GV3
#undef GV4
#undef GTri

SC_INLINE void st3(V3 v, uint i, __global REAL *a)
{
    a[3 * i] = v.x;
    a[3 * i + 1] = v.y;
    a[3 * i + 2] = v.z;
}

#if SC_LANES > 1
#define SC_CAT_(a, b) a##b
#define SC_CAT(a, b) SC_CAT_(a, b)
#ifdef SC_DOUBLE
typedef SC_CAT(double, SC_LANES) REALN;
typedef SC_CAT(long, SC_LANES) MASKN;
#else
typedef SC_CAT(float, SC_LANES) REALN;
typedef SC_CAT(int, SC_LANES) MASKN;
#endif
typedef SC_CAT(uint, SC_LANES) UINTN;
typedef SC_CAT(int, SC_LANES) INTN;
#define VLOADN SC_CAT(vload, SC_LANES)
#define VSTOREN SC_CAT(vstore, SC_LANES)
#define CONVERT_UCHARN SC_CAT(convert_uchar, SC_LANES)
#define CONVERT_INTN SC_CAT(convert_int, SC_LANES)
#define CONVERT_UINTN SC_CAT(convert_uint, SC_LANES)
#ifdef SC_DOUBLE
#define CONVERT_MASKN SC_CAT(convert_long, SC_LANES)
#else
#define CONVERT_MASKN SC_CAT(convert_int, SC_LANES)
#endif

// F applied to each lane's component name, as a comma-separated list
// (SC_LANE_LIST), and F(j, b) for each lane number j (SC_JLIST, for the
// constant indices of __builtin_shufflevector).
#if SC_LANES == 2
#define SC_LANE_LIST(F) F(s0), F(s1)
#define SC_IOTA ((UINTN)(0, 1))
#define SC_JLIST(F, b) F(0, b), F(1, b)
#elif SC_LANES == 4
#define SC_LANE_LIST(F) F(s0), F(s1), F(s2), F(s3)
#define SC_IOTA ((UINTN)(0, 1, 2, 3))
#define SC_JLIST(F, b) F(0, b), F(1, b), F(2, b), F(3, b)
#elif SC_LANES == 8
#define SC_LANE_LIST(F) F(s0), F(s1), F(s2), F(s3), F(s4), F(s5), F(s6), F(s7)
#define SC_IOTA ((UINTN)(0, 1, 2, 3, 4, 5, 6, 7))
#define SC_JLIST(F, b) F(0, b), F(1, b), F(2, b), F(3, b), F(4, b), F(5, b), F(6, b), F(7, b)
#else
#define SC_LANE_LIST(F)                                                                       \
    F(s0), F(s1), F(s2), F(s3), F(s4), F(s5), F(s6), F(s7), F(s8), F(s9), F(sa), F(sb), F(sc), \
        F(sd), F(se), F(sf)
#define SC_IOTA ((UINTN)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15))
#define SC_JLIST(F, b)                                                                      \
    F(0, b), F(1, b), F(2, b), F(3, b), F(4, b), F(5, b), F(6, b), F(7, b), F(8, b), F(9, b), \
        F(10, b), F(11, b), F(12, b), F(13, b), F(14, b), F(15, b)
#endif

// One scalar load per lane; the compiler assembles the vector.
#define SC_LD_ONE(l) a[i.l]
SC_OL SC_INLINE REALN ld1(__global const REAL *a, UINTN i) { return (REALN)(SC_LANE_LIST(SC_LD_ONE)); }
SC_OL SC_INLINE UINTN ldu(__global const uint *a, UINTN i) { return (UINTN)(SC_LANE_LIST(SC_LD_ONE)); }

#define GT REALN
#define GM MASKN
#define GI UINTN
#define GV3 V3N
#define GV4 V4N
#define GTri TriN
#endif // SC_LANES > 1

// The lane instance (empty without lanes: GT is then undefined). The include
// stays outside the #if so that the #line markers around it always apply.
#include "common/curvature_face.h"
#undef GT
#undef GM
#undef GI
#undef GV3
#undef GV4
#undef GTri

#if SC_LANES > 1
// The types of the per-face kernels.
typedef REALN FREAL;
typedef MASKN FMASK;
typedef UINTN FIDX;
typedef V3N FV3;
typedef V4N FV4;
typedef TriN FTri;

// Face block b: faces SC_LANES·b … SC_LANES·b + SC_LANES − 1. Lanes past the
// last face repeat it (`live` is false there); their corners land in the
// padding of the corner buffer (sized for whole blocks) and are never read.
#define FACE_BLOCK_OR_RETURN(nf)                                  \
    const uint blk = (uint)get_global_id(0);                      \
    if (blk >= ((nf) + SC_LANES - 1) / SC_LANES) return;          \
    const FIDX fid_ = (FIDX)(SC_LANES * blk) + SC_IOTA;           \
    const INTN live = fid_ < (FIDX)(nf);                          \
    const FIDX fid = min(fid_, (FIDX)((nf) - 1));

// Adds to *c the lanes of a block where m holds and a face is (live: not
// past the last face): one atomic per block, and none when no lane counts.
// Explicit lanes are SIMD code already, so the atomic costs no vectorisation.
SC_INLINE int lanes_sum(INTN v)
{
#if SC_LANES == 16
    int8 v8 = v.lo + v.hi;
#elif SC_LANES == 8
    int8 v8 = v;
#endif
#if SC_LANES >= 8
    int4 v4_ = v8.lo + v8.hi;
#elif SC_LANES == 4
    int4 v4_ = v;
#endif
#if SC_LANES >= 4
    int2 v2 = v4_.lo + v4_.hi;
#else
    int2 v2 = v;
#endif
    return v2.x + v2.y;
}
SC_INLINE void count_lanes(volatile __global uint *c, FMASK m, INTN live)
{
    INTN im = CONVERT_INTN(m) & live;
    if (any(im))
        atomic_add(c, (uint)(-lanes_sum(im)));
}
#else
typedef REAL FREAL;
typedef int FMASK;
typedef uint FIDX;
typedef V3 FV3;
typedef V4 FV4;
typedef Tri FTri;

#define FACE_BLOCK_OR_RETURN(nf)  \
    GID_OR_RETURN(nf);            \
    const uint blk = gid;         \
    const int live = 1;           \
    const FIDX fid = gid;

SC_INLINE void count_lanes(volatile __global uint *c, FMASK m, int live)
{
    if (m & live)
        atomic_inc(c);
}
#endif

// ---------------------------------------------------------------------------
// Topology pass (once per mesh).

__kernel void curv_max_face(uint nf, __global const uint *faces, volatile __global int *owner)
{
    GID_OR_RETURN(nf);
    for (int i = 0; i < 3; i++)
        atomic_max(&owner[faces[3 * gid + i]], (int)gid);
}

// The lane forms' loads and stores: vertex records, transposes, position rows.
#include "common/curvature_lanes.h"

// ---------------------------------------------------------------------------
// Per-vertex passes (both schemes).

#if SC_LANES == 1
// Unit normal, and the initial tangent frame from the owner face:
// pd1 = (edge to the next vertex of that face) × n, pd2 = n × pd1.
__kernel void curv_frames(uint nv, __global const REAL *pos, __global const uint *faces,
                          __global const int *owner, __global REAL *nrm, __global REAL *pd1,
                          __global REAL *pd2)
{
    GID_OR_RETURN(nv);
    V3 n = unit_normal(ld3(nrm, gid));
    st3(n, gid, nrm);
    int f = owner[gid];
    uint fi = (uint)max(f, 0);
    uint a = faces[3 * fi], b = faces[3 * fi + 1], c = faces[3 * fi + 2];
    uint next = gid == a ? b : gid == b ? c : a;
    V3 p1 = first_dir(sub3(ld3(pos, next), ld3(pos, gid)), n, f >= 0);
    st3(p1, gid, pd1);
    st3(cross3(n, p1), gid, pd2);
}

// One Jacobi rotation diagonalises the 2×2 tensor.
__kernel void curv_principal(uint nv, __global const REAL *nrm, __global const REAL *tens,
                             __global REAL *pd1, __global REAL *pd2, __global REAL *kk)
{
    GID_OR_RETURN(nv);
    V3 n = ld3(nrm, gid), ru, rv;
    rot_coord_sys(ld3(pd1, gid), ld3(pd2, gid), n, &ru, &rv);
    REAL ka, kb;
    V3 d1 = principal_dir(ru, rv, ld3(tens, gid), &ka, &kb);
    st3(d1, gid, pd1);
    st3(cross3(n, d1), gid, pd2);
    kk[2 * gid] = ka;
    kk[2 * gid + 1] = kb;
}

#else // SC_LANES > 1
// With lanes, curv_frames and curv_principal handle SC_LANES consecutive
// vertices per work-item, as vectors: their per-vertex buffers (3 or 2 reals
// per vertex) are read and written as whole vectors and (de)interleaved in
// registers (ld3c, st3c, st2c), instead of a gather or scatter per value;
// each also writes the block's vertex records (st_rec), and curv_frames
// counts the vertices without area itself (no curv_count_empty launch).
// The host pads every per-vertex buffer to whole blocks of MAX_FACE_LANES
// vertices (the padding's results are never read). Their arithmetic is the
// one-lane kernels' above: the same helpers of kernels/common/curvature_face.h
// (unit_normal, first_dir, principal_dir) on the lane types.
#define VERTEX_BLOCK_OR_RETURN(nv)                            \
    const uint blk = (uint)get_global_id(0);                  \
    if (blk >= ((nv) + SC_LANES - 1) / SC_LANES) return;      \
    const FIDX vid = (FIDX)(SC_LANES * blk) + SC_IOTA;

// Component k of the 3-real records of a block: stream element 3j + k of
// the three vectors a b c, picked from a and b first, then from c.
#define SC_D1(j, k) ((3 * (j) + (k)) < 2 * SC_LANES ? 3 * (j) + (k) : 0)
#define SC_D2(j, k) ((3 * (j) + (k)) < 2 * SC_LANES ? (j) : 3 * (j) + (k) - SC_LANES)
#define SC_DEINT(a, b, c, k) \
    __builtin_shufflevector(__builtin_shufflevector(a, b, SC_JLIST(SC_D1, k)), c, SC_JLIST(SC_D2, k))
// Vector o of the stream of three component vectors x y z (element
// e = o·SC_LANES + j is component e % 3 of lane e / 3), and of two (e % 2, e / 2).
#define SC_E(j, o) ((o) * SC_LANES + (j))
#define SC_I1(j, o) \
    (SC_E(j, o) % 3 == 0 ? SC_E(j, o) / 3 : SC_E(j, o) % 3 == 1 ? SC_LANES + SC_E(j, o) / 3 : 0)
#define SC_I2(j, o) (SC_E(j, o) % 3 == 2 ? SC_LANES + SC_E(j, o) / 3 : (j))
#define SC_INT3(x, y, z, o) \
    __builtin_shufflevector(__builtin_shufflevector(x, y, SC_JLIST(SC_I1, o)), z, SC_JLIST(SC_I2, o))
#define SC_IW(j, o) (SC_E(j, o) % 2 == 0 ? SC_E(j, o) / 2 : SC_LANES + SC_E(j, o) / 2)

SC_INLINE FV3 ld3c(__global const REAL *p, uint blk)
{
    FREAL a = VLOADN(3 * blk, p), b = VLOADN(3 * blk + 1, p), c = VLOADN(3 * blk + 2, p);
    return v3(SC_DEINT(a, b, c, 0), SC_DEINT(a, b, c, 1), SC_DEINT(a, b, c, 2));
}
SC_INLINE void st3c(FV3 v, uint blk, __global REAL *p)
{
    VSTOREN(SC_INT3(v.x, v.y, v.z, 0), 3 * blk, p);
    VSTOREN(SC_INT3(v.x, v.y, v.z, 1), 3 * blk + 1, p);
    VSTOREN(SC_INT3(v.x, v.y, v.z, 2), 3 * blk + 2, p);
}
SC_INLINE void st2c(FREAL a, FREAL b, uint blk, __global REAL *p)
{
    VSTOREN(__builtin_shufflevector(a, b, SC_JLIST(SC_IW, 0)), 2 * blk, p);
    VSTOREN(__builtin_shufflevector(a, b, SC_JLIST(SC_IW, 1)), 2 * blk + 1, p);
}

__kernel void curv_frames(uint nv, __global const REAL *pos, __global const uint *faces,
                          __global const int *owner, __global REAL *nrm, __global REAL *pd1,
                          __global REAL *pd2, __global const REAL *area, __global REAL *rec,
                          volatile __global uint *counters)
{
    VERTEX_BLOCK_OR_RETURN(nv);
    FV3 n = unit_normal(ld3c(nrm, blk));
    st3c(n, blk, nrm);
    INTN f = VLOADN(blk, owner);
    FIDX fi = CONVERT_UINTN(max(f, 0));
    FIDX a = ldu(faces, 3 * fi), b = ldu(faces, 3 * fi + 1), c = ldu(faces, 3 * fi + 2);
    FIDX next = vid == a ? b : vid == b ? c : a;
    FV3 p = ld3c(pos, blk);
    FV3 p1 = first_dir(sub3(ld3(pos, next), p), n, CONVERT_MASKN(f >= 0));
    FV3 p2 = cross3(n, p1);
    st3c(p1, blk, pd1);
    st3c(p2, blk, pd2);
    FREAL ar = VLOADN(blk, area);
    const FREAL z = (FREAL)RL(0), r[16] = REC_OF(p, ar, n, z, p1, z, p2);
    st_rec(rec, blk, r);
    // curv_count_empty's count, here (one atomic per block; explicit lanes
    // need no work-item vectoriser)
    count_lanes(&counters[1], !(ar > 0), vid < (FIDX)nv);
}

__kernel void curv_principal(uint nv, __global const REAL *nrm, __global const REAL *tens,
                             __global REAL *pd1, __global REAL *pd2, __global REAL *kk,
                             __global const REAL *pos, __global const REAL *area,
                             __global REAL *rec)
{
    VERTEX_BLOCK_OR_RETURN(nv);
    FV3 n = ld3c(nrm, blk), ru, rv;
    rot_coord_sys(ld3c(pd1, blk), ld3c(pd2, blk), n, &ru, &rv);
    FREAL ka, kb;
    FV3 d1 = principal_dir(ru, rv, ld3c(tens, blk), &ka, &kb);
    FV3 d2 = cross3(n, d1);
    st3c(d1, blk, pd1);
    st3c(d2, blk, pd2);
    st2c(ka, kb, blk, kk);
    const FREAL r[16] = REC_OF(ld3c(pos, blk), VLOADN(blk, area), n, ka, d1, kb, d2);
    st_rec(rec, blk, r);
}
#endif // SC_LANES > 1

// Counts the vertices that no usable face touches (kept out of curv_frames:
// an atomic in a kernel keeps PoCL from vectorising it).
__kernel void curv_count_empty(uint nv, __global const REAL *area,
                               volatile __global uint *counters)
{
    GID_OR_RETURN(nv);
    if (!(area[gid] > 0))
        atomic_inc(&counters[1]);
}

// ---------------------------------------------------------------------------
// The one-ring passes of the scheme this program is built for (the host sets
// SC_GATHER for the gather scheme).
#ifdef SC_GATHER
#include "curvature_gather.cl"
#else
#include "curvature_atomic.cl"
#endif

// ---------------------------------------------------------------------------
// Positions of a device-resident mesh (a fused isosurface, index space):
// pos = a ⊙ src + b, the host's normalization folded with the volume's
// spacing and origin. One work-item per vertex.
__kernel void curv_load_positions(uint nv, __global const float *src, REAL ax, REAL ay, REAL az,
                                  REAL bx, REAL by, REAL bz, __global REAL *pos)
{
    GID_OR_RETURN(nv);
    pos[3 * gid] = ax * (REAL)src[3 * gid] + bx;
    pos[3 * gid + 1] = ay * (REAL)src[3 * gid + 1] + by;
    pos[3 * gid + 2] = az * (REAL)src[3 * gid + 2] + bz;
}

// Replaces the accumulated vertex normals with given unit normals (e.g. from
// an isosurface's volume gradient) where those are finite and non-zero; runs
// after curv_normals_areas, before curv_frames. One work-item per vertex.
__kernel void curv_override_normals(uint nv, __global const float *src, __global REAL *nrm)
{
    GID_OR_RETURN(nv);
    const float x = src[3 * gid], y = src[3 * gid + 1], z = src[3 * gid + 2];
    const float l2 = x * x + y * y + z * z;
    if (isfinite(l2) && l2 > 0.0f) {
        nrm[3 * gid] = (REAL)x;
        nrm[3 * gid + 1] = (REAL)y;
        nrm[3 * gid + 2] = (REAL)z;
    }
}
