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
// The *_gather kernels are the per-vertex twins of the three per-face passes:
// each vertex walks its one-ring (CSR lists built once on the host, sorted by
// face id) and sums in a fixed order: no atomics, bitwise reproducible.
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
//
// Degenerate faces (an edge shorter than 1e-12 of the mesh's RMS radius,
// twice the area below 1e-7 × longest edge², or a height below the f32
// rounding of the positions, 4·2⁻²⁴·max|p|) are skipped in every pass and
// counted once; the rule is the same at every precision and in the CPU twin. A least-squares system whose pivots are not positive (rounding
// on extreme slivers) is skipped and counted. Nothing here can write NaN.
//
// Build options: -DSC_DOUBLE (double precision), -DSC_COMPAT (trimesh2 2.16:
// its 3×3 LDLᵀ third pivot Σv² instead of Σv² − (Σuv)²/d1, and |k1| ≥ |k2|
// ordering instead of k1 ≥ k2).

#define DEGEN_AREA_REL RL(1e-7)
#define DEGEN_EDGE2 RL(1e-24)
#define DEGEN_HEIGHT_ULP RL(2.384185791015625e-7) // 4 × 2^-24: below f32 rounding of positions

#define NEXT3(i) ((i) == 2 ? 0 : (i) + 1)
#define PREV3(i) ((i) == 0 ? 2 : (i) - 1)

inline REAL3 ld3(__global const REAL *a, uint i) { return vload3(i, a); }

typedef struct {
    uint v[3];
    REAL3 p[3];
    REAL3 e[3]; // e[i] is the edge opposite corner i: p[PREV3(i)] − p[NEXT3(i)]
    REAL pmax;  // largest |p| of the corners
} Tri;

inline Tri load_tri(__global const REAL *pos, __global const uint *faces, uint f)
{
    Tri t;
    for (int i = 0; i < 3; i++) {
        t.v[i] = faces[3 * f + i];
        t.p[i] = ld3(pos, t.v[i]);
    }
    for (int i = 0; i < 3; i++)
        t.e[i] = t.p[PREV3(i)] - t.p[NEXT3(i)];
    t.pmax = fmax(length(t.p[0]), fmax(length(t.p[1]), length(t.p[2])));
    return t;
}

inline bool tri_degenerate(const Tri *t)
{
    REAL l0 = dot(t->e[0], t->e[0]), l1 = dot(t->e[1], t->e[1]), l2 = dot(t->e[2], t->e[2]);
    // Written as negated comparisons so NaN counts as degenerate too.
    if (!(l0 > DEGEN_EDGE2 && l1 > DEGEN_EDGE2 && l2 > DEGEN_EDGE2))
        return true;
    REAL twice_area = length(cross(t->e[0], t->e[1]));
    REAL lmax = fmax(l0, fmax(l1, l2));
    return !(twice_area > DEGEN_AREA_REL * lmax &&
             twice_area > DEGEN_HEIGHT_ULP * sqrt(lmax) * t->pmax);
}

// Corner-weighted face normal for corner c (trimesh2 / Max 1999): the face's
// a×b divided by the squared lengths of the two edges at that corner.
inline REAL3 corner_normal(const Tri *t, int c)
{
    REAL3 fn = cross(t->e[2], t->e[0]); // (p1−p0)×(p2−p1): |fn| = 2A, outward for CCW
    REAL la = dot(t->e[NEXT3(c)], t->e[NEXT3(c)]);
    REAL lb = dot(t->e[PREV3(c)], t->e[PREV3(c)]);
    return (fn / la) / lb; // two divisions keep f32 in range for tiny edges
}

// Voronoi (circumcentric) corner areas with trimesh2's obtuse-triangle rule.
inline void corner_areas(const Tri *t, REAL ca[3])
{
    const REAL3 *e = t->e;
    REAL area = RL(0.5) * length(cross(e[0], e[1]));
    REAL l2[3] = {dot(e[0], e[0]), dot(e[1], e[1]), dot(e[2], e[2])};
    REAL ew[3] = {l2[0] * (l2[1] + l2[2] - l2[0]), l2[1] * (l2[2] + l2[0] - l2[1]),
                  l2[2] * (l2[0] + l2[1] - l2[2])};
    if (ew[0] <= RL(0)) {
        ca[1] = RL(-0.25) * l2[2] * area / dot(e[0], e[2]);
        ca[2] = RL(-0.25) * l2[1] * area / dot(e[0], e[1]);
        ca[0] = area - ca[1] - ca[2];
    } else if (ew[1] <= RL(0)) {
        ca[2] = RL(-0.25) * l2[0] * area / dot(e[1], e[0]);
        ca[0] = RL(-0.25) * l2[2] * area / dot(e[1], e[2]);
        ca[1] = area - ca[2] - ca[0];
    } else if (ew[2] <= RL(0)) {
        ca[0] = RL(-0.25) * l2[1] * area / dot(e[2], e[1]);
        ca[1] = RL(-0.25) * l2[0] * area / dot(e[2], e[0]);
        ca[2] = area - ca[0] - ca[1];
    } else {
        REAL s = RL(0.5) * area / (ew[0] + ew[1] + ew[2]);
        for (int j = 0; j < 3; j++)
            ca[j] = s * (ew[NEXT3(j)] + ew[PREV3(j)]);
    }
}

// Weight of a face corner in its vertex's one-ring sum (0 when the vertex has no area).
inline REAL corner_weight(REAL ca, REAL a) { return a > 0 ? ca / a : RL(0); }

// Any unit vector perpendicular to n (n unit).
inline REAL3 any_perp(REAL3 n)
{
    REAL3 a = fabs(n.x) <= fabs(n.y) && fabs(n.x) <= fabs(n.z) ? (REAL3)(1, 0, 0)
              : fabs(n.y) <= fabs(n.z)                         ? (REAL3)(0, 1, 0)
                                                               : (REAL3)(0, 0, 1);
    return normalize(cross(n, a));
}

// Rotate the frame (u, v) by the minimal rotation taking u×v onto nn.
inline void rot_coord_sys(REAL3 u, REAL3 v, REAL3 nn, REAL3 *ru, REAL3 *rv)
{
    REAL3 on = cross(u, v);
    REAL ndot = dot(on, nn);
    if (ndot <= RL(-1) + RL(1e-6)) { // opposite normals: a half turn
        *ru = -u;
        *rv = -v;
        return;
    }
    REAL3 perp_old = nn - ndot * on;
    REAL3 dperp = (on + nn) / (RL(1) + ndot);
    *ru = u - dperp * dot(u, perp_old);
    *rv = v - dperp * dot(v, perp_old);
}

// Re-express the tensor (ku, kuv, kv) given in (ou, ov) in the frame (nu, nv).
inline REAL3 proj_curv(REAL3 ou, REAL3 ov, REAL3 k, REAL3 nu, REAL3 nv)
{
    REAL3 ru, rv;
    rot_coord_sys(nu, nv, cross(ou, ov), &ru, &rv);
    REAL u1 = dot(ru, ou), v1 = dot(ru, ov), u2 = dot(rv, ou), v2 = dot(rv, ov);
    return (REAL3)(k.x * u1 * u1 + k.y * (RL(2) * u1 * v1) + k.z * v1 * v1,
                   k.x * u1 * u2 + k.y * (u1 * v2 + u2 * v1) + k.z * v1 * v2,
                   k.x * u2 * u2 + k.y * (RL(2) * u2 * v2) + k.z * v2 * v2);
}

// The same for the third-order tensor (C111, C112, C122, C222).
inline void proj_dcurv(REAL3 ou, REAL3 ov, const REAL d[4], REAL3 nu, REAL3 nv, REAL o[4])
{
    REAL3 ru, rv;
    rot_coord_sys(nu, nv, cross(ou, ov), &ru, &rv);
    REAL u1 = dot(ru, ou), v1 = dot(ru, ov), u2 = dot(rv, ou), v2 = dot(rv, ov);
    o[0] = d[0] * u1 * u1 * u1 + d[1] * RL(3) * u1 * u1 * v1 + d[2] * RL(3) * u1 * v1 * v1 +
           d[3] * v1 * v1 * v1;
    o[1] = d[0] * u1 * u1 * u2 + d[1] * (u1 * u1 * v2 + RL(2) * u2 * u1 * v1) +
           d[2] * (u2 * v1 * v1 + RL(2) * u1 * v1 * v2) + d[3] * v1 * v1 * v2;
    o[2] = d[0] * u1 * u2 * u2 + d[1] * (u2 * u2 * v1 + RL(2) * u1 * u2 * v2) +
           d[2] * (u1 * v2 * v2 + RL(2) * u2 * v2 * v1) + d[3] * v1 * v2 * v2;
    o[3] = d[0] * u2 * u2 * u2 + d[1] * RL(3) * u2 * u2 * v2 + d[2] * RL(3) * u2 * v2 * v2 +
           d[3] * v2 * v2 * v2;
}

// Face frame: t along e[0], b in the face plane, t × b = face normal.
inline void face_frame(const Tri *t, REAL3 *ft, REAL3 *fb)
{
    *ft = normalize(t->e[0]);
    *fb = normalize(cross(cross(t->e[0], t->e[1]), *ft));
}

// Least-squares second fundamental form of a face from the normal differences
// along its edges. Returns false when a pivot is not positive.
inline bool face_tensor(const Tri *t, REAL3 ft, REAL3 fb, const REAL3 n[3], REAL3 *x)
{
    REAL w00 = 0, w01 = 0, w22 = 0, m0 = 0, m1 = 0, m2 = 0;
    for (int j = 0; j < 3; j++) {
        REAL u = dot(t->e[j], ft), v = dot(t->e[j], fb);
        w00 += u * u;
        w01 += u * v;
        w22 += v * v;
        REAL3 dn = n[PREV3(j)] - n[NEXT3(j)];
        REAL dnu = dot(dn, ft), dnv = dot(dn, fb);
        m0 += dnu * u;
        m1 += dnu * v + dnv * u;
        m2 += dnv * v;
    }
    // Normal equations [[w00 w01 0] [w01 w00+w22 w01] [0 w01 w22]] solved by LDLᵀ.
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
    if (!(d0 > 0 && d1 > 0 && d2 > 0))
        return false;
    REAL y1 = m1 - l10 * m0;
    REAL y2 = m2 - l21 * y1;
    REAL x2 = y2 / d2;
    REAL x1 = y1 / d1 - l21 * x2;
    REAL x0 = m0 / d0 - l10 * x1;
    *x = (REAL3)(x0, x1, x2);
    return isfinite(x0) && isfinite(x1) && isfinite(x2);
}

// Least-squares curvature derivative of a face from the differences of the
// vertex curvature tensors (projected into the face frame) along its edges.
inline bool face_dcurv(const Tri *t, REAL3 ft, REAL3 fb, const REAL3 fc[3], REAL x[4])
{
    REAL w[4][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}};
    REAL m[4] = {0, 0, 0, 0};
    for (int j = 0; j < 3; j++) {
        REAL3 d = fc[PREV3(j)] - fc[NEXT3(j)];
        REAL u = dot(t->e[j], ft), v = dot(t->e[j], fb);
        w[0][0] += u * u;
        w[0][1] += u * v;
        w[3][3] += v * v;
        m[0] += u * d.x;
        m[1] += v * d.x + RL(2) * u * d.y;
        m[2] += RL(2) * v * d.y + u * d.z;
        m[3] += v * d.z;
    }
    w[1][1] = RL(2) * w[0][0] + w[3][3];
    w[1][2] = RL(2) * w[0][1];
    w[2][2] = w[0][0] + RL(2) * w[3][3];
    w[2][3] = w[0][1];
    // Symmetric: fill the lower triangle, then a plain LDLᵀ (L unit lower, D diagonal).
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < i; j++)
            w[i][j] = w[j][i];
    REAL L[4][4], D[4];
    for (int j = 0; j < 4; j++) {
        REAL s = w[j][j];
        for (int k = 0; k < j; k++)
            s -= L[j][k] * L[j][k] * D[k];
        if (!(s > 0))
            return false;
        D[j] = s;
        for (int i = j + 1; i < 4; i++) {
            REAL r = w[i][j];
            for (int k = 0; k < j; k++)
                r -= L[i][k] * L[j][k] * D[k];
            L[i][j] = r / s;
        }
    }
    REAL y[4];
    for (int i = 0; i < 4; i++) {
        REAL s = m[i];
        for (int k = 0; k < i; k++)
            s -= L[i][k] * y[k];
        y[i] = s;
    }
    for (int i = 3; i >= 0; i--) {
        REAL s = y[i] / D[i];
        for (int k = i + 1; k < 4; k++)
            s -= L[k][i] * x[k];
        x[i] = s;
    }
    return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]) && isfinite(x[3]);
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
// Atomic (scatter) variant: one work-item per face, float atomics on the one-ring.

__kernel void curv_clear(uint nv, __global REAL *nrm, __global REAL *area, __global REAL *tens,
                         __global REAL *dk)
{
    GID_OR_RETURN(nv);
    vstore3((REAL3)(0, 0, 0), gid, nrm);
    area[gid] = 0;
    vstore3((REAL3)(0, 0, 0), gid, tens);
    dk[4 * gid + 0] = 0;
    dk[4 * gid + 1] = 0;
    dk[4 * gid + 2] = 0;
    dk[4 * gid + 3] = 0;
}

__kernel void curv_normals_areas(uint nf, __global const REAL *pos, __global const uint *faces,
                                 volatile __global REAL *nrm, volatile __global REAL *area,
                                 volatile __global uint *counters)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    if (tri_degenerate(&t)) {
        atomic_inc(&counters[0]);
        return;
    }
    REAL ca[3];
    corner_areas(&t, ca);
    for (int c = 0; c < 3; c++) {
        REAL3 cn = corner_normal(&t, c);
        uint v = t.v[c];
        atomic_add_real(&nrm[3 * v + 0], cn.x);
        atomic_add_real(&nrm[3 * v + 1], cn.y);
        atomic_add_real(&nrm[3 * v + 2], cn.z);
        atomic_add_real(&area[v], ca[c]);
    }
}

// Per vertex: unit normal, and the initial tangent frame from the owner face:
// pd1 = (edge to the next vertex of that face) × n, pd2 = n × pd1.
__kernel void curv_frames(uint nv, __global const REAL *pos, __global const uint *faces,
                          __global const int *owner, __global REAL *nrm,
                          __global const REAL *area, __global REAL *pd1, __global REAL *pd2,
                          volatile __global uint *counters)
{
    GID_OR_RETURN(nv);
    REAL3 n = ld3(nrm, gid);
    REAL len = length(n);
    n = (len > 0 && isfinite(len)) ? n / len : (REAL3)(0, 0, 1);
    vstore3(n, gid, nrm);
    if (!(area[gid] > 0))
        atomic_inc(&counters[1]);
    REAL3 p1 = (REAL3)(0, 0, 0);
    int f = owner[gid];
    if (f >= 0) {
        uint a = faces[3 * f], b = faces[3 * f + 1], c = faces[3 * f + 2];
        uint next = gid == a ? b : gid == b ? c : a;
        p1 = cross(ld3(pos, next) - ld3(pos, gid), n);
    }
    REAL l = length(p1);
    p1 = (l > RL(1e-20) && isfinite(l)) ? p1 / l : any_perp(n);
    vstore3(p1, gid, pd1);
    vstore3(cross(n, p1), gid, pd2);
}

inline void load_normals(const Tri *t, __global const REAL *nrm, REAL3 n[3])
{
    for (int i = 0; i < 3; i++)
        n[i] = ld3(nrm, t->v[i]);
}

__kernel void curv_tensor(uint nf, __global const REAL *pos, __global const uint *faces,
                          __global const REAL *nrm, __global const REAL *area,
                          __global const REAL *pd1, __global const REAL *pd2,
                          volatile __global REAL *tens, volatile __global uint *counters)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    if (tri_degenerate(&t))
        return;
    REAL3 ft, fb, n[3], x;
    face_frame(&t, &ft, &fb);
    load_normals(&t, nrm, n);
    if (!face_tensor(&t, ft, fb, n, &x)) {
        atomic_inc(&counters[2]);
        return;
    }
    REAL ca[3];
    corner_areas(&t, ca);
    for (int c = 0; c < 3; c++) {
        uint v = t.v[c];
        REAL3 k = proj_curv(ft, fb, x, ld3(pd1, v), ld3(pd2, v)) * corner_weight(ca[c], area[v]);
        atomic_add_real(&tens[3 * v + 0], k.x);
        atomic_add_real(&tens[3 * v + 1], k.y);
        atomic_add_real(&tens[3 * v + 2], k.z);
    }
}

// Per vertex: one Jacobi rotation diagonalises the 2×2 tensor.
__kernel void curv_principal(uint nv, __global const REAL *nrm, __global const REAL *tens,
                             __global REAL *pd1, __global REAL *pd2, __global REAL *kk)
{
    GID_OR_RETURN(nv);
    REAL3 n = ld3(nrm, gid), ru, rv;
    rot_coord_sys(ld3(pd1, gid), ld3(pd2, gid), n, &ru, &rv);
    REAL3 k = ld3(tens, gid);
    REAL ku = k.x, kuv = k.y, kv = k.z;
    REAL c = 1, s = 0, tt = 0;
    if (kuv != 0) {
        REAL h = RL(0.5) * (kv - ku) / kuv;
        tt = (h < 0) ? RL(1) / (h - sqrt(RL(1) + h * h)) : RL(1) / (h + sqrt(RL(1) + h * h));
        c = RL(1) / sqrt(RL(1) + tt * tt);
        s = tt * c;
    }
    REAL k1 = ku - tt * kuv, k2 = kv + tt * kuv;
    REAL3 d1;
#ifdef SC_COMPAT
    bool keep = fabs(k1) >= fabs(k2);
#else
    bool keep = k1 >= k2;
#endif
    if (keep) {
        d1 = c * ru - s * rv;
    } else {
        REAL tmp = k1;
        k1 = k2;
        k2 = tmp;
        d1 = s * ru + c * rv;
    }
    vstore3(d1, gid, pd1);
    vstore3(cross(n, d1), gid, pd2);
    kk[2 * gid] = k1;
    kk[2 * gid + 1] = k2;
}

// The vertex tensors of a face (diagonal in (d1, d2)) re-expressed in its frame.
inline void face_vertex_curv(const Tri *t, REAL3 ft, REAL3 fb, __global const REAL *pd1,
                             __global const REAL *pd2, __global const REAL *kk, REAL3 fc[3])
{
    for (int j = 0; j < 3; j++) {
        uint v = t->v[j];
        fc[j] = proj_curv(ld3(pd1, v), ld3(pd2, v), (REAL3)(kk[2 * v], 0, kk[2 * v + 1]), ft, fb);
    }
}

__kernel void curv_dcurv(uint nf, __global const REAL *pos, __global const uint *faces,
                         __global const REAL *area, __global const REAL *pd1,
                         __global const REAL *pd2, __global const REAL *kk,
                         volatile __global REAL *dk, volatile __global uint *counters)
{
    GID_OR_RETURN(nf);
    Tri t = load_tri(pos, faces, gid);
    if (tri_degenerate(&t))
        return;
    REAL3 ft, fb, fc[3];
    face_frame(&t, &ft, &fb);
    face_vertex_curv(&t, ft, fb, pd1, pd2, kk, fc);
    REAL x[4];
    if (!face_dcurv(&t, ft, fb, fc, x)) {
        atomic_inc(&counters[3]);
        return;
    }
    REAL ca[3];
    corner_areas(&t, ca);
    for (int c = 0; c < 3; c++) {
        uint v = t.v[c];
        REAL o[4];
        proj_dcurv(ft, fb, x, ld3(pd1, v), ld3(pd2, v), o);
        REAL wt = corner_weight(ca[c], area[v]);
        for (int i = 0; i < 4; i++)
            atomic_add_real(&dk[4 * v + i], wt * o[i]);
    }
}

// ---------------------------------------------------------------------------
// Gather variant: one work-item per vertex, summing its one-ring in face order.
// Each face is counted (degenerate, solve skipped) by the vertex at its corner 0.

__kernel void curv_normals_areas_gather(uint nv, __global const REAL *pos,
                                        __global const uint *faces,
                                        __global const uint *ring_off, __global const uint *ring,
                                        __global REAL *nrm, __global REAL *area,
                                        volatile __global uint *counters)
{
    GID_OR_RETURN(nv);
    REAL3 n = (REAL3)(0, 0, 0);
    REAL a = 0;
    for (uint r = ring_off[gid]; r < ring_off[gid + 1]; r++) {
        uint f = ring[r] / 3, c = ring[r] % 3;
        Tri t = load_tri(pos, faces, f);
        if (tri_degenerate(&t)) {
            if (c == 0)
                atomic_inc(&counters[0]);
            continue;
        }
        REAL ca[3];
        corner_areas(&t, ca);
        n += corner_normal(&t, c);
        a += ca[c];
    }
    vstore3(n, gid, nrm);
    area[gid] = a;
}

__kernel void curv_tensor_gather(uint nv, __global const REAL *pos, __global const uint *faces,
                                 __global const uint *ring_off, __global const uint *ring,
                                 __global const REAL *nrm, __global const REAL *area,
                                 __global const REAL *pd1, __global const REAL *pd2,
                                 __global REAL *tens, volatile __global uint *counters)
{
    GID_OR_RETURN(nv);
    REAL3 acc = (REAL3)(0, 0, 0);
    REAL3 u = ld3(pd1, gid), v = ld3(pd2, gid);
    REAL a = area[gid];
    for (uint r = ring_off[gid]; r < ring_off[gid + 1]; r++) {
        uint f = ring[r] / 3, c = ring[r] % 3;
        Tri t = load_tri(pos, faces, f);
        if (tri_degenerate(&t))
            continue;
        REAL3 ft, fb, n[3], x;
        face_frame(&t, &ft, &fb);
        load_normals(&t, nrm, n);
        if (!face_tensor(&t, ft, fb, n, &x)) {
            if (c == 0)
                atomic_inc(&counters[2]);
            continue;
        }
        REAL ca[3];
        corner_areas(&t, ca);
        acc += proj_curv(ft, fb, x, u, v) * corner_weight(ca[c], a);
    }
    vstore3(acc, gid, tens);
}

__kernel void curv_dcurv_gather(uint nv, __global const REAL *pos, __global const uint *faces,
                                __global const uint *ring_off, __global const uint *ring,
                                __global const REAL *area, __global const REAL *pd1,
                                __global const REAL *pd2, __global const REAL *kk,
                                __global REAL *dk, volatile __global uint *counters)
{
    GID_OR_RETURN(nv);
    REAL acc[4] = {0, 0, 0, 0};
    REAL3 u = ld3(pd1, gid), v = ld3(pd2, gid);
    REAL a = area[gid];
    for (uint r = ring_off[gid]; r < ring_off[gid + 1]; r++) {
        uint f = ring[r] / 3, c = ring[r] % 3;
        Tri t = load_tri(pos, faces, f);
        if (tri_degenerate(&t))
            continue;
        REAL3 ft, fb, fc[3];
        face_frame(&t, &ft, &fb);
        face_vertex_curv(&t, ft, fb, pd1, pd2, kk, fc);
        REAL x[4];
        if (!face_dcurv(&t, ft, fb, fc, x)) {
            if (c == 0)
                atomic_inc(&counters[3]);
            continue;
        }
        REAL ca[3], o[4];
        corner_areas(&t, ca);
        proj_dcurv(ft, fb, x, u, v, o);
        REAL wt = corner_weight(ca[c], a);
        for (int i = 0; i < 4; i++)
            acc[i] += wt * o[i];
    }
    for (int i = 0; i < 4; i++)
        dk[4 * gid + i] = acc[i];
}
