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
// with no atomics and no inner loops, so PoCL can vectorise it across
// work-items. A per-vertex kernel (curv_*_sum) then adds the corners of its
// one-ring (CSR lists built once on the host, in face order). The result is
// bitwise reproducible.
//
// Vectors are structs of scalars (V3, V4) and per-corner values are named
// (e0 e1 e2, a0 a1 a2), never float3/vload3 and never private arrays: PoCL's
// work-item vectoriser gives up on OpenCL vector types, private arrays,
// selects of whole structs, fmax and atomics, but turns scalar code, even with
// indexed loads, into AVX-512 code (measured on PoCL 3.1 by disassembling
// the kernel cache). That holds for the per-vertex passes (frames, principal);
// the per-face passes stay scalar even without atomics: PoCL runs -O3 with
// the SLP vectoriser on the single work-item kernel before it builds the
// work-item loops, SLP packs pairs of corners into <2 x float>, and the loop
// vectoriser then refuses the vector-typed instructions (POCL_VECTORIZER_REMARKS,
// "instruction return type cannot be vectorized"). Helpers are SC_INLINE
// (always_inline): left to PoCL's inliner, proj_dcurv, tensor_at and
// vertex_curv_in stay calls returning structs through the stack, which cost
// ~15 % of curv_dcurv.
//
// Buffers (V vertices, F faces; REAL is float or double, see real.h):
//   pos   REAL[3V]  positions, centred and scaled by the host (unit RMS radius)
//   faces uint[3F]  triangle vertex indices
//   owner int[V]    owning face (−1: unreferenced vertex)
//   nrm   REAL[3V]  normal (accumulated, then unit)      area REAL[V] point area
//   pd1, pd2 REAL[3V] initial frame, overwritten by principal directions
//   tens  REAL[3V]  curvature tensor (ku, kuv, kv) in the initial frame
//   kk    REAL[2V]  (k1, k2)                              dk REAL[4V] derivative tensor
//   counters uint[4] degenerate faces, vertices without area, tensor and dcurv solves skipped
//   ring_off uint[V+1], ring uint[3F] one-ring (face*3 + corner), gather variant only
//   corner REAL[12F] per-corner contributions: corner c of face f, component k at
//                    12f + 3k + c (one gap-free store group per face), gather only
//   status uchar[F]   bit 0 degenerate, bit 1 tensor solve skipped, bit 2 dcurv solve skipped
//
// Degenerate faces (an edge shorter than 1e-12 of the mesh's RMS radius,
// twice the area below 5e-8 × Σ edge², or 2A/√(Σ edge²) below the f32
// rounding of the positions, 2⁻²³·Σ|p|) are skipped in every pass and
// counted once; the rule is the same at every precision and in the CPU twin. A least-squares system whose pivots are not positive (rounding
// on extreme slivers) is skipped and counted. Nothing here can write NaN.
//
// Build options: -DSC_DOUBLE (double precision), -DSC_COMPAT (trimesh2 2.16:
// its 3×3 LDLᵀ third pivot Σv² instead of Σv² − (Σuv)²/d1, and |k1| ≥ |k2|
// ordering instead of k1 ≥ k2).
// Shared with the host (src/spec/curvature.rs): Precision::F64 ↔ SC_DOUBLE,
// Compat::Trimesh2 ↔ SC_COMPAT, the counters uint[4] in CurvatureCounts order.

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
// Scalar vectors.

typedef struct {
    REAL x, y, z;
} V3;
typedef struct {
    REAL x, y, z, w;
} V4;

SC_INLINE V3 v3(REAL x, REAL y, REAL z)
{
    V3 r;
    r.x = x;
    r.y = y;
    r.z = z;
    return r;
}
SC_INLINE V4 v4(REAL x, REAL y, REAL z, REAL w)
{
    V4 r;
    r.x = x;
    r.y = y;
    r.z = z;
    r.w = w;
    return r;
}
SC_INLINE V3 ld3(__global const REAL *a, uint i) { return v3(a[3 * i], a[3 * i + 1], a[3 * i + 2]); }
SC_INLINE void st3(V3 v, uint i, __global REAL *a)
{
    a[3 * i] = v.x;
    a[3 * i + 1] = v.y;
    a[3 * i + 2] = v.z;
}
SC_INLINE V3 add3(V3 a, V3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
SC_INLINE V3 sub3(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
SC_INLINE V3 mul3(V3 a, REAL s) { return v3(a.x * s, a.y * s, a.z * s); }
SC_INLINE V3 neg3(V3 a) { return v3(-a.x, -a.y, -a.z); }
SC_INLINE REAL dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
SC_INLINE V3 cross3(V3 a, V3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
SC_INLINE REAL len3(V3 a) { return sqrt(dot3(a, a)); }
SC_INLINE V3 normalize3(V3 a) { return mul3(a, RL(1) / len3(a)); }
// Component-wise select (a select of a whole struct keeps PoCL from vectorising).
SC_INLINE V3 sel3(bool c, V3 a, V3 b) { return v3(c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z); }
SC_INLINE V4 mul4(V4 a, REAL s) { return v4(a.x * s, a.y * s, a.z * s, a.w * s); }

// ---------------------------------------------------------------------------
// Per-face geometry, shared by the atomic and gather variants.

typedef struct {
    uint v0, v1, v2;
    V3 e0, e1, e2; // e_i is the edge opposite corner i: p[i−1] − p[i+1]
    REAL psum;     // |p0| + |p1| + |p2| (sums, not maxima: a max keeps PoCL from vectorising)
} Tri;

SC_INLINE Tri load_tri(__global const REAL *pos, __global const uint *faces, uint f)
{
    Tri t;
    t.v0 = faces[3 * f];
    t.v1 = faces[3 * f + 1];
    t.v2 = faces[3 * f + 2];
    V3 p0 = ld3(pos, t.v0), p1 = ld3(pos, t.v1), p2 = ld3(pos, t.v2);
    t.e0 = sub3(p2, p1);
    t.e1 = sub3(p0, p2);
    t.e2 = sub3(p1, p0);
    t.psum = len3(p0) + len3(p1) + len3(p2);
    return t;
}

SC_INLINE bool tri_degenerate(Tri t)
{
    REAL l0 = dot3(t.e0, t.e0), l1 = dot3(t.e1, t.e1), l2 = dot3(t.e2, t.e2);
    REAL twice_area = len3(cross3(t.e0, t.e1));
    REAL lsum = l0 + l1 + l2;
    // Written as negated comparisons so NaN counts as degenerate too.
    // Bitwise & (not &&): short-circuit branches keep PoCL from vectorising.
    return !((l0 > DEGEN_EDGE2) & (l1 > DEGEN_EDGE2) & (l2 > DEGEN_EDGE2) &
             (twice_area > DEGEN_AREA_REL * lsum) &
             (twice_area > DEGEN_HEIGHT_ULP * sqrt(lsum) * t.psum));
}

// Corner-weighted face normal (trimesh2 / Max 1999): the face's a×b divided by
// the squared lengths of the two edges at the corner, la (next edge) then lb.
SC_INLINE V3 corner_normal(V3 fn, REAL la, REAL lb)
{
    return mul3(mul3(fn, RL(1) / la), RL(1) / lb); // two steps keep f32 in range
}
SC_INLINE V3 face_normal(Tri t) { return cross3(t.e2, t.e0); } // |.| = 2A, outward for CCW

// Voronoi (circumcentric) corner areas with trimesh2's obtuse-triangle rule.
SC_INLINE V3 corner_areas(Tri t)
{
    REAL area = RL(0.5) * len3(cross3(t.e0, t.e1));
    REAL l0 = dot3(t.e0, t.e0), l1 = dot3(t.e1, t.e1), l2 = dot3(t.e2, t.e2);
    REAL ew0 = l0 * (l1 + l2 - l0), ew1 = l1 * (l2 + l0 - l1), ew2 = l2 * (l0 + l1 - l2);
    REAL q = RL(-0.25) * area;
    // obtuse at corner 0, 1 or 2: the other two get the area cut off by the
    // perpendicular bisector of their edge to it, the obtuse corner the rest
    REAL o01 = q * l2 / dot3(t.e0, t.e2), o02 = q * l1 / dot3(t.e0, t.e1);
    REAL o12 = q * l0 / dot3(t.e1, t.e0), o10 = q * l2 / dot3(t.e1, t.e2);
    REAL o20 = q * l1 / dot3(t.e2, t.e1), o21 = q * l0 / dot3(t.e2, t.e0);
    REAL s = RL(0.5) * area / (ew0 + ew1 + ew2);
    V3 acute = v3(s * (ew1 + ew2), s * (ew2 + ew0), s * (ew0 + ew1));
    V3 obt0 = v3(area - o01 - o02, o01, o02);
    V3 obt1 = v3(o10, area - o12 - o10, o12);
    V3 obt2 = v3(o20, o21, area - o20 - o21);
    return sel3(ew0 <= 0, obt0, sel3(ew1 <= 0, obt1, sel3(ew2 <= 0, obt2, acute)));
}

// Weight of a face corner in its vertex's one-ring sum (0 when the vertex has no area).
SC_INLINE REAL corner_weight(REAL ca, REAL a) { return a > 0 ? ca / a : RL(0); }

// Any unit vector perpendicular to n (n unit).
SC_INLINE V3 any_perp(V3 n)
{
    REAL ax = fabs(n.x), ay = fabs(n.y), az = fabs(n.z);
    V3 a = sel3((ax <= ay) & (ax <= az), v3(1, 0, 0), sel3(ay <= az, v3(0, 1, 0), v3(0, 0, 1)));
    return normalize3(cross3(n, a));
}

// Rotate the frame (u, v) by the minimal rotation taking u×v onto nn.
SC_INLINE void rot_coord_sys(V3 u, V3 v, V3 nn, V3 *ru, V3 *rv)
{
    V3 on = cross3(u, v);
    REAL ndot = dot3(on, nn);
    bool flip = ndot <= RL(-1) + RL(1e-6); // opposite normals: a half turn
    V3 perp_old = sub3(nn, mul3(on, ndot));
    V3 dperp = mul3(add3(on, nn), RL(1) / (RL(1) + ndot));
    *ru = sel3(flip, neg3(u), sub3(u, mul3(dperp, dot3(u, perp_old))));
    *rv = sel3(flip, neg3(v), sub3(v, mul3(dperp, dot3(v, perp_old))));
}

// Re-express the tensor k = (ku, kuv, kv) given in (ou, ov) in the frame (nu, nv).
SC_INLINE V3 proj_curv(V3 ou, V3 ov, V3 k, V3 nu, V3 nv)
{
    V3 ru, rv;
    rot_coord_sys(nu, nv, cross3(ou, ov), &ru, &rv);
    REAL u1 = dot3(ru, ou), v1 = dot3(ru, ov), u2 = dot3(rv, ou), v2 = dot3(rv, ov);
    return v3(k.x * u1 * u1 + k.y * (RL(2) * u1 * v1) + k.z * v1 * v1,
              k.x * u1 * u2 + k.y * (u1 * v2 + u2 * v1) + k.z * v1 * v2,
              k.x * u2 * u2 + k.y * (RL(2) * u2 * v2) + k.z * v2 * v2);
}

// The same for the third-order tensor d = (C111, C112, C122, C222).
SC_INLINE V4 proj_dcurv(V3 ou, V3 ov, V4 d, V3 nu, V3 nv)
{
    V3 ru, rv;
    rot_coord_sys(nu, nv, cross3(ou, ov), &ru, &rv);
    REAL u1 = dot3(ru, ou), v1 = dot3(ru, ov), u2 = dot3(rv, ou), v2 = dot3(rv, ov);
    return v4(d.x * u1 * u1 * u1 + d.y * RL(3) * u1 * u1 * v1 + d.z * RL(3) * u1 * v1 * v1 +
                  d.w * v1 * v1 * v1,
              d.x * u1 * u1 * u2 + d.y * (u1 * u1 * v2 + RL(2) * u2 * u1 * v1) +
                  d.z * (u2 * v1 * v1 + RL(2) * u1 * v1 * v2) + d.w * v1 * v1 * v2,
              d.x * u1 * u2 * u2 + d.y * (u2 * u2 * v1 + RL(2) * u1 * u2 * v2) +
                  d.z * (u1 * v2 * v2 + RL(2) * u2 * v2 * v1) + d.w * v1 * v2 * v2,
              d.x * u2 * u2 * u2 + d.y * RL(3) * u2 * u2 * v2 + d.z * RL(3) * u2 * v2 * v2 +
                  d.w * v2 * v2 * v2);
}

// Face frame: t along e0, b in the face plane, t × b = face normal.
SC_INLINE void face_frame(Tri t, V3 *ft, V3 *fb)
{
    *ft = normalize3(t.e0);
    *fb = normalize3(cross3(cross3(t.e0, t.e1), *ft));
}

// Least-squares second fundamental form of a face from the normal differences
// along its edges (edge e_i pairs with n[i−1] − n[i+1]). The normal equations
// [[w00 w01 0] [w01 w00+w22 w01] [0 w01 w22]] are tridiagonal; LDLᵀ unrolled.
// Returns false when a pivot is not positive or the result is not finite.
SC_INLINE bool face_tensor(Tri t, V3 ft, V3 fb, V3 n0, V3 n1, V3 n2, V3 *x)
{
    REAL w00 = 0, w01 = 0, w22 = 0, m0 = 0, m1 = 0, m2 = 0;
#define TENSOR_EDGE(e, dn)                                 \
    {                                                      \
        REAL u = dot3(e, ft), v = dot3(e, fb);             \
        REAL dnu = dot3(dn, ft), dnv = dot3(dn, fb);       \
        w00 += u * u;                                      \
        w01 += u * v;                                      \
        w22 += v * v;                                      \
        m0 += dnu * u;                                     \
        m1 += dnu * v + dnv * u;                           \
        m2 += dnv * v;                                     \
    }
    TENSOR_EDGE(t.e0, sub3(n2, n1));
    TENSOR_EDGE(t.e1, sub3(n0, n2));
    TENSOR_EDGE(t.e2, sub3(n1, n0));
#undef TENSOR_EDGE
    REAL w11 = w00 + w22, w12 = w01;
    REAL d0 = w00;
    REAL l10 = w01 / d0;
    REAL d1 = w11 - l10 * w01;
    REAL l21 = w12 / d1;
#ifdef SC_COMPAT
    REAL d2 = w22; // trimesh2 2.16's pivot quirk (reads the lower triangle before filling it)
#else
    REAL d2 = w22 - l21 * w12;
#endif
    REAL y1 = m1 - l10 * m0;
    REAL y2 = m2 - l21 * y1;
    REAL x2 = y2 / d2;
    REAL x1 = y1 / d1 - l21 * x2;
    REAL x0 = m0 / d0 - l10 * x1;
    *x = v3(x0, x1, x2);
    return (d0 > 0) & (d1 > 0) & (d2 > 0) & isfinite(x0) & isfinite(x1) & isfinite(x2);
}

// Least-squares curvature derivative of a face from the differences of the
// vertex tensors (in the face frame) along its edges. The 4×4 normal equations
// [[a b 0 0] [b 2a+c 2b 0] [0 2b a+2c b] [0 0 b c]] (a = Σu², b = Σuv, c = Σv²)
// are tridiagonal too.
SC_INLINE bool face_dcurv(Tri t, V3 ft, V3 fb, V3 f0, V3 f1, V3 f2, V4 *x)
{
    REAL a = 0, b = 0, c = 0, m0 = 0, m1 = 0, m2 = 0, m3 = 0;
#define DCURV_EDGE(e, d)                                   \
    {                                                      \
        REAL u = dot3(e, ft), v = dot3(e, fb);             \
        a += u * u;                                        \
        b += u * v;                                        \
        c += v * v;                                        \
        m0 += u * d.x;                                     \
        m1 += v * d.x + RL(2) * u * d.y;                   \
        m2 += RL(2) * v * d.y + u * d.z;                   \
        m3 += v * d.z;                                     \
    }
    DCURV_EDGE(t.e0, sub3(f2, f1));
    DCURV_EDGE(t.e1, sub3(f0, f2));
    DCURV_EDGE(t.e2, sub3(f1, f0));
#undef DCURV_EDGE
    REAL d0 = a;
    REAL l10 = b / d0;
    REAL d1 = RL(2) * a + c - l10 * b;
    REAL l21 = RL(2) * b / d1;
    REAL d2 = a + RL(2) * c - l21 * (RL(2) * b);
    REAL l32 = b / d2;
    REAL d3 = c - l32 * b;
    REAL y1 = m1 - l10 * m0;
    REAL y2 = m2 - l21 * y1;
    REAL y3 = m3 - l32 * y2;
    REAL x3 = y3 / d3;
    REAL x2 = y2 / d2 - l32 * x3;
    REAL x1 = y1 / d1 - l21 * x2;
    REAL x0 = m0 / d0 - l10 * x1;
    *x = v4(x0, x1, x2, x3);
    return (d0 > 0) & (d1 > 0) & (d2 > 0) & (d3 > 0) & isfinite(x0) & isfinite(x1) &
           isfinite(x2) & isfinite(x3);
}

// A vertex tensor (diagonal in (d1, d2)) re-expressed in a face frame.
SC_INLINE V3 vertex_curv_in(__global const REAL *pd1, __global const REAL *pd2,
                         __global const REAL *kk, uint v, V3 ft, V3 fb)
{
    return proj_curv(ld3(pd1, v), ld3(pd2, v), v3(kk[2 * v], 0, kk[2 * v + 1]), ft, fb);
}

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

// Unit normal, and the initial tangent frame from the owner face:
// pd1 = (edge to the next vertex of that face) × n, pd2 = n × pd1.
__kernel void curv_frames(uint nv, __global const REAL *pos, __global const uint *faces,
                          __global const int *owner, __global REAL *nrm, __global REAL *pd1,
                          __global REAL *pd2)
{
    GID_OR_RETURN(nv);
    V3 n = ld3(nrm, gid);
    REAL len = len3(n);
    n = sel3((len > 0) & isfinite(len), mul3(n, RL(1) / len), v3(0, 0, 1));
    st3(n, gid, nrm);
    int f = owner[gid];
    uint fi = (uint)max(f, 0);
    uint a = faces[3 * fi], b = faces[3 * fi + 1], c = faces[3 * fi + 2];
    uint next = gid == a ? b : gid == b ? c : a;
    V3 p1 = cross3(sub3(ld3(pos, next), ld3(pos, gid)), n);
    REAL l = len3(p1);
    p1 = sel3((f >= 0) & (l > RL(1e-20)) & isfinite(l), mul3(p1, RL(1) / l), any_perp(n));
    st3(p1, gid, pd1);
    st3(cross3(n, p1), gid, pd2);
}

// Counts the vertices that no usable face touches (kept out of curv_frames:
// an atomic in a kernel keeps PoCL from vectorising it).
__kernel void curv_count_empty(uint nv, __global const REAL *area,
                               volatile __global uint *counters)
{
    GID_OR_RETURN(nv);
    if (!(area[gid] > 0))
        atomic_inc(&counters[1]);
}

// One Jacobi rotation diagonalises the 2×2 tensor.
__kernel void curv_principal(uint nv, __global const REAL *nrm, __global const REAL *tens,
                             __global REAL *pd1, __global REAL *pd2, __global REAL *kk)
{
    GID_OR_RETURN(nv);
    V3 n = ld3(nrm, gid), ru, rv;
    rot_coord_sys(ld3(pd1, gid), ld3(pd2, gid), n, &ru, &rv);
    REAL ku = tens[3 * gid], kuv = tens[3 * gid + 1], kv = tens[3 * gid + 2];
    REAL h = RL(0.5) * (kv - ku) / kuv;
    REAL root = sqrt(RL(1) + h * h);
    REAL tt = kuv != 0 ? ((h < 0) ? RL(1) / (h - root) : RL(1) / (h + root)) : RL(0);
    REAL c = RL(1) / sqrt(RL(1) + tt * tt);
    REAL s = tt * c;
    REAL k1 = ku - tt * kuv, k2 = kv + tt * kuv;
#ifdef SC_COMPAT
    bool keep = fabs(k1) >= fabs(k2);
#else
    bool keep = k1 >= k2;
#endif
    V3 d1 = sel3(keep, sub3(mul3(ru, c), mul3(rv, s)), add3(mul3(ru, s), mul3(rv, c)));
    st3(d1, gid, pd1);
    st3(cross3(n, d1), gid, pd2);
    kk[2 * gid] = keep ? k1 : k2;
    kk[2 * gid + 1] = keep ? k2 : k1;
}

// ---------------------------------------------------------------------------
// Atomic (scatter) variant: one work-item per face, float atomics on the one-ring.

__kernel void curv_clear(uint nv, __global REAL *nrm, __global REAL *area, __global REAL *tens,
                         __global REAL *dk)
{
    GID_OR_RETURN(nv);
    st3(v3(0, 0, 0), gid, nrm);
    area[gid] = 0;
    st3(v3(0, 0, 0), gid, tens);
    dk[4 * gid] = 0;
    dk[4 * gid + 1] = 0;
    dk[4 * gid + 2] = 0;
    dk[4 * gid + 3] = 0;
}

SC_INLINE void atomic_add3(volatile __global REAL *a, uint v, V3 x)
{
    atomic_add_real(&a[3 * v], x.x);
    atomic_add_real(&a[3 * v + 1], x.y);
    atomic_add_real(&a[3 * v + 2], x.z);
}

SC_INLINE void atomic_add4(volatile __global REAL *a, uint v, V4 x)
{
    atomic_add_real(&a[4 * v], x.x);
    atomic_add_real(&a[4 * v + 1], x.y);
    atomic_add_real(&a[4 * v + 2], x.z);
    atomic_add_real(&a[4 * v + 3], x.w);
}

__kernel void curv_normals_areas(uint nf, __global const REAL *pos, __global const uint *faces,
                                 volatile __global REAL *nrm, volatile __global REAL *area,
                                 volatile __global uint *counters)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    if (tri_degenerate(t)) {
        atomic_inc(&counters[0]);
        return;
    }
    V3 ca = corner_areas(t), fn = face_normal(t);
    REAL l0 = dot3(t.e0, t.e0), l1 = dot3(t.e1, t.e1), l2 = dot3(t.e2, t.e2);
    atomic_add3(nrm, t.v0, corner_normal(fn, l1, l2));
    atomic_add3(nrm, t.v1, corner_normal(fn, l2, l0));
    atomic_add3(nrm, t.v2, corner_normal(fn, l0, l1));
    atomic_add_real(&area[t.v0], ca.x);
    atomic_add_real(&area[t.v1], ca.y);
    atomic_add_real(&area[t.v2], ca.z);
}

// The weighted tensor of face (t, ft, fb, x) in vertex v's frame.
SC_INLINE V3 tensor_at(__global const REAL *pd1, __global const REAL *pd2,
                    __global const REAL *area, uint v, REAL ca, V3 ft, V3 fb, V3 x)
{
    return mul3(proj_curv(ft, fb, x, ld3(pd1, v), ld3(pd2, v)), corner_weight(ca, area[v]));
}

__kernel void curv_tensor(uint nf, __global const REAL *pos, __global const uint *faces,
                          __global const REAL *nrm, __global const REAL *area,
                          __global const REAL *pd1, __global const REAL *pd2,
                          volatile __global REAL *tens, volatile __global uint *counters)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    if (tri_degenerate(t))
        return;
    V3 ft, fb, x;
    face_frame(t, &ft, &fb);
    if (!face_tensor(t, ft, fb, ld3(nrm, t.v0), ld3(nrm, t.v1), ld3(nrm, t.v2), &x)) {
        atomic_inc(&counters[2]);
        return;
    }
    V3 ca = corner_areas(t);
    atomic_add3(tens, t.v0, tensor_at(pd1, pd2, area, t.v0, ca.x, ft, fb, x));
    atomic_add3(tens, t.v1, tensor_at(pd1, pd2, area, t.v1, ca.y, ft, fb, x));
    atomic_add3(tens, t.v2, tensor_at(pd1, pd2, area, t.v2, ca.z, ft, fb, x));
}

// The weighted derivative tensor of a face in vertex v's frame.
SC_INLINE V4 dcurv_at(__global const REAL *pd1, __global const REAL *pd2, __global const REAL *area,
                   uint v, REAL ca, V3 ft, V3 fb, V4 x)
{
    return mul4(proj_dcurv(ft, fb, x, ld3(pd1, v), ld3(pd2, v)), corner_weight(ca, area[v]));
}

__kernel void curv_dcurv(uint nf, __global const REAL *pos, __global const uint *faces,
                         __global const REAL *area, __global const REAL *pd1,
                         __global const REAL *pd2, __global const REAL *kk,
                         volatile __global REAL *dk, volatile __global uint *counters)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    if (tri_degenerate(t))
        return;
    V3 ft, fb;
    V4 x;
    face_frame(t, &ft, &fb);
    if (!face_dcurv(t, ft, fb, vertex_curv_in(pd1, pd2, kk, t.v0, ft, fb),
                    vertex_curv_in(pd1, pd2, kk, t.v1, ft, fb),
                    vertex_curv_in(pd1, pd2, kk, t.v2, ft, fb), &x)) {
        atomic_inc(&counters[3]);
        return;
    }
    V3 ca = corner_areas(t);
    atomic_add4(dk, t.v0, dcurv_at(pd1, pd2, area, t.v0, ca.x, ft, fb, x));
    atomic_add4(dk, t.v1, dcurv_at(pd1, pd2, area, t.v1, ca.y, ft, fb, x));
    atomic_add4(dk, t.v2, dcurv_at(pd1, pd2, area, t.v2, ca.z, ft, fb, x));
}

// ---------------------------------------------------------------------------
// Gather variant. Face kernels: no atomics, no inner loops, no arrays; a
// skipped face writes zeros (selected, never multiplied, so NaN cannot leak)
// and sets its status bit. Sum kernels: each vertex adds its corners in face
// order and counts each skipped face once, at the face's corner 0.

// Corner c of face f, component k, lives at corner[12f + 3k + c]: a face's 12
// stores form one gap-free group (stores with gaps, or into several planes of
// one buffer, keep PoCL from vectorising).
SC_INLINE void st_corner(__global REAL *corner, uint f, uint c, bool use, V4 x)
{
    uint i = 12 * f + c;
    corner[i] = use ? x.x : 0;
    corner[i + 3] = use ? x.y : 0;
    corner[i + 6] = use ? x.z : 0;
    corner[i + 9] = use ? x.w : 0;
}

SC_INLINE V4 ext4(V3 a, REAL w) { return v4(a.x, a.y, a.z, w); }

__kernel void curv_normals_areas_corners(uint nf, __global const REAL *pos,
                                         __global const uint *faces, __global REAL *corner,
                                         __global uchar *status)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    bool use = !tri_degenerate(t);
    V3 ca = corner_areas(t), fn = face_normal(t);
    REAL l0 = dot3(t.e0, t.e0), l1 = dot3(t.e1, t.e1), l2 = dot3(t.e2, t.e2);
    st_corner(corner, gid, 0, use, ext4(corner_normal(fn, l1, l2), ca.x));
    st_corner(corner, gid, 1, use, ext4(corner_normal(fn, l2, l0), ca.y));
    st_corner(corner, gid, 2, use, ext4(corner_normal(fn, l0, l1), ca.z));
    status[gid] = use ? 0 : 1;
}

__kernel void curv_tensor_corners(uint nf, __global const REAL *pos, __global const uint *faces,
                                  __global const REAL *nrm, __global const REAL *area,
                                  __global const REAL *pd1, __global const REAL *pd2,
                                  __global REAL *corner, __global uchar *status)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    bool deg = tri_degenerate(t);
    V3 ft, fb, x;
    face_frame(t, &ft, &fb);
    bool ok = face_tensor(t, ft, fb, ld3(nrm, t.v0), ld3(nrm, t.v1), ld3(nrm, t.v2), &x);
    bool use = !deg & ok;
    V3 ca = corner_areas(t);
    st_corner(corner, gid, 0, use, ext4(tensor_at(pd1, pd2, area, t.v0, ca.x, ft, fb, x), 0));
    st_corner(corner, gid, 1, use, ext4(tensor_at(pd1, pd2, area, t.v1, ca.y, ft, fb, x), 0));
    st_corner(corner, gid, 2, use, ext4(tensor_at(pd1, pd2, area, t.v2, ca.z, ft, fb, x), 0));
    status[gid] = (deg ? 1 : 0) | ((!deg & !ok) ? 2 : 0);
}

__kernel void curv_dcurv_corners(uint nf, __global const REAL *pos, __global const uint *faces,
                                 __global const REAL *area, __global const REAL *pd1,
                                 __global const REAL *pd2, __global const REAL *kk,
                                 __global REAL *corner, __global uchar *status)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    bool deg = tri_degenerate(t);
    V3 ft, fb;
    V4 x;
    face_frame(t, &ft, &fb);
    bool ok = face_dcurv(t, ft, fb, vertex_curv_in(pd1, pd2, kk, t.v0, ft, fb),
                         vertex_curv_in(pd1, pd2, kk, t.v1, ft, fb),
                         vertex_curv_in(pd1, pd2, kk, t.v2, ft, fb), &x);
    bool use = !deg & ok;
    V3 ca = corner_areas(t);
    st_corner(corner, gid, 0, use, dcurv_at(pd1, pd2, area, t.v0, ca.x, ft, fb, x));
    st_corner(corner, gid, 1, use, dcurv_at(pd1, pd2, area, t.v1, ca.y, ft, fb, x));
    st_corner(corner, gid, 2, use, dcurv_at(pd1, pd2, area, t.v2, ca.z, ft, fb, x));
    status[gid] = (deg ? 1 : 0) | ((!deg & !ok) ? 4 : 0);
}

// Sums the corners of vertex v's one-ring in face order, counting (once per
// face, at its corner 0) the faces whose status has `bit`.
SC_INLINE V4 sum_ring(uint v, __global const uint *ring_off, __global const uint *ring,
                   __global const REAL *corner, __global const uchar *status, uchar bit,
                   volatile __global uint *counter)
{
    V4 s = v4(0, 0, 0, 0);
    for (uint r = ring_off[v]; r < ring_off[v + 1]; r++) {
        uint e = ring[r], f = e / 3, i = 12 * f + e % 3;
        if (e % 3 == 0 && (status[f] & bit))
            atomic_inc(counter);
        s.x += corner[i];
        s.y += corner[i + 3];
        s.z += corner[i + 6];
        s.w += corner[i + 9];
    }
    return s;
}

__kernel void curv_normals_areas_sum(uint nv, __global const uint *ring_off,
                                     __global const uint *ring, __global const REAL *corner,
                                     __global const uchar *status, __global REAL *nrm,
                                     __global REAL *area, volatile __global uint *counters)
{
    GID_OR_RETURN(nv);
    V4 s = sum_ring(gid, ring_off, ring, corner, status, 1, &counters[0]);
    st3(v3(s.x, s.y, s.z), gid, nrm);
    area[gid] = s.w;
}

__kernel void curv_tensor_sum(uint nv, __global const uint *ring_off, __global const uint *ring,
                              __global const REAL *corner, __global const uchar *status,
                              __global REAL *tens, volatile __global uint *counters)
{
    GID_OR_RETURN(nv);
    V4 s = sum_ring(gid, ring_off, ring, corner, status, 2, &counters[2]);
    st3(v3(s.x, s.y, s.z), gid, tens);
}

__kernel void curv_dcurv_sum(uint nv, __global const uint *ring_off, __global const uint *ring,
                             __global const REAL *corner, __global const uchar *status,
                             __global REAL *dk, volatile __global uint *counters)
{
    GID_OR_RETURN(nv);
    V4 s = sum_ring(gid, ring_off, ring, corner, status, 4, &counters[3]);
    dk[4 * gid] = s.x;
    dk[4 * gid + 1] = s.y;
    dk[4 * gid + 2] = s.z;
    dk[4 * gid + 3] = s.w;
}

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
