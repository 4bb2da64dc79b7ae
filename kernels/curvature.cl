// curvature.cl: per-vertex normals, point areas, principal curvatures and
// directions, and the curvature derivative of a triangle mesh.
//
// Follows Griffin et al. 2012 (§3.6), the GPU form of Rusinkiewicz 2004 as
// implemented in trimesh2 2.16. Passes (host: src/stages/curvature.rs; CPU
// twin with the same step names: src/cpu/curvature.rs):
//   curv_max_face        per face   owner[v] = largest face id using v (atomic_max); topology only
//   curv_clear           per vertex zero the one-ring accumulators (atomic variant)
//   curv_normals_areas   per face   Σ corner-weighted face normals, Σ Voronoi corner areas
//   curv_frames          per vertex normalise n; initial frame (pd1, pd2) from the owner face
//   curv_tensor          per face   per-face least squares on normal differences, projected
//                                   into each vertex frame, weighted by corner/point area, Σ
//   curv_principal       per vertex diagonalise (ku, kuv, kv): k1, k2, d1, d2
//   curv_dcurv           per face   same scheme on curvature differences: C111 C112 C122 C222
// Gather variant: each one-ring pass is split in two. A per-face kernel
// (curv_*_corners) writes its three corner contributions to a corner buffer,
// with no inner loops, and counts its skipped faces. A per-vertex kernel
// (curv_*_sum) then adds the corners of its one-ring (CSR lists built once on
// the host, in face order). The result is bitwise reproducible.
// The derivative pass computes one set of projection coefficients per face
// corner (proj_coef) and uses it both ways: the vertex's tensor into the
// face frame, and the face's derivative tensor back into the vertex frame
// (the two minimal rotations between the planes are each other's inverse).
// Three frame rotations and twelve dot products fewer per face; dk moves by
// rounding only (bunny: relative RMS 1e-7). 500k torus, PoCL: dcurv corners
// 9.3 → 8.2 ms.
//
// Explicit SIMD lanes (SC_LANES, set by the host: the device's native vector
// width on CPUs, 1 on GPUs; either scheme). The per-face
// kernels handle SC_LANES consecutive faces per work-item, and curv_frames
// and curv_principal SC_LANES consecutive vertices: their geometry
// (kernels/common/curvature_face.h) is written once over type macros and
// instantiated on scalars and on REAL vectors of SC_LANES lanes, with
// overloaded helper names, so one kernel text serves both. The arithmetic is
// the same operation for operation, so every lane count gives the same bits
// (tests/curvature.rs checks 1 to 16 lanes, on face and vertex counts that
// are not multiples of 16).
// Why: PoCL 3.1 leaves these kernels scalar when written one face per
// work-item. It runs -O3 with the SLP vectoriser on the single work-item
// kernel before it builds the work-item loops; SLP packs pairs of corners into
// <2 x float>, and the loop vectoriser then refuses the vector-typed
// instructions (POCL_VECTORIZER_REMARKS, "instruction return type cannot be
// vectorized"). Its build options cannot switch SLP off (it accepts only
// -cl-*, -w, -Werror, -g, -D and -I). With one lane there are no packed
// float operations in curv_tensor_corners (1,664 scalar float operations of
// 2,346 instructions on pthread-skylake-avx512).
// Memory access with lanes: nothing is gathered one lane at a time except
// the owner faces' vertices and their positions in curv_frames.
//  - Positions of the normal pass (ld_pos): each lane's x y z is one 4-real
//    load (the next vertex's x comes along unused; the pos buffer has one
//    real of padding past its last vertex), addressed through a scalar
//    face-index load, and the rows are transposed into lane vectors in
//    registers (rows_v3: the rows' stream gathered into four whole vectors,
//    then two-source shuffles), instead of 9 hardware gathers of positions
//    and 3 of face indices per block. 500k torus, PoCL: normal corners
//    6.2–7.2 → 3.2–4.1 ms; lucy 0.65–0.98 → 0.38–0.43 ms (medians of 11 and
//    61 runs, interleaved processes). Written the same way in curv_frames
//    (three scalar loads of the owner face per lane, then the next vertex's
//    row), the chains of dependent scalar loads were slower on the scanned
//    meshes (lucy 0.24 → 0.29–0.31 ms, bunny 0.17–0.21 → 0.20–0.26) though
//    faster on the torus (3.3 → 2.3 ms): not kept.
//  - Face indices: the host pads the faces buffer to whole blocks of 16
//    faces with copies of the last face, so a block's face indices are
//    scalar loads at constant offsets. With the clamp at the last face that
//    this replaces, LLVM had turned them into gathers (3 per corner).
//  - Vertex records (rec, REC_*): 16 reals per vertex (position, point area,
//    normal, k1, first direction, k2, second direction), written by
//    curv_frames and rewritten by curv_principal. The tensor and derivative
//    face kernels load each lane's record of a corner as whole vectors (the
//    face index a scalar load, used as an address) and transpose them in
//    registers (ld_rec: log2(SC_LANES) stages of two-vector shuffles per
//    SC_LANES × SC_LANES block). Against one scalar load per lane and value
//    (hardware gathers on AVX-512; 39 values per face in the tensor pass):
//    500k torus, PoCL, tensor corners 16.7 → 10.7 ms, dcurv corners
//    18.5 → 13.6 ms.
//  - Corner stores: the face kernels transpose their component vectors the
//    same way and store each face's 12 reals whole (st_corners).
//  - curv_frames and curv_principal load and store their 3- and 2-real
//    per-vertex buffers as whole vectors, (de)interleaved in registers (ld3c,
//    st3c, st2c), and write the records the same way (st_rec); the host pads
//    every per-vertex buffer to whole blocks of 16 vertices. 500k torus,
//    PoCL: frames with its records 6.2 → 3.3 ms (PoCL's own vectorisation
//    across work-items had gathers and scatters for every value), principal
//    with its records 4.9 → 2.2 ms. Written in separate pack kernels, the
//    records cost 1.7 and 1.4 ms more; written by the one-lane kernels they
//    kept PoCL from vectorising those (frames 8.8 against 6.3 ms).
// Disassembly of PoCL's kernel cache, pthread-skylake-avx512, 16 lanes (the
// work-group function PoCL built for the 500k torus, objdump; instructions /
// of them on zmm registers / shuffles, inserts, extracts and broadcasts /
// gathers / operands on the stack, at %rsp or %rbp):
//   curv_normals_areas_corners   746 /   339 / 190 /  0 /  42
//   curv_tensor_corners        1,456 /   794 / 352 /  0 / 173
//   curv_dcurv_corners         1,724 / 1,009 / 340 /  0 / 267
//   curv_frames                  603 /   331 / 184 / 12 /  45   (owner faces' vertices)
//   curv_principal               534 /   333 / 176 /  0 /  49
//   curv_tensor_sum               51 /     0 /   2 /  0 /   0   (scalar)
// The stack accesses of the tensor and derivative kernels are spills: three
// records of 16 vectors outnumber the 32 registers. Loading each record in
// two halves, the second (frame) half of a corner only where it is
// projected, did not help (500k torus, tensor + dcurv: 25.4–25.7 against
// 24.9–26.8 ms over three interleaved pairs).
// Nor did taking the derivative pass's positions from ld_pos and loading
// each corner's record only once the face frame is known, so that it dies
// after its projection: LLVM scheduled the loads early all the same (1,853
// instructions, 334 on the stack), and lucy's dcurv corners got slower.
// Still scalar: the ring sums (curv_*_sum; their loop keeps PoCL's work-item
// vectoriser off, and written with SC_LANES vertices per work-item, rings
// walked together to the longest, they ran no faster). Intel's CPU runtime
// vectorises across work-items itself; lanes gain less there. Each sum adds
// a corner as one 4-real vector (one vector add, the same bits as four
// scalar adds): lucy 0.27 → 0.24 ms per sum, 500k torus 2.5–2.7 → 2.4–2.6.
// Four consecutive vertices per work-item, their rings walked together to
// the longest with selects (four independent chains, no branch per vertex),
// were slower: lucy 0.24 → 0.25 ms, 500k torus 2.4 → 3.1–3.4 ms per sum. So
// the sums are bound by their loads, not by the latency of their adds.
// Fusing each ring sum with the per-vertex pass after it (normal sum with
// curv_frames, tensor sum with curv_principal, raw sums left unstored) was
// measured slower on PoCL 3.1 (bunny, medians of 41 runs: 0.9 ms against
// 0.48 for the normal sum and frames, 0.6 against 0.4 for the tensor sum and
// principal): the loop of the sum keeps the fused kernel scalar, and the
// frames and principal passes lose their vectorisation. They stay apart.
// Recomputing pd2 = n × pd1 in curv_tensor_corners instead of loading it
// (three scalar loads per lane fewer) gained nothing measurable (0.78
// against 0.80 ms), so the loads stay.
// Storing each corner at its vertex's one-ring position instead (a slot
// map built with the rings, so that each vertex sums a contiguous run, with
// no ring index to load) made the three ring sums 3× faster (torus 2M:
// 19 against 59 ms) but the per-face kernels slower by as much, their whole-
// vector stores becoming one scattered store per lane (tensor corners 71
// against 41 ms): no gain in total, so the corners stay in face order.
// The corners are stored per corner: corner e = 3f + c (a ring entry) has
// its four components at 4e … 4e + 3, so that a ring sum reads a corner as
// one 16-byte vload4 within one cache line, where the earlier layout (one
// lane vector per component) put them on four lines. 500k torus: each ring
// sum 4.4–4.7 → 2.8–3.1 ms on PoCL and 4.5 → 3.0 ms on Intel's runtime. On
// Intel's runtime the form matters: four scalar loads from 4·ring[r] made its
// sums 2.3× slower than the vload4 (and ring entries holding precomputed
// slots, an older trial, 2.7× slower).
// Storing each corner, after the transposes, as one 16-byte piece at its
// vertex's one-ring position was tried again: on the 500k torus each sum
// went 3.6–3.8 → 1.8–2.1 ms and the face kernels lost 0.1–0.9 ms (6–10 %
// faster in all), but on lucy (scanned, in Morton order) the scattered
// stores made the face kernels 1.4× slower (medians of 61 runs: tensor
// corners 1.29 → 1.91 ms) for 0.03–0.13 ms gained per sum. Not kept.
// The LDLᵀ solves of face_tensor and face_dcurv divide by each pivot once
// and multiply by its reciprocal twice (3 and 4 divisions fewer per face; the
// per-face kernels are bound by arithmetic, and a 16-lane division costs
// several multiplications): tensor corners 84 → 78 ms and dcurv corners
// 86 → 79 ms on the 2M torus on PoCL (medians of 4 interleaved processes of
// 7 runs), results within an ulp of the quotients (the CPU twin does the same).
// Memory order matters on scanned meshes too: the host renumbers a
// scattered mesh along a Morton curve first (src/mesh/order.rs). On the
// Stanford bunny (PoCL, medians of 41 runs per kernel) that makes the ring
// sums 1.3× and the tensor and dcurv face kernels 1.2× faster, 15 % in all.
//
// Vectors are structs of scalars (V3, V4) and per-corner values are named
// (e0 e1 e2, a0 a1 a2), never float3/vload3 and never private arrays in the
// one-lane kernels: PoCL's work-item vectoriser gives up on OpenCL vector
// types, private arrays, selects of whole structs, fmax and atomics. (The
// lane kernels are vector code already; their small arrays have constant
// indices after unrolling and live in registers.) Helpers are SC_INLINE
// (always_inline): left to PoCL's inliner, the projections and tensor_at
// stayed calls returning structs through the stack, which cost ~15 % of
// curv_dcurv.
//
// Buffers (V vertices, F faces; REAL is float or double, see real.h):
//   pos   REAL[3V+1] positions, centred and scaled by the host (unit RMS
//                    radius), and one real of padding (ld_pos)
//   faces uint[3F']  triangle vertex indices (F' = F rounded up to 16; the
//                    padding repeats the last face)
//   owner int[V]    owning face (−1: unreferenced vertex)
//   nrm   REAL[3V]  normal (accumulated, then unit)      area REAL[V] point area
//   pd1, pd2 REAL[3V] initial frame, overwritten by principal directions
//   tens  REAL[3V]  curvature tensor (ku, kuv, kv) in the initial frame
//   kk    REAL[2V]  (k1, k2)                              dk REAL[4V] derivative tensor
//   counters uint[4] degenerate faces, vertices without area, tensor and dcurv solves skipped
//   ring_off uint[V+1], ring uint[3F] one-ring (face*3 + corner), gather variant only
//   corner REAL[12F'] per-corner contributions, gather only (F' = F rounded up to
//                    16): corner c of face f, component k at 12f + 4c + k
//                    (CORNER_SLOT); the normal pass's component 3 is the corner area
//   cw    REAL[3F']  gather only: the corner areas (normal pass), then each
//                    corner's weight, corner area ÷ point area (tensor pass),
//                    which the dcurv pass reads instead of recomputing (4 %
//                    on the bunny, mostly divisions); corner c of face f at
//                    L·(3·(f / L) + c) + f % L (L = SC_LANES): whole vectors.
//                    (In the corner buffer's component 3, read one lane at a
//                    time, they cost 3 ms more on the 500k torus.)
//   rec   REAL[16V'] gather with lanes only: vertex records (REC_*, above)
// With lanes the per-vertex buffers hold V' = V rounded up to 16 vertices
// (owner −1 in the padding); nothing reads the padding's results.
//
// Degenerate faces (an edge shorter than 1e-12 of the mesh's RMS radius,
// twice the area below 5e-8 × Σ edge², or 2A/√(Σ edge²) below the f32
// rounding of the positions, 2⁻²³·Σ|p|) are skipped in every pass and
// counted once; the rule is the same at every precision and in the CPU twin. A least-squares system whose pivots are not positive (rounding
// on extreme slivers) is skipped and counted. Nothing here can write NaN.
//
// Build options: -DSC_GATHER (the gather scheme: the program holds the
// corner and ring-sum kernels and not the atomic ones, and the reverse without
// it; the program PoCL 3.1 builds from source is then about 5 % quicker to
// build, 650-710 against 680-750 ms on the bunny with an empty kernel cache,
// and no quicker from its warm cache), -DSC_LANES=N (above),
// -DSC_DOUBLE (double precision), -DSC_COMPAT (trimesh2 2.16:
// its 3×3 LDLᵀ third pivot Σv² instead of Σv² − (Σuv)²/d1, and |k1| ≥ |k2|
// ordering instead of k1 ≥ k2).
// Shared with the host (src/spec/curvature.rs): Accumulate::Gather ↔
// SC_GATHER, Precision::F64 ↔ SC_DOUBLE, Compat::Trimesh2 ↔ SC_COMPAT, the
// counters uint[4] in CurvatureCounts order.

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

#define NEXT3(i) ((i) == 2 ? 0 : (i) + 1)
#define PREV3(i) ((i) == 0 ? 2 : (i) - 1)

// ---------------------------------------------------------------------------
// Types. The geometry of kernels/common/curvature_face.h is instantiated on
// scalars for every kernel and, with SC_LANES > 1 (CPU devices; the host
// picks the count), on vectors of SC_LANES lanes for the gather variant's
// per-face kernels, which then handle SC_LANES consecutive faces per
// work-item (see the file header).

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

// The positions of face f's corners, and their indices.
SC_INLINE Tri load_tri(__global const REAL *pos, __global const uint *faces, uint f, uint *v0,
                       uint *v1, uint *v2)
{
    *v0 = faces[3 * f];
    *v1 = faces[3 * f + 1];
    *v2 = faces[3 * f + 2];
    return make_tri(ld3(pos, *v0), ld3(pos, *v1), ld3(pos, *v2));
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

// The corner areas (then weights) of corner c of the block's faces: one
// whole vector (see `cw` in the file header).
#define CW_LD(c) VLOADN(3 * blk + (c), cw)
#define CW_ST(x, c) VSTOREN((x), 3 * blk + (c), cw)

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

#define CW_LD(c) cw[3 * blk + (c)]
#define CW_ST(x, c) (cw[3 * blk + (c)] = (x))

#define FACE_BLOCK_OR_RETURN(nf)  \
    GID_OR_RETURN(nf);            \
    const uint blk = gid;         \
    const int live = 1;           \
    const FIDX fid = gid;

// The three corners of face f, each at 4·(3f + c) (see CORNER_SLOT).
SC_INLINE void st_corners(__global REAL *corner, uint f, V4 x0, V4 x1, V4 x2)
{
    __global REAL *p = corner + 12 * f;
    p[0] = x0.x;
    p[1] = x0.y;
    p[2] = x0.z;
    p[3] = x0.w;
    p[4] = x1.x;
    p[5] = x1.y;
    p[6] = x1.z;
    p[7] = x1.w;
    p[8] = x2.x;
    p[9] = x2.y;
    p[10] = x2.z;
    p[11] = x2.w;
}

SC_INLINE void count_lanes(volatile __global uint *c, FMASK m, int live)
{
    if (m & live)
        atomic_inc(c);
}
#endif

// The corner slot of face f's corner c, component k: corner e = 3f + c has
// its four components at 4e … 4e + 3, so that a ring sum reads a corner as
// one 16-byte run (for every lane count).
#define CORNER_SLOT(f, c, k) (12 * (f) + 4 * (c) + (k))


// ---------------------------------------------------------------------------
// Topology pass (once per mesh).

__kernel void curv_max_face(uint nf, __global const uint *faces, volatile __global int *owner)
{
    GID_OR_RETURN(nf);
    for (int i = 0; i < 3; i++)
        atomic_max(&owner[faces[3 * gid + i]], (int)gid);
}

// ---------------------------------------------------------------------------
// Per-vertex passes (both variants).

#if SC_LANES > 1
// Vertex records: what the tensor and derivative face kernels read of each
// vertex, 16 reals in one 16-real-aligned run, so that a face block loads a
// vertex of each lane as whole vectors and transposes them in registers
// (ld_rec) instead of one scalar load per lane and value. Record offsets are
// computed in size_t (16 reals per vertex pass 32 bits at 2^28 vertices).
// curv_frames writes the records with the position, area, normal and
// initial frame, and curv_principal rewrites them with the principal
// curvatures and directions: the same values as in the per-vertex buffers,
// transposed in registers from the kernels' lane vectors (st_rec) and
// stored whole.
#define REC_POS 0  // x y z; area at 3
#define REC_AREA 3
#define REC_NRM 4  // x y z; k1 at 7
#define REC_K1 7
#define REC_PD1 8  // x y z; k2 at 11
#define REC_K2 11
#define REC_PD2 12 // x y z; 15 is zero

// An SC_LANES × SC_LANES transpose of the rows r0 … r(SC_LANES−1) in
// log2(SC_LANES) stages; stage b swaps the off-diagonal b × b blocks of each
// 2b × 2b block (bit b of the row index with bit b of the column index).
// Each swap is two two-vector shuffles with constant indices.
#define SC_LO(j, b) (((j) & (b)) ? SC_LANES + (j) - (b) : (j))
#define SC_HI(j, b) (((j) & (b)) ? SC_LANES + (j) : (j) + (b))
#define SC_SWAP(x, y, b)                                                   \
    {                                                                      \
        REALN lo_ = __builtin_shufflevector(x, y, SC_JLIST(SC_LO, b));     \
        y = __builtin_shufflevector(x, y, SC_JLIST(SC_HI, b));             \
        x = lo_;                                                           \
    }
#if SC_LANES == 2
#define SC_ROWS(F) F(0, s0) F(1, s1)
#define SC_TRANSPOSE() SC_SWAP(r0, r1, 1)
#elif SC_LANES == 4
#define SC_ROWS(F) F(0, s0) F(1, s1) F(2, s2) F(3, s3)
#define SC_TRANSPOSE()                                                     \
    SC_SWAP(r0, r2, 2) SC_SWAP(r1, r3, 2) SC_SWAP(r0, r1, 1) SC_SWAP(r2, r3, 1)
#elif SC_LANES == 8
#define SC_ROWS(F) F(0, s0) F(1, s1) F(2, s2) F(3, s3) F(4, s4) F(5, s5) F(6, s6) F(7, s7)
#define SC_TRANSPOSE()                                                              \
    SC_SWAP(r0, r4, 4) SC_SWAP(r1, r5, 4) SC_SWAP(r2, r6, 4) SC_SWAP(r3, r7, 4)     \
    SC_SWAP(r0, r2, 2) SC_SWAP(r1, r3, 2) SC_SWAP(r4, r6, 2) SC_SWAP(r5, r7, 2)     \
    SC_SWAP(r0, r1, 1) SC_SWAP(r2, r3, 1) SC_SWAP(r4, r5, 1) SC_SWAP(r6, r7, 1)
#else
#define SC_ROWS(F)                                                                          \
    F(0, s0) F(1, s1) F(2, s2) F(3, s3) F(4, s4) F(5, s5) F(6, s6) F(7, s7) F(8, s8)          \
    F(9, s9) F(10, sa) F(11, sb) F(12, sc) F(13, sd) F(14, se) F(15, sf)
#define SC_TRANSPOSE()                                                                  \
    SC_SWAP(r0, r8, 8) SC_SWAP(r1, r9, 8) SC_SWAP(r2, r10, 8) SC_SWAP(r3, r11, 8)       \
    SC_SWAP(r4, r12, 8) SC_SWAP(r5, r13, 8) SC_SWAP(r6, r14, 8) SC_SWAP(r7, r15, 8)     \
    SC_SWAP(r0, r4, 4) SC_SWAP(r1, r5, 4) SC_SWAP(r2, r6, 4) SC_SWAP(r3, r7, 4)         \
    SC_SWAP(r8, r12, 4) SC_SWAP(r9, r13, 4) SC_SWAP(r10, r14, 4) SC_SWAP(r11, r15, 4)   \
    SC_SWAP(r0, r2, 2) SC_SWAP(r1, r3, 2) SC_SWAP(r4, r6, 2) SC_SWAP(r5, r7, 2)         \
    SC_SWAP(r8, r10, 2) SC_SWAP(r9, r11, 2) SC_SWAP(r12, r14, 2) SC_SWAP(r13, r15, 2)   \
    SC_SWAP(r0, r1, 1) SC_SWAP(r2, r3, 1) SC_SWAP(r4, r5, 1) SC_SWAP(r6, r7, 1)         \
    SC_SWAP(r8, r9, 1) SC_SWAP(r10, r11, 1) SC_SWAP(r12, r13, 1) SC_SWAP(r14, r15, 1)
#endif

// The records of the vertices v (one per lane), as 16 vectors: component k
// of every lane's record in c[k]. Each record is 16 / SC_LANES whole-vector
// loads; each chunk of SC_LANES components is one transpose.
typedef struct {
    FREAL c[16];
} RecN;
#define SC_LD_ROW(l, s) \
    FREAL r##l = VLOADN((size_t)faces[3 * (f0 + l) + c] * (16 / SC_LANES) + q, rec);
#define SC_PUT_ROW(l, s) o.c[q * SC_LANES + l] = r##l;
// The records of corner c's vertices of face block blk (the faces buffer
// holds whole blocks: the host repeats the last face in its padding, as
// FACE_BLOCK_OR_RETURN repeats it in lanes past the last face); the face
// indices are scalar loads with constant offsets, used as addresses only.
SC_INLINE RecN ld_rec(__global const REAL *rec, __global const uint *faces, uint blk, uint c)
{
    const uint f0 = SC_LANES * blk;
    RecN o;
#pragma unroll
    for (uint q = 0; q < 16 / SC_LANES; q++) {
        SC_ROWS(SC_LD_ROW)
        SC_TRANSPOSE()
        SC_ROWS(SC_PUT_ROW)
    }
    return o;
}
SC_INLINE FV3 rec3(RecN a, int k) { return v3(a.c[k], a.c[k + 1], a.c[k + 2]); }
// vertex_coef and vertex_curv_by from a vertex's record.
SC_INLINE FV4 rec_coef(RecN a, FV3 ft, FV3 fb)
{
    return proj_coef(rec3(a, REC_PD1), rec3(a, REC_PD2), ft, fb);
}
SC_INLINE FV3 rec_curv_by(RecN a, FV4 c)
{
    return proj_curv_by(c, v3(a.c[REC_K1], (FREAL)RL(0), a.c[REC_K2]));
}
// tensor_w from a vertex's record.
SC_INLINE FV3 rec_tensor_w(RecN a, FREAL w, FV3 ft, FV3 fb, FV3 x)
{
    return mul3(proj_curv(ft, fb, x, rec3(a, REC_PD1), rec3(a, REC_PD2)), w);
}

// The start of the tensor and derivative face kernels with lanes, of either
// scheme (as LOAD_FACE_BLOCK for one lane): the records a0 a1 a2 of the
// block's corners, its triangle t, the degenerate lanes deg and the face
// frame ft fb.
#define REC_FACE_BLOCK(rec, faces)                                              \
    RecN a0 = ld_rec(rec, faces, blk, 0), a1 = ld_rec(rec, faces, blk, 1),      \
         a2 = ld_rec(rec, faces, blk, 2);                                       \
    FTri t = make_tri(rec3(a0, REC_POS), rec3(a1, REC_POS), rec3(a2, REC_POS)); \
    FMASK deg = tri_degenerate(t);                                              \
    FV3 ft, fb;                                                                 \
    face_frame(t, &ft, &fb);
// The tensor pass's face solve (after REC_FACE_BLOCK): x, and ok where it
// was solved.
#define REC_TENSOR_SOLVE()                                                      \
    FV3 x;                                                                      \
    FMASK ok = face_tensor(t, ft, fb, rec3(a0, REC_NRM), rec3(a1, REC_NRM),     \
                           rec3(a2, REC_NRM), &x);
// The derivative pass's (after REC_FACE_BLOCK): the projection coefficients
// q0 q1 q2 of the corners, x, and ok.
#define REC_DCURV_SOLVE()                                                       \
    FV4 x;                                                                      \
    FV4 q0 = rec_coef(a0, ft, fb), q1 = rec_coef(a1, ft, fb),                   \
        q2 = rec_coef(a2, ft, fb);                                              \
    FMASK ok = face_dcurv(t, ft, fb, rec_curv_by(a0, q0), rec_curv_by(a1, q1),  \
                          rec_curv_by(a2, q2), &x);

// The positions of corner c's vertices of face block blk, as lane vectors:
// each lane's x y z (and the next vertex's x, unused) is one 4-real load
// addressed through a scalar face-index load (the pos buffer has one real of
// padding past its last vertex), and the SC_LANES rows of 4 are transposed in
// registers, instead of one hardware gather per component and face index.
// The rows' stream is first gathered into four whole vectors a0 … a3
// (elements 4l … 4l + 3 are lane l's row), then component k of lane j is
// picked from a0 a1 (lanes of the first half) or a2 a3 (second half).
#define SC_C2(x, y) __builtin_shufflevector(x, y, 0, 1, 2, 3, 4, 5, 6, 7)
#define SC_C4(x, y) \
    __builtin_shufflevector(x, y, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15)
#define SC_P01(j, k) (4 * (j) + (k) < 2 * SC_LANES ? 4 * (j) + (k) : 0)
#define SC_P23(j, k) (4 * (j) + (k) >= 2 * SC_LANES ? 4 * (j) + (k) - 2 * SC_LANES : 0)
#define SC_PSEL(j, b) (2 * (j) < SC_LANES ? (j) : SC_LANES + (j))
#define SC_POS_K(k)                                                                   \
    __builtin_shufflevector(__builtin_shufflevector(a0, a1, SC_JLIST(SC_P01, k)),     \
                            __builtin_shufflevector(a2, a3, SC_JLIST(SC_P23, k)),     \
                            SC_JLIST(SC_PSEL, 0))
// x y z of lane l's row p[l], as lane vectors.
SC_INLINE FV3 rows_v3(const REAL4 *p)
{
#if SC_LANES == 16
    const REALN a0 = SC_C4(SC_C2(p[0], p[1]), SC_C2(p[2], p[3])),
                a1 = SC_C4(SC_C2(p[4], p[5]), SC_C2(p[6], p[7])),
                a2 = SC_C4(SC_C2(p[8], p[9]), SC_C2(p[10], p[11])),
                a3 = SC_C4(SC_C2(p[12], p[13]), SC_C2(p[14], p[15]));
#elif SC_LANES == 8
    const REALN a0 = SC_C2(p[0], p[1]), a1 = SC_C2(p[2], p[3]), a2 = SC_C2(p[4], p[5]),
                a3 = SC_C2(p[6], p[7]);
#elif SC_LANES == 4
    const REALN a0 = p[0], a1 = p[1], a2 = p[2], a3 = p[3];
#else
    const REALN a0 = p[0].lo, a1 = p[0].hi, a2 = p[1].lo, a3 = p[1].hi;
#endif
    return v3(SC_POS_K(0), SC_POS_K(1), SC_POS_K(2));
}
#define SC_LD_POS_ROW(l, s) p[l] = vload4(0, pos + 3 * (size_t)faces[3 * (f0 + l) + c]);
SC_INLINE FV3 ld_pos(__global const REAL *pos, __global const uint *faces, uint blk, uint c)
{
    const uint f0 = SC_LANES * blk;
    REAL4 p[SC_LANES];
    SC_ROWS(SC_LD_POS_ROW)
    return rows_v3(p);
}
// The triangles of face block blk from the positions (ld_pos per corner).
SC_INLINE FTri ld_pos_tri(__global const REAL *pos, __global const uint *faces, uint blk)
{
    return make_tri(ld_pos(pos, faces, blk, 0), ld_pos(pos, faces, blk, 1),
                    ld_pos(pos, faces, blk, 2));
}

// The records of vertex block blk (SC_LANES consecutive vertices), component
// k of every lane in x[k]: each chunk of SC_LANES components is transposed
// and stored as whole vectors.
#define SC_GET_ROW(l, s) FREAL r##l = x[q * SC_LANES + l];
#define SC_ST_REC_ROW(l, s) VSTOREN(r##l, 0, rec + 16 * (size_t)(v0 + l) + q * SC_LANES);
SC_INLINE void st_rec(__global REAL *rec, uint blk, const FREAL *x)
{
    const uint v0 = SC_LANES * blk;
#pragma unroll
    for (uint q = 0; q < 16 / SC_LANES; q++) {
        SC_ROWS(SC_GET_ROW)
        SC_TRANSPOSE()
        SC_ROWS(SC_ST_REC_ROW)
    }
}
// The record of a vertex from its values (component 15 is zero).
#define REC_OF(p, a, n, k1, d1, k2, d2)                                                     \
    {p.x, p.y, p.z, a, n.x, n.y, n.z, k1, d1.x, d1.y, d1.z, k2, d2.x, d2.y, d2.z, (FREAL)RL(0)}

// The corners of face block blk, x_c holding corner c of every lane's face:
// the 12 component vectors (and 4 of zeros) transposed in registers into
// each face's 12 reals at CORNER_SLOT, stored as whole vectors.
#if SC_LANES == 16
#define SC_ST_ROW(l, s)                                 \
    vstore8(r##l.lo, 0, corner + 12 * (f0 + l));        \
    vstore4(r##l.s89ab, 0, corner + 12 * (f0 + l) + 8);
#elif SC_LANES == 8
#define SC_ST_ROW(l, s)                                 \
    if (q == 0)                                         \
        vstore8(r##l, 0, corner + 12 * (f0 + l));       \
    else                                                \
        vstore4(r##l.lo, 0, corner + 12 * (f0 + l) + 8);
#else
#define SC_ST_ROW(l, s) VSTOREN(r##l, 0, corner + 12 * (f0 + l) + q * SC_LANES);
#endif
SC_INLINE void st_corners(__global REAL *corner, uint blk, FV4 x0, FV4 x1, FV4 x2)
{
    const uint f0 = SC_LANES * blk;
    const FREAL z = (FREAL)RL(0);
    const FREAL x[16] = {x0.x, x0.y, x0.z, x0.w, x1.x, x1.y, x1.z, x1.w,
                         x2.x, x2.y, x2.z, x2.w, z,    z,    z,    z};
#pragma unroll
    for (uint q = 0; q < 12 / SC_LANES + (12 % SC_LANES != 0); q++) {
        SC_ROWS(SC_GET_ROW)
        SC_TRANSPOSE()
        SC_ROWS(SC_ST_ROW)
    }
}
#endif // SC_LANES > 1

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
// Atomic (scatter) variant: one work-item per face (or per block of SC_LANES
// faces), float atomics on the one-ring.
// A program holds the kernels of one scheme: these without SC_GATHER, the
// gather kernels below with it (the host sets it for the gather scheme).
#ifndef SC_GATHER

__kernel void curv_clear(uint nv, __global REAL *nrm, __global REAL *area, __global REAL *tens,
                         __global REAL *dk)
{
    GID_OR_RETURN(nv);
    st3(v3(RL(0), RL(0), RL(0)), gid, nrm);
    area[gid] = 0;
    st3(v3(RL(0), RL(0), RL(0)), gid, tens);
    dk[4 * gid] = 0;
    dk[4 * gid + 1] = 0;
    dk[4 * gid + 2] = 0;
    dk[4 * gid + 3] = 0;
}

// With SC_PAIR_ADDS, a vertex's 3 reals take one pair add and one single
// (the pair at 3v for even v, at 3v + 1 for odd v: 8-byte aligned either
// way) and its 4 reals two pair adds: 11 locked operations per face corner
// become 7.
SC_INLINE void atomic_add3(volatile __global REAL *a, uint v, V3 x)
{
#ifdef SC_PAIR_ADDS
    if (v & 1) {
        atomic_add_real(&a[3 * v], x.x);
        atomic_add_pair(&a[3 * v + 1], x.y, x.z);
    } else {
        atomic_add_pair(&a[3 * v], x.x, x.y);
        atomic_add_real(&a[3 * v + 2], x.z);
    }
#else
    atomic_add_real(&a[3 * v], x.x);
    atomic_add_real(&a[3 * v + 1], x.y);
    atomic_add_real(&a[3 * v + 2], x.z);
#endif
}

SC_INLINE void atomic_add4(volatile __global REAL *a, uint v, V4 x)
{
#ifdef SC_PAIR_ADDS
    atomic_add_pair(&a[4 * v], x.x, x.y);
    atomic_add_pair(&a[4 * v + 2], x.z, x.w);
#else
    atomic_add_real(&a[4 * v], x.x);
    atomic_add_real(&a[4 * v + 1], x.y);
    atomic_add_real(&a[4 * v + 2], x.z);
    atomic_add_real(&a[4 * v + 3], x.w);
#endif
}

#if SC_LANES == 1
__kernel void curv_normals_areas(uint nf, __global const REAL *pos, __global const uint *faces,
                                 volatile __global REAL *nrm, volatile __global REAL *area,
                                 volatile __global uint *counters)
{
    GID_OR_RETURN(nf);
    uint v0, v1, v2;
    Tri t = load_tri(pos, faces, gid, &v0, &v1, &v2);
    if (tri_degenerate(t)) {
        atomic_inc(&counters[0]);
        return;
    }
    V3 ca = corner_areas(t), fn = face_normal(t);
    REAL l0 = dot3(t.e0, t.e0), l1 = dot3(t.e1, t.e1), l2 = dot3(t.e2, t.e2);
    atomic_add3(nrm, v0, corner_normal(fn, l1, l2));
    atomic_add3(nrm, v1, corner_normal(fn, l2, l0));
    atomic_add3(nrm, v2, corner_normal(fn, l0, l1));
    atomic_add_real(&area[v0], ca.x);
    atomic_add_real(&area[v1], ca.y);
    atomic_add_real(&area[v2], ca.z);
}

__kernel void curv_tensor(uint nf, __global const REAL *pos, __global const uint *faces,
                          __global const REAL *nrm, __global const REAL *area,
                          __global const REAL *pd1, __global const REAL *pd2,
                          volatile __global REAL *tens, volatile __global uint *counters)
{
    GID_OR_RETURN(nf);
    uint v0, v1, v2;
    Tri t = load_tri(pos, faces, gid, &v0, &v1, &v2);
    if (tri_degenerate(t))
        return;
    V3 ft, fb, x;
    face_frame(t, &ft, &fb);
    if (!face_tensor(t, ft, fb, ld3(nrm, v0), ld3(nrm, v1), ld3(nrm, v2), &x)) {
        atomic_inc(&counters[2]);
        return;
    }
    V3 ca = corner_areas(t);
    atomic_add3(tens, v0, tensor_at(pd1, pd2, area, v0, ca.x, ft, fb, x));
    atomic_add3(tens, v1, tensor_at(pd1, pd2, area, v1, ca.y, ft, fb, x));
    atomic_add3(tens, v2, tensor_at(pd1, pd2, area, v2, ca.z, ft, fb, x));
}

__kernel void curv_dcurv(uint nf, __global const REAL *pos, __global const uint *faces,
                         __global const REAL *area, __global const REAL *pd1,
                         __global const REAL *pd2, __global const REAL *kk,
                         volatile __global REAL *dk, volatile __global uint *counters)
{
    GID_OR_RETURN(nf);
    uint v0, v1, v2;
    Tri t = load_tri(pos, faces, gid, &v0, &v1, &v2);
    if (tri_degenerate(t))
        return;
    V3 ft, fb;
    V4 x;
    face_frame(t, &ft, &fb);
    V4 q0 = vertex_coef(pd1, pd2, v0, ft, fb), q1 = vertex_coef(pd1, pd2, v1, ft, fb),
       q2 = vertex_coef(pd1, pd2, v2, ft, fb);
    if (!face_dcurv(t, ft, fb, vertex_curv_by(kk, v0, q0), vertex_curv_by(kk, v1, q1),
                    vertex_curv_by(kk, v2, q2), &x)) {
        atomic_inc(&counters[3]);
        return;
    }
    V3 ca = corner_areas(t);
    atomic_add4(dk, v0, dcurv_by(q0, corner_weight(ca.x, area[v0]), x));
    atomic_add4(dk, v1, dcurv_by(q1, corner_weight(ca.y, area[v1]), x));
    atomic_add4(dk, v2, dcurv_by(q2, corner_weight(ca.z, area[v2]), x));
}

#else // SC_LANES > 1
// With lanes (CPU devices): SC_LANES consecutive faces per work-item, their
// arithmetic the lane code of the gather kernels below (positions through
// ld_pos, the vertex records through ld_rec, the same helpers), and then
// each lane's corners added to their vertices one float atomic add per value
// (scatter_*), lane after lane, for the lanes whose face is used. The adds
// stay scalar; what they save is the scalar arithmetic: with one face per
// work-item PoCL 3.1 leaves these kernels unvectorised (an atomic stops its
// work-item vectoriser), and with the compare-and-swap adds replaced by
// plain ones (a timing probe, wrong results) the scheme took 5.9-6.5 of its
// 7.8 ms on the bunny. With lanes (medians of 11-21 runs, interleaved
// processes): PoCL, bunny 8.4-8.7 -> 7.0-7.6 ms, lucy 11.3 -> 8.4-8.8,
// 500k torus 114 -> 87 (tensor 34 -> 23, dcurv 44 -> 31; the normal pass,
// almost all adds, 29 -> 28 there and 2.2 -> 2.7-2.9 on the bunny); Intel's
// runtime, bunny 8.0 -> 5.9 ms, 500k torus 120 -> 88 (native float adds
// 6.5 -> 5.9 and 98 -> 88). What remained was the adds: about 5.5-6.5 ns
// of a core per add (the bunny's tensor pass: 625,000 adds in 1.75 ms on 2
// cores), scalar, each a read, an add and a locked compare-and-swap. Pair
// adds (SC_PAIR_ADDS, kernels/common/atomics.h: two adjacent floats in one
// 64-bit compare-and-swap, 7 locked operations per face corner instead of
// 11) then took, with 16 lanes (medians of 11-21 runs, 3 interleaved pairs
// of processes): PoCL, bunny 6.2 -> 4.2-4.6 ms (tensor 1.71 -> 1.22, dcurv
// 2.27 -> 1.30, normals 2.03 -> 1.55), lucy 9.0-10.5 -> 6.1-7.3, 500k torus
// 92.6 -> 65.6; Intel's runtime, bunny 6.3 -> 4.3, 500k torus 92 -> 63.
// Summing each run of lanes that share a vertex before its add (below) then
// took PoCL's bunny 4.02 -> 3.56 ms, lucy 5.77 -> 5.24, 500k torus
// 60.6 -> 47.1 (3 interleaved pairs of processes, medians of 21 runs).
// The lanes are added in order, and a run of used lanes whose corner goes
// to one vertex (consecutive faces sorted by their first vertex share it)
// is summed in registers and added once (SC_FLUSH: a, b the accumulators).
#define SC_RUN_STEP(l, s_)                                                    \
    if (m.s_) {                                                               \
        if (have && v.s_ == cur) {                                            \
            r0 += x.x.s_;                                                     \
            r1 += x.y.s_;                                                     \
            r2 += x.z.s_;                                                     \
            r3 += x.w.s_;                                                     \
        } else {                                                              \
            if (have)                                                         \
                SC_FLUSH(cur);                                                \
            cur = v.s_;                                                       \
            have = true;                                                      \
            r0 = x.x.s_;                                                      \
            r1 = x.y.s_;                                                      \
            r2 = x.z.s_;                                                      \
            r3 = x.w.s_;                                                      \
        }                                                                     \
    }
#define SC_RUN_BODY                                                           \
    uint cur = 0;                                                             \
    bool have = false;                                                        \
    REAL r0 = RL(0), r1 = RL(0), r2 = RL(0), r3 = RL(0);                      \
    SC_ROWS(SC_RUN_STEP)                                                      \
    if (have)                                                                 \
        SC_FLUSH(cur);
// normal (a) and area (b)
#define SC_FLUSH(c)                                                           \
    {                                                                         \
        atomic_add3(a, c, v3(r0, r1, r2));                                    \
        atomic_add_real(&b[c], r3);                                           \
    }
SC_INLINE void scatter_na(volatile __global REAL *a, volatile __global REAL *b, FIDX v, FV4 x,
                          INTN m)
{
    SC_RUN_BODY
}
#undef SC_FLUSH
#define SC_FLUSH(c) atomic_add3(a, c, v3(r0, r1, r2))
SC_INLINE void scatter3(volatile __global REAL *a, FIDX v, FV3 x3, INTN m)
{
    const FV4 x = ext4(x3, (FREAL)RL(0));
    SC_RUN_BODY
}
#undef SC_FLUSH
#define SC_FLUSH(c) atomic_add4(a, c, v4(r0, r1, r2, r3))
SC_INLINE void scatter4(volatile __global REAL *a, FIDX v, FV4 x, INTN m)
{
    SC_RUN_BODY
}
#undef SC_FLUSH

__kernel void curv_normals_areas(uint nf, __global const REAL *pos, __global const uint *faces,
                                 volatile __global REAL *nrm, volatile __global REAL *area,
                                 volatile __global uint *counters)
{
    FACE_BLOCK_OR_RETURN(nf);
    FTri t = ld_pos_tri(pos, faces, blk);
    FMASK deg = tri_degenerate(t);
    FV3 ca = corner_areas(t), fn = face_normal(t);
    FREAL l0 = dot3(t.e0, t.e0), l1 = dot3(t.e1, t.e1), l2 = dot3(t.e2, t.e2);
    INTN m = CONVERT_INTN(!deg) & live;
    scatter_na(nrm, area, ldu(faces, 3 * fid), ext4(corner_normal(fn, l1, l2), ca.x), m);
    scatter_na(nrm, area, ldu(faces, 3 * fid + 1), ext4(corner_normal(fn, l2, l0), ca.y), m);
    scatter_na(nrm, area, ldu(faces, 3 * fid + 2), ext4(corner_normal(fn, l0, l1), ca.z), m);
    count_lanes(&counters[0], deg, live);
}

__kernel void curv_tensor(uint nf, __global const REAL *rec, __global const uint *faces,
                          volatile __global REAL *tens, volatile __global uint *counters)
{
    FACE_BLOCK_OR_RETURN(nf);
    REC_FACE_BLOCK(rec, faces)
    REC_TENSOR_SOLVE()
    INTN m = CONVERT_INTN((!deg) & ok) & live;
    FV3 ca = corner_areas(t);
    FREAL w0 = corner_weight(ca.x, a0.c[REC_AREA]);
    FREAL w1 = corner_weight(ca.y, a1.c[REC_AREA]);
    FREAL w2 = corner_weight(ca.z, a2.c[REC_AREA]);
    FV3 c0 = rec_tensor_w(a0, w0, ft, fb, x);
    FV3 c1 = rec_tensor_w(a1, w1, ft, fb, x);
    FV3 c2 = rec_tensor_w(a2, w2, ft, fb, x);
    scatter3(tens, ldu(faces, 3 * fid), c0, m);
    scatter3(tens, ldu(faces, 3 * fid + 1), c1, m);
    scatter3(tens, ldu(faces, 3 * fid + 2), c2, m);
    count_lanes(&counters[2], (!deg) & (!ok), live);
}

__kernel void curv_dcurv(uint nf, __global const REAL *rec, __global const uint *faces,
                         volatile __global REAL *dk, volatile __global uint *counters)
{
    FACE_BLOCK_OR_RETURN(nf);
    REC_FACE_BLOCK(rec, faces)
    REC_DCURV_SOLVE()
    INTN m = CONVERT_INTN((!deg) & ok) & live;
    FV3 ca = corner_areas(t);
    FV4 c0 = dcurv_by(q0, corner_weight(ca.x, a0.c[REC_AREA]), x);
    FV4 c1 = dcurv_by(q1, corner_weight(ca.y, a1.c[REC_AREA]), x);
    FV4 c2 = dcurv_by(q2, corner_weight(ca.z, a2.c[REC_AREA]), x);
    scatter4(dk, ldu(faces, 3 * fid), c0, m);
    scatter4(dk, ldu(faces, 3 * fid + 1), c1, m);
    scatter4(dk, ldu(faces, 3 * fid + 2), c2, m);
    count_lanes(&counters[3], (!deg) & (!ok), live);
}
#endif // SC_LANES > 1

#endif // !SC_GATHER

#ifdef SC_GATHER
// ---------------------------------------------------------------------------
// Gather variant. Face kernels: no atomics, no inner loops, no arrays, and
// SC_LANES faces per work-item (one face block); a skipped face writes zeros
// (st_corner) and sets its status bit. Sum kernels: each vertex adds its
// corners in face order and counts each skipped face once, at the face's
// corner 0.

// The corner indices and positions of a face block.
#define LOAD_FACE_BLOCK(pos, faces)                                                \
    FIDX v0 = ldu(faces, 3 * fid), v1 = ldu(faces, 3 * fid + 1),                   \
         v2 = ldu(faces, 3 * fid + 2);                                             \
    FTri t = make_tri(ld3(pos, v0), ld3(pos, v1), ld3(pos, v2));


__kernel void curv_normals_areas_corners(uint nf, __global const REAL *pos,
                                         __global const uint *faces, __global REAL *corner,
                                         __global REAL *cw,
                                         volatile __global uint *counters)
{
    FACE_BLOCK_OR_RETURN(nf);
#if SC_LANES > 1
    FTri t = ld_pos_tri(pos, faces, blk);
#else
    LOAD_FACE_BLOCK(pos, faces);
#endif
    FMASK deg = tri_degenerate(t);
    FMASK use = !deg;
    FV3 ca = corner_areas(t), fn = face_normal(t);
    FREAL l0 = dot3(t.e0, t.e0), l1 = dot3(t.e1, t.e1), l2 = dot3(t.e2, t.e2);
    FV4 x0 = zero_unless(use, ext4(corner_normal(fn, l1, l2), ca.x)),
        x1 = zero_unless(use, ext4(corner_normal(fn, l2, l0), ca.y)),
        x2 = zero_unless(use, ext4(corner_normal(fn, l0, l1), ca.z));
    st_corners(corner, blk, x0, x1, x2);
    CW_ST(x0.w, 0);
    CW_ST(x1.w, 1);
    CW_ST(x2.w, 2);
    count_lanes(&counters[0], deg, live);
}

#if SC_LANES > 1
// The lane forms of the tensor and derivative face kernels read the vertex
// records (ld_rec) instead of pos, nrm, area, pd1, pd2 and kk; the same
// values, the same arithmetic, the same bits.
__kernel void curv_tensor_corners(uint nf, __global const REAL *rec, __global const uint *faces,
                                  __global REAL *corner, __global REAL *cw,
                                  volatile __global uint *counters)
{
    FACE_BLOCK_OR_RETURN(nf);
    REC_FACE_BLOCK(rec, faces)
    REC_TENSOR_SOLVE()
    FMASK use = (!deg) & ok;
    FREAL w0 = corner_weight(CW_LD(0), a0.c[REC_AREA]);
    FREAL w1 = corner_weight(CW_LD(1), a1.c[REC_AREA]);
    FREAL w2 = corner_weight(CW_LD(2), a2.c[REC_AREA]);
    FV3 c0 = rec_tensor_w(a0, w0, ft, fb, x);
    FV3 c1 = rec_tensor_w(a1, w1, ft, fb, x);
    FV3 c2 = rec_tensor_w(a2, w2, ft, fb, x);
    st_corners(corner, blk, zero_unless(use, ext4(c0, (FREAL)RL(0))),
               zero_unless(use, ext4(c1, (FREAL)RL(0))), zero_unless(use, ext4(c2, (FREAL)RL(0))));
    FREAL z = (FREAL)RL(0);
    CW_ST(!deg ? w0 : z, 0);
    CW_ST(!deg ? w1 : z, 1);
    CW_ST(!deg ? w2 : z, 2);
    count_lanes(&counters[2], (!deg) & (!ok), live);
}

__kernel void curv_dcurv_corners(uint nf, __global const REAL *rec, __global const uint *faces,
                                 __global REAL *corner, __global REAL *cw,
                                 volatile __global uint *counters)
{
    FACE_BLOCK_OR_RETURN(nf);
    REC_FACE_BLOCK(rec, faces)
    REC_DCURV_SOLVE()
    FMASK use = (!deg) & ok;
    FREAL w0 = CW_LD(0), w1 = CW_LD(1), w2 = CW_LD(2);
    FV4 c0 = dcurv_by(q0, w0, x), c1 = dcurv_by(q1, w1, x), c2 = dcurv_by(q2, w2, x);
    st_corners(corner, blk, zero_unless(use, c0), zero_unless(use, c1), zero_unless(use, c2));
    count_lanes(&counters[3], (!deg) & (!ok), live);
}
#else
__kernel void curv_tensor_corners(uint nf, __global const REAL *pos, __global const uint *faces,
                                  __global const REAL *nrm, __global const REAL *area,
                                  __global const REAL *pd1, __global const REAL *pd2,
                                  __global REAL *corner, __global REAL *cw,
                                  volatile __global uint *counters)
{
    FACE_BLOCK_OR_RETURN(nf);
    LOAD_FACE_BLOCK(pos, faces);
    FMASK deg = tri_degenerate(t);
    FV3 ft, fb, x;
    face_frame(t, &ft, &fb);
    FMASK ok = face_tensor(t, ft, fb, ld3(nrm, v0), ld3(nrm, v1), ld3(nrm, v2), &x);
    FMASK use = (!deg) & ok;
    // The corner areas the normal pass stored (component 3 of each corner;
    // zero for degenerate faces), read back instead of recomputed, and each
    // corner's weight in its vertex's sum, stored there in their place for
    // curv_dcurv_corners. The same values as computing them here.
    FREAL w0 = corner_weight(CW_LD(0), ld1(area, v0));
    FREAL w1 = corner_weight(CW_LD(1), ld1(area, v1));
    FREAL w2 = corner_weight(CW_LD(2), ld1(area, v2));
    // All three corners before the first store (see curv_dcurv_corners).
    FV3 c0 = tensor_w(pd1, pd2, v0, w0, ft, fb, x);
    FV3 c1 = tensor_w(pd1, pd2, v1, w1, ft, fb, x);
    FV3 c2 = tensor_w(pd1, pd2, v2, w2, ft, fb, x);
    st_corners(corner, blk, zero_unless(use, ext4(c0, (FREAL)RL(0))),
               zero_unless(use, ext4(c1, (FREAL)RL(0))), zero_unless(use, ext4(c2, (FREAL)RL(0))));
    FREAL z = (FREAL)RL(0);
    CW_ST(!deg ? w0 : z, 0);
    CW_ST(!deg ? w1 : z, 1);
    CW_ST(!deg ? w2 : z, 2);
    count_lanes(&counters[2], (!deg) & (!ok), live);
}

__kernel void curv_dcurv_corners(uint nf, __global const REAL *pos, __global const uint *faces,
                                 __global const REAL *area, __global const REAL *pd1,
                                 __global const REAL *pd2, __global const REAL *kk,
                                 __global REAL *corner, __global REAL *cw,
                                 volatile __global uint *counters)
{
    FACE_BLOCK_OR_RETURN(nf);
    LOAD_FACE_BLOCK(pos, faces);
    FMASK deg = tri_degenerate(t);
    FV3 ft, fb;
    FV4 x;
    face_frame(t, &ft, &fb);
    FV4 q0 = vertex_coef(pd1, pd2, v0, ft, fb), q1 = vertex_coef(pd1, pd2, v1, ft, fb),
        q2 = vertex_coef(pd1, pd2, v2, ft, fb);
    FMASK ok = face_dcurv(t, ft, fb, vertex_curv_by(kk, v0, q0), vertex_curv_by(kk, v1, q1),
                          vertex_curv_by(kk, v2, q2), &x);
    FMASK use = (!deg) & ok;
    // The corner weights curv_tensor_corners stored (`area` is not read).
    FREAL w0 = CW_LD(0), w1 = CW_LD(1), w2 = CW_LD(2);
    FV4 c0 = dcurv_by(q0, w0, x), c1 = dcurv_by(q1, w1, x), c2 = dcurv_by(q2, w2, x);
    st_corners(corner, blk, zero_unless(use, c0), zero_unless(use, c1), zero_unless(use, c2));
    count_lanes(&counters[3], (!deg) & (!ok), live);
}

#endif // SC_LANES > 1

// Sums the corners of vertex v's one-ring in face order (components x, y, z,
// and w when `four`; a constant after inlining). One vertex per work-item:
// written with SC_LANES vertices per work-item (rings walked together to the
// longest, masked) these ran no faster on PoCL 3.1 (4.1 against 4.2 ms for
// the three on the bunny), so their loads (a ring entry, then its corner),
// not their few adds, look like the limit.
SC_INLINE V4 sum_ring(uint v, __global const uint *ring_off, __global const uint *ring,
                      __global const REAL *corner, bool four)
{
    REAL4 s = (REAL4)(RL(0));
    for (uint r = ring_off[v]; r < ring_off[v + 1]; r++)
        s += vload4(ring[r], corner);
    return v4(s.x, s.y, s.z, four ? s.w : RL(0));
}

__kernel void curv_normals_areas_sum(uint nv, __global const uint *ring_off,
                                     __global const uint *ring, __global const REAL *corner,
                                     __global REAL *nrm, __global REAL *area)
{
    GID_OR_RETURN(nv);
    V4 s = sum_ring(gid, ring_off, ring, corner, true);
    st3(v3(s.x, s.y, s.z), gid, nrm);
    area[gid] = s.w;
}

__kernel void curv_tensor_sum(uint nv, __global const uint *ring_off, __global const uint *ring,
                              __global const REAL *corner, __global REAL *tens)
{
    GID_OR_RETURN(nv);
    V4 s = sum_ring(gid, ring_off, ring, corner, false);
    st3(v3(s.x, s.y, s.z), gid, tens);
}

__kernel void curv_dcurv_sum(uint nv, __global const uint *ring_off, __global const uint *ring,
                             __global const REAL *corner, __global REAL *dk)
{
    GID_OR_RETURN(nv);
    V4 s = sum_ring(gid, ring_off, ring, corner, true);
    dk[4 * gid] = s.x;
    dk[4 * gid + 1] = s.y;
    dk[4 * gid + 2] = s.z;
    dk[4 * gid + 3] = s.w;
}
#endif // SC_GATHER

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
