// curvature_lanes.h: the memory side of the curvature kernels' lane forms
// (SC_LANES > 1; empty otherwise), shared by curv_frames and curv_principal
// and by the per-face kernels of both schemes (kernels/curvature_atomic.cl,
// kernels/curvature_gather.cl). Included by kernels/curvature.cl after both
// instances of common/curvature_face.h, whose lane types (FREAL, FV3, FTri)
// it uses. A face or vertex block's values are loaded and stored as whole
// vectors and transposed in registers, never gathered one lane at a time:
//   vertex records (REC_*): 16 reals per vertex, written by curv_frames and
//     rewritten by curv_principal (st_rec), read by the tensor and derivative
//     face kernels (ld_rec) in place of pos, nrm, area, pd1, pd2 and kk;
//   positions (ld_pos): each lane's x y z as one 4-real load through its
//     face index (the pos buffer has one real of padding past its end).
// The transposes are SC_LANES × SC_LANES, in log2(SC_LANES) stages of
// two-vector shuffles with constant indices.

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
#endif // SC_LANES > 1
