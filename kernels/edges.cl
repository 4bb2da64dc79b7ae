// edges.cl: object-space feature edges with caps (House & Li, "Real-Time
// Object-Space Edge Detection using OpenCL"; McGuire & Hughes 2004).
//
// Passes (host: src/stages/edges.rs; CPU twin with the same step names:
// src/cpu/edges.rs):
//   edges_detect    per edge  contour / crease / boundary+marked tests; writes one
//                             projection-space quad (4 float4) per edge to edge_out,
//                             or the degenerate quad (NaN, 0, −1, 1) ×4
//   caps_mh         per edge  McGuire-Hughes half-caps: one triangle at each end, from
//                             the projected vertex normal, into cap_mh0 / cap_mh1
//   caps_adjacency_flags, caps_adjacency
//                   per cap   House & Li adjacency cap: for a pair of edges sharing a
//                             vertex, both drawn, a quad (middle vector, p0, sM, p1);
//                             flags scanned into slots, drawn caps compacted
//
// Buffers (V vertices, E edge entries, C cap pairs):
//   params   EdgeParams per frame, see below (packed by EdgeParams::pack)
//   pos      float[3V]  world-space positions        nrm float[3V] unit vertex normals
//   edges    uint[4E]   (i0, i1, i2, i3); i3 == i0: boundary or marked
//   caps     uint[2C]   (e0, e1) edge entries sharing an end vertex (sorted by vertex)
//   edge_out float[16E] quad vertices 0 = s0 − p, 1 = s1 − p, 2 = s1 + p, 3 = s0 + p;
//                       contour half quads (optional): s0, s1, s1 + 2p', s0 + 2p'
//   kind     uint[E]    bit 0 contour, 1 crease, 2 boundary/marked, 3 drawn
//   cap_mh0, cap_mh1 float[12E]  half-cap triangles (s, s + p·sign(m·p), s + m)
//   cap_slot uint[C]    flags, then (scanned) each cap pair's slot among the drawn caps
//   cap_adj  float[16K] the K drawn caps' quads (sM + mv, sM + p0, sM, sM + p1)
// An edge undrawn now and in the previous run keeps its marker (not rewritten).
//
// Conventions (src/stages/edges.rs): clip space is OpenGL's; the screen is in
// pixels from the viewport centre; p is the unit screen perpendicular times half
// the line width times max(1, k/w). An edge with an end at w ≤ w_min is not
// drawn. Crease: na·nb < cos θ |na||nb|. Scalar code only; details and the
// vectoriser's measurements: docs/notes/isosurface-kernels.md.

// The per-frame parameter block. Mirrors the Rust struct
// spec::edges::EdgeParamBlock field by field (same names, same order, every
// field a 4-byte float, so neither side pads); a probe-kernel test in
// src/stages/edges.rs checks sizeof and each offsetof on the device.
typedef struct {
    float view_proj[16]; // world to clip, column-major
    float eye[3];
    float view_dir[3];   // unit, eye towards target
    float ortho;         // 1: orthographic
    float half_vw;       // half viewport width, pixels
    float half_vh;       // half viewport height, pixels
    float half_width;    // half line width, pixels
    float cos_crease;    // −2: no creases
    float depth_k;       // 0: constant width
    float w_min;         // near-plane w (0 when orthographic)
    float contours;      // 1: detect contours
    float boundaries;    // 1: draw boundary and marked edges
    float half_contours; // 1: contour-only edges as half quads
} EdgeParams;

#define KIND_CONTOUR 1u
#define KIND_CREASE 2u
#define KIND_BOUNDARY 4u
#define KIND_DRAWN 8u

// Writes the marker vertex (NaN, 0, −1, 1) at float4 slot `slot` of `out`.
#define WRITE_MARKER(out, slot)              \
    do {                                     \
        (out)[4 * (slot) + 0] = NAN;         \
        (out)[4 * (slot) + 1] = 0.0f;        \
        (out)[4 * (slot) + 2] = -1.0f;       \
        (out)[4 * (slot) + 3] = 1.0f;        \
    } while (0)

// Writes the screen point (sx, sy) (pixels from the centre) with clip z, w.
#define WRITE_SCREEN(out, slot, sx, sy, z, w, hvw, hvh) \
    do {                                                \
        (out)[4 * (slot) + 0] = (sx) / (hvw) * (w);      \
        (out)[4 * (slot) + 1] = (sy) / (hvh) * (w);      \
        (out)[4 * (slot) + 2] = (z);                     \
        (out)[4 * (slot) + 3] = (w);                     \
    } while (0)

// Clip-space coordinate `row` of M·(x, y, z, h), M = P->view_proj (column-major).
#define CLIP(P, row, x, y, z, h)                                                        \
    ((P)->view_proj[(row)] * (x) + (P)->view_proj[4 + (row)] * (y) +                    \
     (P)->view_proj[8 + (row)] * (z) + (P)->view_proj[12 + (row)] * (h))

// Depth factor max(1, k/w), or 1 when k = 0 (a select, not fmax: PoCL's
// work-item vectoriser gives up on fmax).
inline float depth_factor(float k, float w) {
    const float f = k / w;
    return (k > 0.0f && f > 1.0f) ? f : 1.0f;
}

__kernel void edges_detect(uint n, __global const EdgeParams* P, __global const float* pos,
                           __global const float* nrm, __global const uint* edges,
                           __global float* edge_out, __global uint* kind) {
    GID_OR_RETURN(n)
    const uint i0 = edges[4 * gid], i1 = edges[4 * gid + 1];
    const uint i2 = edges[4 * gid + 2], i3 = edges[4 * gid + 3];
    const float x0 = pos[3 * i0], y0 = pos[3 * i0 + 1], z0 = pos[3 * i0 + 2];
    const float x1 = pos[3 * i1], y1 = pos[3 * i1 + 1], z1 = pos[3 * i1 + 2];
    const float x2 = pos[3 * i2], y2 = pos[3 * i2 + 1], z2 = pos[3 * i2 + 2];
    const float x3 = pos[3 * i3], y3 = pos[3 * i3 + 1], z3 = pos[3 * i3 + 2];
    // Face a = (i0, i1, i2); face b traverses the edge the other way: (i1, i0, i3).
    const float ux = x1 - x0, uy = y1 - y0, uz = z1 - z0;
    const float vx = x2 - x0, vy = y2 - y0, vz = z2 - z0;
    const float nax = uy * vz - uz * vy, nay = uz * vx - ux * vz, naz = ux * vy - uy * vx;
    const float wx = x3 - x1, wy = y3 - y1, wz = z3 - z1;
    const float nbx = wy * uz - wz * uy, nby = wz * ux - wx * uz, nbz = wx * uy - wy * ux;
    uint k = 0u;
    if (i3 == i0) {
        if (P->boundaries != 0.0f) k |= KIND_BOUNDARY;
    } else {
        // View vector towards the eye, per edge (perspective) or constant (orthographic).
        const int ortho = P->ortho != 0.0f;
        const float ex = ortho ? -P->view_dir[0] : P->eye[0] - x0;
        const float ey = ortho ? -P->view_dir[1] : P->eye[1] - y0;
        const float ez = ortho ? -P->view_dir[2] : P->eye[2] - z0;
        const float da = nax * ex + nay * ey + naz * ez;
        const float db = nbx * ex + nby * ey + nbz * ez;
        if (P->contours != 0.0f && ((da < 0.0f && db > 0.0f) || (da > 0.0f && db < 0.0f)))
            k |= KIND_CONTOUR;
        const float dn = nax * nbx + nay * nby + naz * nbz;
        const float la = nax * nax + nay * nay + naz * naz;
        const float lb = nbx * nbx + nby * nby + nbz * nbz;
        if (dn < P->cos_crease * sqrt(la * lb)) k |= KIND_CREASE;
    }
    const float c0x = CLIP(P, 0, x0, y0, z0, 1.0f), c0y = CLIP(P, 1, x0, y0, z0, 1.0f);
    const float c0z = CLIP(P, 2, x0, y0, z0, 1.0f), c0w = CLIP(P, 3, x0, y0, z0, 1.0f);
    const float c1x = CLIP(P, 0, x1, y1, z1, 1.0f), c1y = CLIP(P, 1, x1, y1, z1, 1.0f);
    const float c1z = CLIP(P, 2, x1, y1, z1, 1.0f), c1w = CLIP(P, 3, x1, y1, z1, 1.0f);
    const float wmin = P->w_min;
    const int drawn = k != 0u && c0w > wmin && c1w > wmin;
    __global float* out = edge_out + 16 * gid;
    if (!drawn) {
        // The marker is already there unless the previous run drew this edge:
        // skipping the rewrite saves most of the output traffic (edge-out and
        // kind start as markers and 0, see EdgeStage::new).
        const uint prev = kind[gid];
        kind[gid] = k;
        if ((prev & KIND_DRAWN) != 0u) {
            WRITE_MARKER(out, 0);
            WRITE_MARKER(out, 1);
            WRITE_MARKER(out, 2);
            WRITE_MARKER(out, 3);
        }
        return;
    }
    kind[gid] = k | KIND_DRAWN;
    const float hvw = P->half_vw, hvh = P->half_vh, hw = P->half_width;
    const float s0x = c0x / c0w * hvw, s0y = c0y / c0w * hvh;
    const float s1x = c1x / c1w * hvw, s1y = c1y / c1w * hvh;
    const float dx = s1x - s0x, dy = s1y - s0y;
    const float len = sqrt(dx * dx + dy * dy);
    // An edge seen end-on has no direction: any perpendicular gives a zero-area quad.
    const float px = len > 0.0f ? -dy / len : 0.0f;
    const float py = len > 0.0f ? dx / len : 1.0f;
    const float f0 = hw * depth_factor(P->depth_k, c0w);
    const float f1 = hw * depth_factor(P->depth_k, c1w);
    // Half quads (contour-only edges, when asked): from the edge outward by the full
    // width, outward = the side the projected vertex normal of i0 points to (House & Li's
    // sign(m0·p)). Slots stay in perimeter order: 0 = s0, 1 = s1, 2, 3 outside.
    const int halfq = P->half_contours != 0.0f && k == KIND_CONTOUR;
    const uint j0 = halfq ? i0 : 0u;
    const float n0x = nrm[3 * j0], n0y = nrm[3 * j0 + 1], n0z = nrm[3 * j0 + 2];
    const float d0x = CLIP(P, 0, n0x, n0y, n0z, 0.0f), d0y = CLIP(P, 1, n0x, n0y, n0z, 0.0f);
    const float d0w = CLIP(P, 3, n0x, n0y, n0z, 0.0f);
    const float m0x = (d0x * c0w - c0x * d0w) * hvw, m0y = (d0y * c0w - c0y * d0w) * hvh;
    const float g = (m0x * px + m0y * py) >= 0.0f ? 1.0f : -1.0f;
    const float lo = halfq ? 0.0f : 1.0f, hi = halfq ? 2.0f * g : 1.0f;
    WRITE_SCREEN(out, 0, s0x - px * f0 * lo, s0y - py * f0 * lo, c0z, c0w, hvw, hvh);
    WRITE_SCREEN(out, 1, s1x - px * f1 * lo, s1y - py * f1 * lo, c1z, c1w, hvw, hvh);
    WRITE_SCREEN(out, 2, s1x + px * f1 * hi, s1y + py * f1 * hi, c1z, c1w, hvw, hvh);
    WRITE_SCREEN(out, 3, s0x + px * f0 * hi, s0y + py * f0 * hi, c0z, c0w, hvw, hvh);
}

__kernel void caps_mh(uint n, __global const EdgeParams* P, __global const float* pos,
                      __global const float* nrm, __global const uint* edges,
                      __global const uint* kind, __global float* cap0, __global float* cap1) {
    GID_OR_RETURN(n)
    __global float* o0 = cap0 + 12 * gid;
    __global float* o1 = cap1 + 12 * gid;
    // KIND_DRAWN is set exactly when edge-out holds a quad, not the marker.
    if ((kind[gid] & KIND_DRAWN) == 0u) {
        WRITE_MARKER(o0, 0);
        WRITE_MARKER(o0, 1);
        WRITE_MARKER(o0, 2);
        WRITE_MARKER(o1, 0);
        WRITE_MARKER(o1, 1);
        WRITE_MARKER(o1, 2);
        return;
    }
    const uint i0 = edges[4 * gid], i1 = edges[4 * gid + 1];
    const float x0 = pos[3 * i0], y0 = pos[3 * i0 + 1], z0 = pos[3 * i0 + 2];
    const float x1 = pos[3 * i1], y1 = pos[3 * i1 + 1], z1 = pos[3 * i1 + 2];
    const float c0x = CLIP(P, 0, x0, y0, z0, 1.0f), c0y = CLIP(P, 1, x0, y0, z0, 1.0f);
    const float c0z = CLIP(P, 2, x0, y0, z0, 1.0f), c0w = CLIP(P, 3, x0, y0, z0, 1.0f);
    const float c1x = CLIP(P, 0, x1, y1, z1, 1.0f), c1y = CLIP(P, 1, x1, y1, z1, 1.0f);
    const float c1z = CLIP(P, 2, x1, y1, z1, 1.0f), c1w = CLIP(P, 3, x1, y1, z1, 1.0f);
    const float hvw = P->half_vw, hvh = P->half_vh, hw = P->half_width;
    const float s0x = c0x / c0w * hvw, s0y = c0y / c0w * hvh;
    const float s1x = c1x / c1w * hvw, s1y = c1y / c1w * hvh;
    const float dx = s1x - s0x, dy = s1y - s0y;
    const float len = sqrt(dx * dx + dy * dy);
    const float px = len > 0.0f ? -dy / len : 0.0f;
    const float py = len > 0.0f ? dx / len : 1.0f;
    const float f0 = hw * depth_factor(P->depth_k, c0w);
    const float f1 = hw * depth_factor(P->depth_k, c1w);
    // Screen direction of the vertex normal: d/dt of the projection of p + t·n at t = 0.
    const float n0x = nrm[3 * i0], n0y = nrm[3 * i0 + 1], n0z = nrm[3 * i0 + 2];
    const float n1x = nrm[3 * i1], n1y = nrm[3 * i1 + 1], n1z = nrm[3 * i1 + 2];
    const float d0x = CLIP(P, 0, n0x, n0y, n0z, 0.0f), d0y = CLIP(P, 1, n0x, n0y, n0z, 0.0f);
    const float d0w = CLIP(P, 3, n0x, n0y, n0z, 0.0f);
    const float d1x = CLIP(P, 0, n1x, n1y, n1z, 0.0f), d1y = CLIP(P, 1, n1x, n1y, n1z, 0.0f);
    const float d1w = CLIP(P, 3, n1x, n1y, n1z, 0.0f);
    float m0x = (d0x * c0w - c0x * d0w) * hvw, m0y = (d0y * c0w - c0y * d0w) * hvh;
    float m1x = (d1x * c1w - c1x * d1w) * hvw, m1y = (d1y * c1w - c1y * d1w) * hvh;
    const float l0 = sqrt(m0x * m0x + m0y * m0y), l1 = sqrt(m1x * m1x + m1y * m1y);
    // A normal along the view ray projects to (almost) nothing, and its direction is
    // then rounding noise: below 1e-4 of the size a unit normal can project to
    // (matrix rows x, y, w times |c| times the viewport), use the perpendicular.
    const float msz = fabs(P->view_proj[0]) + fabs(P->view_proj[4]) + fabs(P->view_proj[8]) + fabs(P->view_proj[1]) + fabs(P->view_proj[5]) +
                      fabs(P->view_proj[9]) + fabs(P->view_proj[3]) + fabs(P->view_proj[7]) + fabs(P->view_proj[11]);
    const float hvm = hvw > hvh ? hvw : hvh;
    const float t0 = 1e-4f * msz * (fabs(c0x) + fabs(c0y) + fabs(c0w)) * hvm;
    const float t1 = 1e-4f * msz * (fabs(c1x) + fabs(c1y) + fabs(c1w)) * hvm;
    const int ok0 = l0 > t0 && l0 > 0.0f, ok1 = l1 > t1 && l1 > 0.0f;
    m0x = ok0 ? m0x / l0 : px;
    m0y = ok0 ? m0y / l0 : py;
    m1x = ok1 ? m1x / l1 : px;
    m1y = ok1 ? m1y / l1 : py;
    const float g0 = (m0x * px + m0y * py) >= 0.0f ? 1.0f : -1.0f;
    const float g1 = (m1x * px + m1y * py) >= 0.0f ? 1.0f : -1.0f;
    WRITE_SCREEN(o0, 0, s0x, s0y, c0z, c0w, hvw, hvh);
    WRITE_SCREEN(o0, 1, s0x + px * g0 * f0, s0y + py * g0 * f0, c0z, c0w, hvw, hvh);
    WRITE_SCREEN(o0, 2, s0x + m0x * f0, s0y + m0y * f0, c0z, c0w, hvw, hvh);
    WRITE_SCREEN(o1, 0, s1x, s1y, c1z, c1w, hvw, hvh);
    WRITE_SCREEN(o1, 1, s1x + px * g1 * f1, s1y + py * g1 * f1, c1z, c1w, hvw, hvh);
    WRITE_SCREEN(o1, 2, s1x + m1x * f1, s1y + m1y * f1, c1z, c1w, hvw, hvh);
}

// House & Li's adjacency cap of pair gid: 1 when the pair draws one (both
// edges drawn, not collinear), and then, when o is not null, its quad
// (sM + mv, sM + p0, sM, sM + p1) written to o; 0 otherwise.
inline int cap_quad(uint gid, __global const EdgeParams* P, __global const uint* edges,
                    __global const uint* caps, __global const uint* kind,
                    __global const float* edge_out, __global float* o) {
    const uint e0 = caps[2 * gid], e1 = caps[2 * gid + 1];
    // Most pairs have an undrawn edge: decide from the kind bits (4 bytes per
    // edge, cache-resident, where edge-out's first x costs a cache line per
    // edge) before any other read.
    if (((kind[e0] & kind[e1]) & KIND_DRAWN) == 0u) return 0;
    __global const float* q0 = edge_out + 16 * e0;
    __global const float* q1 = edge_out + 16 * e1;
    const float hvw = P->half_vw, hvh = P->half_vh;
    int ok = 1;
    const uint a0 = edges[4 * e0], b0 = edges[4 * e1], b1 = edges[4 * e1 + 1];
    const uint v = (a0 == b0 || a0 == b1) ? a0 : edges[4 * e0 + 1];
    // Quad slots at end 0 are 0 and 3, at end 1 are 1 and 2. First edge: its end at
    // v is the joint sM, its other end sL; second edge: its far end is sR.
    const uint ma = v == a0 ? 0u : 1u, fa = 3u - ma; // the slots 0/3 or 1/2
    const uint la = 1u - ma, lfa = 3u - la;
    const uint rb = v == b0 ? 1u : 0u, rfb = 3u - rb;
    // Joint: midpoint of the two quad vertices at v (clip space; same z, w).
    const float mAx = q0[4 * ma], mAy = q0[4 * ma + 1], mBx = q0[4 * fa], mBy = q0[4 * fa + 1];
    const float mz = q0[4 * ma + 2], mw = q0[4 * ma + 3];
    const float smx = 0.5f * (mAx + mBx) / mw * hvw, smy = 0.5f * (mAy + mBy) / mw * hvh;
    // Half width at the joint: half the screen distance between those two vertices.
    const float hx = 0.5f * (mBx - mAx) / mw * hvw, hy = 0.5f * (mBy - mAy) / mw * hvh;
    const float hw = sqrt(hx * hx + hy * hy);
    const float lw = q0[4 * la + 3];
    const float slx = 0.5f * (q0[4 * la] + q0[4 * lfa]) / lw * hvw;
    const float sly = 0.5f * (q0[4 * la + 1] + q0[4 * lfa + 1]) / lw * hvh;
    const float rw = q1[4 * rb + 3];
    const float srx = 0.5f * (q1[4 * rb] + q1[4 * rfb]) / rw * hvw;
    const float sry = 0.5f * (q1[4 * rb + 1] + q1[4 * rfb + 1]) / rw * hvh;
    const float dlx = slx - smx, dly = sly - smy, drx = srx - smx, dry = sry - smy;
    const float ll = sqrt(dlx * dlx + dly * dly), lr = sqrt(drx * drx + dry * dry);
    ok = ok && ll > 1e-6f && lr > 1e-6f;
    const float ulx = ok ? dlx / ll : 0.0f, uly = ok ? dly / ll : 0.0f;
    const float urx = ok ? drx / lr : 0.0f, ury = ok ? dry / lr : 0.0f;
    const float sx = ulx + urx, sy = uly + ury;
    const float ls = sqrt(sx * sx + sy * sy);
    // Collinear edges (straight continuation) leave no gap: no cap.
    ok = ok && ls > 1e-4f;
    if (!ok || o == 0) return ok;
    const float mvx = -sx / ls, mvy = -sy / ls;
    float p0x = -uly, p0y = ulx;
    const float g0 = (p0x * mvx + p0y * mvy) >= 0.0f ? 1.0f : -1.0f;
    float p1x = -ury, p1y = urx;
    const float g1 = (p1x * mvx + p1y * mvy) >= 0.0f ? 1.0f : -1.0f;
    p0x *= g0;
    p0y *= g0;
    p1x *= g1;
    p1y *= g1;
    WRITE_SCREEN(o, 0, smx + mvx * hw, smy + mvy * hw, mz, mw, hvw, hvh);
    WRITE_SCREEN(o, 1, smx + p0x * hw, smy + p0y * hw, mz, mw, hvw, hvh);
    WRITE_SCREEN(o, 2, smx, smy, mz, mw, hvw, hvh);
    WRITE_SCREEN(o, 3, smx + p1x * hw, smy + p1y * hw, mz, mw, hvw, hvh);
    return 1;
}

// Which cap pairs draw a cap (1/0 into flags); the host scans the flags in
// place (scan.cl) into each drawn cap's slot.
__kernel void caps_adjacency_flags(uint n, __global const EdgeParams* P,
                                   __global const uint* edges, __global const uint* caps,
                                   __global const uint* kind, __global const float* edge_out,
                                   __global uint* flags) {
    GID_OR_RETURN(n)
    flags[gid] = (uint)cap_quad(gid, P, edges, caps, kind, edge_out, (__global float*)0);
}

// The drawn caps' quads, each at its slot: cap-out holds only drawn caps, in
// pair order (`total` of them; a pair draws one where the next slot is
// larger).
__kernel void caps_adjacency(uint n, __global const EdgeParams* P, __global const uint* edges,
                             __global const uint* caps, __global const uint* kind,
                             __global const float* edge_out, __global const uint* slot,
                             uint total, __global float* cap_out) {
    GID_OR_RETURN(n)
    const uint s = slot[gid];
    const uint next = gid + 1u < n ? slot[gid + 1u] : total;
    if (next == s) return;
    cap_quad(gid, P, edges, caps, kind, edge_out, cap_out + 16 * s);
}

// Read-back of what was drawn, compacted on the device (EdgeStage::read_drawn;
// CPU twin: cpu::edges::compact_drawn). drawn_flags writes 1 per edge entry
// the last run drew (kind bit 3) and 0 elsewhere; the host scans the flags in
// place (scan.cl), so that slot[i] is edge i's place among the drawn ones, and
// compact_edges copies each drawn edge's `per` vertices there: index order is
// kept, and only drawn geometry crosses to the host. (Adjacency caps are
// written compacted by caps_adjacency already.)
__kernel void drawn_flags(uint ne, __global const uint* kind, __global uint* flags) {
    GID_OR_RETURN(ne)
    flags[gid] = (kind[gid] & KIND_DRAWN) != 0u ? 1u : 0u;
}

// Edge entries' primitives (edge-out quads, per = 4; McGuire-Hughes half-caps,
// per = 3) into dst from vertex `at` on.
__kernel void compact_edges(uint n, uint per, __global const float4* src,
                            __global const uint* kind, __global const uint* slot,
                            uint at, __global float4* dst) {
    GID_OR_RETURN(n)
    if ((kind[gid] & KIND_DRAWN) == 0u) return;
    __global const float4* s = src + per * gid;
    __global float4* d = dst + at + per * slot[gid];
    for (uint k = 0; k < per; k++) d[k] = s[k];
}
