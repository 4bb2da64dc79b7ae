// curvature_gather.cl: the one-ring passes of the gather scheme, bitwise
// reproducible. Each pass is split in two: a per-face kernel (curv_*_corners;
// one face, or a block of SC_LANES faces, per work-item; no atomics, no inner
// loops) writes its three corners' contributions to the corner buffer, and a
// per-vertex kernel (curv_*_sum) adds the corners of its one-ring in face
// order (CSR lists built once, on the host or, on GPUs, by curv_ring_count,
// a scan, curv_ring_fill and curv_ring_order). Included by kernels/curvature.cl
// when built with -DSC_GATHER; the types, the per-vertex passes and the face
// geometry are there and in common/curvature_face.h. CPU twin:
// src/cpu/curvature.rs (the same sums in face order); host:
// src/stages/curvature/gather.rs.
//   curv_normals_areas_corners / _sum   corner normals and areas → nrm, area
//   curv_tensor_corners / _sum          the face tensor in each vertex frame → tens
//   curv_dcurv_corners / _sum           the face derivative in each vertex frame → dk
// Buffers, beyond those of curvature.cl:
//   ring_off uint[V+1], ring uint[3F]  one-ring (face·3 + corner), in face order
//   corner REAL[12F]  corner c of face f, component k at 12f + 4c + k
//                     (CORNER_SLOT; the normal pass's component 3 is the corner area)
//   cw    REAL[3F]    the corner areas (normal pass), then each corner's weight,
//                     corner area ÷ point area (tensor pass), which the dcurv
//                     pass reads instead of recomputing; corner c of face f at
//                     L·(3·(f / L) + c) + f % L (L = SC_LANES): whole vectors.
// A skipped face writes zeros and is counted once, by its face kernel.
// The derivative pass uses one set of projection coefficients per corner
// (proj_coef) both ways: the vertex's tensor into the face frame, and the
// face's derivative back into the vertex frame.

#if SC_LANES > 1
// The corner areas (then weights) of corner c of the block's faces: one
// whole vector (see `cw` above).
#define CW_LD(c) VLOADN(3 * blk + (c), cw)
#define CW_ST(x, c) VSTOREN((x), 3 * blk + (c), cw)
#else
#define CW_LD(c) cw[3 * blk + (c)]
#define CW_ST(x, c) (cw[3 * blk + (c)] = (x))
#endif

// The corner slot of face f's corner c, component k: corner e = 3f + c has
// its four components at 4e … 4e + 3, so that a ring sum reads a corner as
// one 16-byte run (for every lane count).
#define CORNER_SLOT(f, c, k) (12 * (f) + 4 * (c) + (k))

#if SC_LANES > 1
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
#else
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
#endif // SC_LANES > 1

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
// and w when `four`; a constant after inlining), a corner as one 4-real
// load. One vertex per work-item: the sums are bound by their loads, not by
// their adds (docs/notes/curvature-kernels.md, "Ring sums").
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

// ---------------------------------------------------------------------------
// The one-ring lists on the device (GPUs; the host builds them on CPU
// devices): the same lists as mesh::topology::one_rings_into, its twin.
// Corners per vertex, counted; count[V] stays 0 so that its exclusive scan
// (kernels/scan.cl) gives ring_off[0..V] in one.
__kernel void curv_ring_count(uint nf, __global const uint *faces, volatile __global uint *count)
{
    GID_OR_RETURN(nf);
    for (int c = 0; c < 3; c++)
        atomic_inc(&count[faces[3 * gid + c]]);
}

// Each corner into its vertex's list, in any order (cursor: zeros).
__kernel void curv_ring_fill(uint nf, __global const uint *faces, __global const uint *ring_off,
                             volatile __global uint *cursor, __global uint *ring)
{
    GID_OR_RETURN(nf);
    for (uint c = 0; c < 3; c++) {
        const uint v = faces[3 * gid + c];
        ring[ring_off[v] + atomic_inc(&cursor[v])] = 3 * gid + c;
    }
}

// Each list sorted (face·3 + corner ascending is face order, as the host's),
// and the owner, its last face; padding vertices up to nvp get -1.
__kernel void curv_ring_order(uint nv, uint nvp, __global const uint *ring_off,
                              __global uint *ring, __global int *owner)
{
    GID_OR_RETURN(nvp);
    if (gid >= nv) {
        owner[gid] = -1;
        return;
    }
    const uint a = ring_off[gid], b = ring_off[gid + 1];
    for (uint i = a + 1; i < b; i++) {
        const uint x = ring[i];
        uint j = i;
        while (j > a && ring[j - 1] > x) {
            ring[j] = ring[j - 1];
            j--;
        }
        ring[j] = x;
    }
    owner[gid] = b > a ? (int)(ring[b - 1] / 3) : -1;
}
