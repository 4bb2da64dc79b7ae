// curvature_face.h: the per-face geometry of the curvature kernels (both
// schemes: kernels/curvature_atomic.cl, kernels/curvature_gather.cl) and the
// per-vertex steps of the frame and principal passes (kernels/curvature.cl),
// written over type macros so that it is instantiated twice: once on scalars
// (every kernel) and, when SC_LANES > 1, once on OpenCL vectors of SC_LANES
// faces or vertices (the lane kernels). The includer defines
//   GT   the real type (REAL, or a REAL vector of SC_LANES lanes)
//   GM   the mask type of a comparison of two GT (int, or an int/long vector)
//   GI   the index type (uint, or a uint vector: one face or vertex per lane)
//   GV3, GV4, GTri   the names of the structs this instance defines
//   ld1(a, GI)   the buffer load of the instance: a[i] per lane
// and SC_OL, empty for one instance and __attribute__((overloadable)) when
// there are two, so that both instances share their function names.
// An include with GT undefined is empty.
// Masks are what comparisons give: 0 or 1 on scalars, 0 or -1 per lane on
// vectors; only &, | and ! combine them and only ?: consumes them, which
// reads the same in both. Literals are scalars (widened by the arithmetic).
// Vectors are structs of scalars, never float3 or private arrays, and helpers
// are SC_INLINE: PoCL's work-item vectoriser gives up on OpenCL vector types,
// private arrays, selects of whole structs, fmax and atomics, and its inliner
// left the larger helpers as calls returning structs through the stack.

#ifdef GT

typedef struct {
    GT x, y, z;
} GV3;
typedef struct {
    GT x, y, z, w;
} GV4;

SC_OL SC_INLINE GV3 v3(GT x, GT y, GT z)
{
    GV3 r;
    r.x = x;
    r.y = y;
    r.z = z;
    return r;
}
SC_OL SC_INLINE GV4 v4(GT x, GT y, GT z, GT w)
{
    GV4 r;
    r.x = x;
    r.y = y;
    r.z = z;
    r.w = w;
    return r;
}
SC_OL SC_INLINE GV3 add3(GV3 a, GV3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
SC_OL SC_INLINE GV3 sub3(GV3 a, GV3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
SC_OL SC_INLINE GV3 mul3(GV3 a, GT s) { return v3(a.x * s, a.y * s, a.z * s); }
SC_OL SC_INLINE GV3 neg3(GV3 a) { return v3(-a.x, -a.y, -a.z); }
SC_OL SC_INLINE GT dot3(GV3 a, GV3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
SC_OL SC_INLINE GV3 cross3(GV3 a, GV3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
SC_OL SC_INLINE GT len3(GV3 a) { return sqrt(dot3(a, a)); }
SC_OL SC_INLINE GV3 normalize3(GV3 a) { return mul3(a, RL(1) / len3(a)); }
// Component-wise select (a select of a whole struct keeps PoCL from vectorising).
SC_OL SC_INLINE GV3 sel3(GM c, GV3 a, GV3 b)
{
    return v3(c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z);
}
SC_OL SC_INLINE GV3 ld3(__global const REAL *a, GI i)
{
    return v3(ld1(a, 3 * i), ld1(a, 3 * i + 1), ld1(a, 3 * i + 2));
}
SC_OL SC_INLINE GV4 mul4(GV4 a, GT s) { return v4(a.x * s, a.y * s, a.z * s, a.w * s); }
SC_OL SC_INLINE GV4 ext4(GV3 a, GT w) { return v4(a.x, a.y, a.z, w); }

// ---------------------------------------------------------------------------
// Per-face geometry, shared by the atomic and gather variants.

typedef struct {
    GV3 e0, e1, e2; // e_i is the edge opposite corner i: p[i−1] − p[i+1]
    GT psum;        // |p0| + |p1| + |p2| (sums, not maxima: a max keeps PoCL from vectorising)
} GTri;

SC_OL SC_INLINE GTri make_tri(GV3 p0, GV3 p1, GV3 p2)
{
    GTri t;
    t.e0 = sub3(p2, p1);
    t.e1 = sub3(p0, p2);
    t.e2 = sub3(p1, p0);
    t.psum = len3(p0) + len3(p1) + len3(p2);
    return t;
}

SC_OL SC_INLINE GM tri_degenerate(GTri t)
{
    GT l0 = dot3(t.e0, t.e0), l1 = dot3(t.e1, t.e1), l2 = dot3(t.e2, t.e2);
    GT twice_area = len3(cross3(t.e0, t.e1));
    GT lsum = l0 + l1 + l2;
    // Written as negated comparisons so NaN counts as degenerate too.
    // Bitwise & (not &&): short-circuit branches keep PoCL from vectorising.
    return !((l0 > DEGEN_EDGE2) & (l1 > DEGEN_EDGE2) & (l2 > DEGEN_EDGE2) &
             (twice_area > DEGEN_AREA_REL * lsum) &
             (twice_area > DEGEN_HEIGHT_ULP * sqrt(lsum) * t.psum));
}

// Corner-weighted face normal (trimesh2 / Max 1999): the face's a×b divided by
// the squared lengths of the two edges at the corner, la (next edge) then lb.
SC_OL SC_INLINE GV3 corner_normal(GV3 fn, GT la, GT lb)
{
    return mul3(mul3(fn, RL(1) / la), RL(1) / lb); // two steps keep f32 in range
}
SC_OL SC_INLINE GV3 face_normal(GTri t) { return cross3(t.e2, t.e0); } // |.| = 2A, outward for CCW

// Voronoi (circumcentric) corner areas with trimesh2's obtuse-triangle rule.
SC_OL SC_INLINE GV3 corner_areas(GTri t)
{
    GT area = RL(0.5) * len3(cross3(t.e0, t.e1));
    GT l0 = dot3(t.e0, t.e0), l1 = dot3(t.e1, t.e1), l2 = dot3(t.e2, t.e2);
    GT ew0 = l0 * (l1 + l2 - l0), ew1 = l1 * (l2 + l0 - l1), ew2 = l2 * (l0 + l1 - l2);
    GT q = RL(-0.25) * area;
    // obtuse at corner 0, 1 or 2: the other two get the area cut off by the
    // perpendicular bisector of their edge to it, the obtuse corner the rest
    GT o01 = q * l2 / dot3(t.e0, t.e2), o02 = q * l1 / dot3(t.e0, t.e1);
    GT o12 = q * l0 / dot3(t.e1, t.e0), o10 = q * l2 / dot3(t.e1, t.e2);
    GT o20 = q * l1 / dot3(t.e2, t.e1), o21 = q * l0 / dot3(t.e2, t.e0);
    GT s = RL(0.5) * area / (ew0 + ew1 + ew2);
    GV3 acute = v3(s * (ew1 + ew2), s * (ew2 + ew0), s * (ew0 + ew1));
    GV3 obt0 = v3(area - o01 - o02, o01, o02);
    GV3 obt1 = v3(o10, area - o12 - o10, o12);
    GV3 obt2 = v3(o20, o21, area - o20 - o21);
    return sel3(ew0 <= 0, obt0, sel3(ew1 <= 0, obt1, sel3(ew2 <= 0, obt2, acute)));
}

// Weight of a face corner in its vertex's one-ring sum (0 when the vertex has no area).
SC_OL SC_INLINE GT corner_weight(GT ca, GT a) { return a > 0 ? ca / a : (GT)RL(0); }

// Rotate the frame (u, v) by the minimal rotation taking u×v onto nn.
SC_OL SC_INLINE void rot_coord_sys(GV3 u, GV3 v, GV3 nn, GV3 *ru, GV3 *rv)
{
    GV3 on = cross3(u, v);
    GT ndot = dot3(on, nn);
    GM flip = ndot <= RL(-1) + RL(1e-6); // opposite normals: a half turn
    GV3 perp_old = sub3(nn, mul3(on, ndot));
    GV3 dperp = mul3(add3(on, nn), RL(1) / (RL(1) + ndot));
    *ru = sel3(flip, neg3(u), sub3(u, mul3(dperp, dot3(u, perp_old))));
    *rv = sel3(flip, neg3(v), sub3(v, mul3(dperp, dot3(v, perp_old))));
}

// The coefficients (u1, v1, u2, v2) that re-express a tensor given in the
// frame (ou, ov) in the frame (nu, nv): (nu, nv) rotated into the plane of
// (ou, ov), dotted with ou and ov. The projection the other way, from
// (nu, nv) to (ou, ov), has the coefficients (u1, u2, v1, v2) (coef_reverse):
// the minimal rotations between the two planes are each other's inverse, so
// one set serves both directions (the derivative pass projects each vertex's
// tensor into the face frame and the face's result back into the vertex's).
SC_OL SC_INLINE GV4 proj_coef(GV3 ou, GV3 ov, GV3 nu, GV3 nv)
{
    GV3 ru, rv;
    rot_coord_sys(nu, nv, cross3(ou, ov), &ru, &rv);
    return v4(dot3(ru, ou), dot3(ru, ov), dot3(rv, ou), dot3(rv, ov));
}
SC_OL SC_INLINE GV4 coef_reverse(GV4 c) { return v4(c.x, c.z, c.y, c.w); }

// Re-express the tensor k = (ku, kuv, kv) by the coefficients c of proj_coef.
SC_OL SC_INLINE GV3 proj_curv_by(GV4 c, GV3 k)
{
    GT u1 = c.x, v1 = c.y, u2 = c.z, v2 = c.w;
    return v3(k.x * u1 * u1 + k.y * (RL(2) * u1 * v1) + k.z * v1 * v1,
              k.x * u1 * u2 + k.y * (u1 * v2 + u2 * v1) + k.z * v1 * v2,
              k.x * u2 * u2 + k.y * (RL(2) * u2 * v2) + k.z * v2 * v2);
}
SC_OL SC_INLINE GV3 proj_curv(GV3 ou, GV3 ov, GV3 k, GV3 nu, GV3 nv)
{
    return proj_curv_by(proj_coef(ou, ov, nu, nv), k);
}

// The same for the third-order tensor d = (C111, C112, C122, C222).
SC_OL SC_INLINE GV4 proj_dcurv_by(GV4 c, GV4 d)
{
    GT u1 = c.x, v1 = c.y, u2 = c.z, v2 = c.w;
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
SC_OL SC_INLINE void face_frame(GTri t, GV3 *ft, GV3 *fb)
{
    *ft = normalize3(t.e0);
    *fb = normalize3(cross3(cross3(t.e0, t.e1), *ft));
}

// Least-squares second fundamental form of a face from the normal differences
// along its edges (edge e_i pairs with n[i−1] − n[i+1]). The normal equations
// [[w00 w01 0] [w01 w00+w22 w01] [0 w01 w22]] are tridiagonal; LDLᵀ unrolled.
// The mask is false where a pivot is not positive or the result is not finite.
SC_OL SC_INLINE GM face_tensor(GTri t, GV3 ft, GV3 fb, GV3 n0, GV3 n1, GV3 n2, GV3 *x)
{
    GT w00 = 0, w01 = 0, w22 = 0, m0 = 0, m1 = 0, m2 = 0;
#define TENSOR_EDGE(e, dn)                                 \
    {                                                      \
        GT u = dot3(e, ft), v = dot3(e, fb);               \
        GT dnu = dot3(dn, ft), dnv = dot3(dn, fb);         \
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
    GT w11 = w00 + w22, w12 = w01;
    GT d0 = w00;
    GT r0 = RL(1) / d0;
    GT l10 = w01 * r0;
    GT d1 = w11 - l10 * w01;
    GT r1 = RL(1) / d1;
    GT l21 = w12 * r1;
#ifdef SC_COMPAT
    GT d2 = w22; // trimesh2 2.16's pivot quirk (reads the lower triangle before filling it)
#else
    GT d2 = w22 - l21 * w12;
#endif
    GT y1 = m1 - l10 * m0;
    GT y2 = m2 - l21 * y1;
    GT x2 = y2 / d2;
    GT x1 = y1 * r1 - l21 * x2;
    GT x0 = m0 * r0 - l10 * x1;
    *x = v3(x0, x1, x2);
    return (d0 > 0) & (d1 > 0) & (d2 > 0) & isfinite(x0) & isfinite(x1) & isfinite(x2);
}

// Least-squares curvature derivative of a face from the differences of the
// vertex tensors (in the face frame) along its edges. The 4×4 normal equations
// [[a b 0 0] [b 2a+c 2b 0] [0 2b a+2c b] [0 0 b c]] (a = Σu², b = Σuv, c = Σv²)
// are tridiagonal too.
SC_OL SC_INLINE GM face_dcurv(GTri t, GV3 ft, GV3 fb, GV3 f0, GV3 f1, GV3 f2, GV4 *x)
{
    GT a = 0, b = 0, c = 0, m0 = 0, m1 = 0, m2 = 0, m3 = 0;
#define DCURV_EDGE(e, d)                                   \
    {                                                      \
        GT u = dot3(e, ft), v = dot3(e, fb);               \
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
    GT d0 = a;
    GT r0 = RL(1) / d0;
    GT l10 = b * r0;
    GT d1 = RL(2) * a + c - l10 * b;
    GT r1 = RL(1) / d1;
    GT l21 = RL(2) * b * r1;
    GT d2 = a + RL(2) * c - l21 * (RL(2) * b);
    GT r2 = RL(1) / d2;
    GT l32 = b * r2;
    GT d3 = c - l32 * b;
    GT y1 = m1 - l10 * m0;
    GT y2 = m2 - l21 * y1;
    GT y3 = m3 - l32 * y2;
    GT x3 = y3 / d3;
    GT x2 = y2 * r2 - l32 * x3;
    GT x1 = y1 * r1 - l21 * x2;
    GT x0 = m0 * r0 - l10 * x1;
    *x = v4(x0, x1, x2, x3);
    return (d0 > 0) & (d1 > 0) & (d2 > 0) & (d3 > 0) & isfinite(x0) & isfinite(x1) &
           isfinite(x2) & isfinite(x3);
}

// ---------------------------------------------------------------------------
// Per-vertex steps of curv_frames and curv_principal (one vertex per lane).

// Any unit vector perpendicular to n (n unit).
SC_OL SC_INLINE GV3 any_perp(GV3 n)
{
    GT ax = fabs(n.x), ay = fabs(n.y), az = fabs(n.z);
    GT o = (GT)RL(1), z = (GT)RL(0);
    GV3 ex = v3(o, z, z), ey = v3(z, o, z), ez = v3(z, z, o);
    GV3 a = sel3((ax <= ay) & (ax <= az), ex, sel3(ay <= az, ey, ez));
    return normalize3(cross3(n, a));
}

// The unit normal of an accumulated one; +z where it has no finite length.
SC_OL SC_INLINE GV3 unit_normal(GV3 n)
{
    GT len = len3(n);
    GT o = (GT)RL(1), z = (GT)RL(0);
    return sel3((len > 0) & isfinite(len), mul3(n, RL(1) / len), v3(z, z, o));
}

// The initial first direction: e × n made unit, e the edge from the vertex
// to the next vertex of its owner face; any perpendicular to n where there
// is no owner face (`owned` false) or e × n has no length.
SC_OL SC_INLINE GV3 first_dir(GV3 e, GV3 n, GM owned)
{
    GV3 p1 = cross3(e, n);
    GT l = len3(p1);
    return sel3(owned & (l > RL(1e-20)) & isfinite(l), mul3(p1, RL(1) / l), any_perp(n));
}

// One Jacobi rotation diagonalises the tensor t = (ku, kuv, kv) given in the
// frame (ru, rv): the first principal direction, with the principal
// curvatures in *ka ≥ *kb (|*ka| ≥ |*kb| with SC_COMPAT).
SC_OL SC_INLINE GV3 principal_dir(GV3 ru, GV3 rv, GV3 t, GT *ka, GT *kb)
{
    GT ku = t.x, kuv = t.y, kv = t.z;
    GT h = RL(0.5) * (kv - ku) / kuv;
    GT root = sqrt(RL(1) + h * h);
    GT tt = kuv != 0 ? ((h < 0) ? RL(1) / (h - root) : RL(1) / (h + root)) : (GT)RL(0);
    GT c = RL(1) / sqrt(RL(1) + tt * tt);
    GT s = tt * c;
    GT k1 = ku - tt * kuv, k2 = kv + tt * kuv;
#ifdef SC_COMPAT
    GM keep = fabs(k1) >= fabs(k2);
#else
    GM keep = k1 >= k2;
#endif
    *ka = keep ? k1 : k2;
    *kb = keep ? k2 : k1;
    return sel3(keep, sub3(mul3(ru, c), mul3(rv, s)), add3(mul3(ru, s), mul3(rv, c)));
}

// ---------------------------------------------------------------------------
// Reads of per-vertex state inside face kernels.

// The proj_coef coefficients from vertex v's frame to a face frame (ft, fb).
SC_OL SC_INLINE GV4 vertex_coef(__global const REAL *pd1, __global const REAL *pd2, GI v, GV3 ft,
                                GV3 fb)
{
    return proj_coef(ld3(pd1, v), ld3(pd2, v), ft, fb);
}
// A vertex tensor (diagonal in (d1, d2)) re-expressed in a face frame, by
// the coefficients of vertex_coef.
SC_OL SC_INLINE GV3 vertex_curv_by(__global const REAL *kk, GI v, GV4 c)
{
    return proj_curv_by(c, v3(ld1(kk, 2 * v), (GT)RL(0), ld1(kk, 2 * v + 1)));
}

// The tensor of face (ft, fb, x) in vertex v's frame, times the corner's
// weight w in v's one-ring sum.
SC_OL SC_INLINE GV3 tensor_w(__global const REAL *pd1, __global const REAL *pd2, GI v, GT w,
                             GV3 ft, GV3 fb, GV3 x)
{
    return mul3(proj_curv(ft, fb, x, ld3(pd1, v), ld3(pd2, v)), w);
}
// The same with the weight from the corner area ca and v's point area.
SC_OL SC_INLINE GV3 tensor_at(__global const REAL *pd1, __global const REAL *pd2,
                              __global const REAL *area, GI v, GT ca, GV3 ft, GV3 fb, GV3 x)
{
    return tensor_w(pd1, pd2, v, corner_weight(ca, ld1(area, v)), ft, fb, x);
}

// The weighted derivative tensor of a face in a vertex's frame, from the
// vertex_coef coefficients c of that vertex and face.
SC_OL SC_INLINE GV4 dcurv_by(GV4 c, GT w, GV4 x) { return mul4(proj_dcurv_by(coef_reverse(c), x), w); }

// A face's corner contribution where `use` holds, zero elsewhere (selected,
// never multiplied, so NaN cannot leak).
SC_OL SC_INLINE GV4 zero_unless(GM use, GV4 x)
{
    return v4(use ? x.x : (GT)RL(0), use ? x.y : (GT)RL(0), use ? x.z : (GT)RL(0),
              use ? x.w : (GT)RL(0));
}
#endif // GT
