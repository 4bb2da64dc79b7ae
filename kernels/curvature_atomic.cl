// curvature_atomic.cl: the one-ring passes of the atomic schemes, as Griffin
// et al. 2012 (§3.6) write them: one work-item per face (or per block of
// SC_LANES faces) adds its three corners' contributions to their vertices
// with float atomic adds. Included by kernels/curvature.cl when built without
// -DSC_GATHER; the types, the per-vertex passes and the face geometry are
// there and in common/curvature_face.h. CPU twin: src/cpu/curvature.rs (the
// same sums in face order); host: src/stages/curvature/atomic.rs.
//   curv_clear           per vertex zero nrm, area, tens, dk
//   curv_normals_areas   per face   nrm += corner normal, area += corner area
//   curv_tensor          per face   tens += the face tensor in each vertex frame
//   curv_dcurv           per face   dk += the face derivative in each vertex frame
// Adds (common/atomics.h): a compare-and-swap loop per float (OpenCL 1.2), two
// adjacent floats per 64-bit compare-and-swap with -DSC_PAIR_ADDS, or the
// device's own float atomic add with -DSC_NATIVE_ATOMICS (cl_ext_float_atomics).
// Sums in no fixed order: results vary with the rounding of that order.
// With lanes a block's arithmetic is the gather kernels' lane code; then each
// lane's corners are added lane after lane, a run of lanes whose corner goes
// to one vertex summed in registers first (SC_RUN_STEP). A face whose solve is
// skipped adds nothing and is counted (counters[2], counters[3]).

// The positions of face f's corners, and their indices.
SC_INLINE Tri load_tri(__global const REAL *pos, __global const uint *faces, uint f, uint *v0,
                       uint *v1, uint *v2)
{
    *v0 = faces[3 * f];
    *v1 = faces[3 * f + 1];
    *v2 = faces[3 * f + 2];
    return make_tri(ld3(pos, *v0), ld3(pos, *v1), ld3(pos, *v2));
}

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
// arithmetic the lane code of the gather kernels (positions through ld_pos,
// the vertex records through ld_rec, the same helpers), and then each lane's
// corners added to their vertices one float atomic add per value (scatter_*),
// lane after lane, for the lanes whose face is used.
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
