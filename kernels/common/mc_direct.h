// mc_direct.h: direct numbering's cell helpers (marching_cubes_direct.cl):
// the kinds of an edge's vertex (inside the edge, or rounding onto a grid
// point), a grid row's offsets, a chunk of 16 cells' cases and edge kinds in
// lanes, the owned edges of a row position, the twin test of triangles
// lying in a cube face, the twelve edges' kinds and coordinates of the
// triangle pass, and the steps of the cells with a corner on a hit point
// (the hit points a grid row's owned edges round onto, in lanes or one
// position at a time; the sorted hit points, their cursor over a cell row,
// collapses), and the dropped triangles per cell row of the check for
// unused vertices. Uses
// mc_edge.h (the edge rule) and mc_cell.h (cell cases, edge numbering). CPU
// twin: src/cpu/marching_cubes.rs (edge_vertex, has_twin).

#define EV_NONE 0u
#define EV_IN 1u // CELL_KINDS relies on it being 1
#define EV_LO 2u
#define EV_HI 3u

// What the edge from value v0 (coordinate a along its axis) to v1 (a + 1)
// carries: EV_NONE (one side, or an end not finite), EV_IN (a vertex inside
// the edge, at coordinate *c), EV_LO / EV_HI (the vertex rounds onto the
// lower / upper grid point). Twin: cpu::marching_cubes::edge_vertex.
inline uint edge_kind(float v0, float v1, float iso, uint a, float *c)
{
    if (!(isfinite(v0) && isfinite(v1)) || ((v0 < iso) == (v1 < iso)))
        return EV_NONE;
    const float fa = (float)a;
    const float cc = fa + mc_edge_t(v0, v1, iso);
    *c = cc;
    return cc == fa ? EV_LO : (cc == (float)(a + 1) ? EV_HI : EV_IN);
}

// A row's chunk mask (trim[3r + 2]): chunk c of the row (cells 16c ..
// 16c + 15, the last one ending at the row's end) is bit c >> chunk_shift(nx),
// so that a row of more than 32 chunks shares a bit among 2, 4, ... of them;
// a bit is set when one of its chunks is not finite and uniform.
inline uint chunk_shift(uint nx)
{
    const uint last = nx >= 2 ? (nx - 2) >> 4 : 0;
    uint s = 0;
    while ((last >> s) >= 32)
        ++s;
    return s;
}

// Grid row gid; rows past the volume's last y or z alias row 00, so their
// "edges" join a value to itself and never cross.
#define GRID_ROW_SETUP                                                              \
    const uint y = gid % ny, z = gid / ny;                                          \
    const uint hy = y + 1 < ny, hz = z + 1 < nz;                                    \
    const ulong b00 = (ulong)nx * (y + (ulong)ny * z);                              \
    const ulong b10 = b00 + (hy ? nx : 0), b01 = b00 + (hz ? (ulong)nx * ny : 0);   \
    const ulong b11 = b10 + (b01 - b00);

// True when values x .. nx−1 of the four rows are finite and on one side.
inline bool tail_uniform(__global const float *vol, ulong b00, ulong b10, ulong b01, ulong b11,
                         uint x, uint nx, float iso)
{
    bool in = true, out = true;
    for (uint i = x; i < nx; ++i) {
        const float a = vol[b00 + i], b = vol[b10 + i], c = vol[b01 + i], d = vol[b11 + i];
        if (!(isfinite(a) && isfinite(b) && isfinite(c) && isfinite(d)))
            return false;
        in = in && a < iso && b < iso && c < iso && d < iso;
        out = out && a >= iso && b >= iso && c >= iso && d >= iso;
    }
    return in || out;
}

// The owned edges at position i of the row: their interior vertices along
// x, y, z in bits 0, 8, 16 and their hits in bits 24.. (scalars, so the
// counters stay in registers).
inline uint count_owned(__global const float *vol, ulong b00, ulong b10, ulong b01, uint i,
                        uint nx, uint y, uint z, float iso)
{
    float c;
    const float a = vol[b00 + i];
    const uint kx = i + 1 < nx ? edge_kind(a, vol[b00 + i + 1], iso, i, &c) : EV_NONE;
    const uint ky = edge_kind(a, vol[b10 + i], iso, y, &c);
    const uint kz = edge_kind(a, vol[b01 + i], iso, z, &c);
    return (uint)(kx == EV_IN) | ((uint)(ky == EV_IN) << 8) | ((uint)(kz == EV_IN) << 16) |
           (((uint)(kx >= EV_LO) + (uint)(ky >= EV_LO) + (uint)(kz >= EV_LO)) << 24);
}

// Cases of the 16 cells x .. x+15 of a cell row (bit c set when corner c is
// inside), from float16 loads of the values x .. x+16 of the four rows; the
// corner values come back in a[8] (corner c's value of each lane). *finite
// is false when one of them is not finite (then the cases are not used).
inline uint16 chunk_cases(__global const float *vol, ulong b00, ulong b10, ulong b01, ulong b11,
                          uint x, float iso, float16 *a, bool *finite)
{
    ROW_PREFETCH(vol + b00 + x);
    ROW_PREFETCH(vol + b10 + x);
    ROW_PREFETCH(vol + b01 + x);
    ROW_PREFETCH(vol + b11 + x);
    a[0] = vload16(0, vol + b00 + x);
    a[1] = vload16(0, vol + b00 + x + 1);
    a[2] = vload16(0, vol + b10 + x);
    a[3] = vload16(0, vol + b10 + x + 1);
    a[4] = vload16(0, vol + b01 + x);
    a[5] = vload16(0, vol + b01 + x + 1);
    a[6] = vload16(0, vol + b11 + x);
    a[7] = vload16(0, vol + b11 + x + 1);
    const float16 i16 = (float16)(iso);
    int16 fin = isfinite(a[0]);
    uint16 cas = (uint16)(0);
    for (uint c = 0; c < 8; ++c) {
        fin &= isfinite(a[c]);
        cas |= as_uint16(isless(a[c], i16)) & (uint16)(1u << c);
    }
    *finite = all16(fin);
    return cas;
}

// Bit i set when lane i of a relational built-in's mask is (−1 = true):
// disjoint bits summed in four halving steps.
inline uint lanes_bits(int16 m)
{
    const uint16 p = as_uint16(m) & (uint16)(1u << 0, 1u << 1, 1u << 2, 1u << 3, 1u << 4, 1u << 5,
                                          1u << 6, 1u << 7, 1u << 8, 1u << 9, 1u << 10,
                                          1u << 11, 1u << 12, 1u << 13, 1u << 14, 1u << 15);
    const uint8 s8 = p.lo | p.hi;
    const uint4 s4 = s8.lo | s8.hi;
    const uint2 s2 = s4.lo | s4.hi;
    return s2.x | s2.y;
}

// The owned edges of 16 positions at once, as count_owned packs them
// (interior vertices along x, y, z in bits 0, 8, 16, hits in bits 24..),
// from the masks of edge_kinds16 (hx, hy, hz: hits; ix, iy, iz: inside),
// lanes outside `mine` left out: one horizontal sum for all six counts
// (at most 16, and 48 hits, per field: no carries).
inline uint owned16(int16 hx, int16 hy, int16 hz, int16 ix, int16 iy, int16 iz, int16 mine)
{
    const uint16 one = (uint16)(1);
    const uint16 p = ((as_uint16(ix) & one) | ((as_uint16(iy) & one) << 8) |
                      ((as_uint16(iz) & one) << 16) |
                      (((as_uint16(hx) & one) + (as_uint16(hy) & one) + (as_uint16(hz) & one))
                       << 24)) &
                     as_uint16(mine);
    const uint8 s8 = p.lo + p.hi;
    const uint4 s4 = s8.lo + s8.hi;
    const uint2 s2 = s4.lo + s4.hi;
    return s2.x + s2.y;
}

// The vertex coordinate fa + t of 16 edges at once, all ends finite, as
// edge_kind computes it; *cross the lanes whose ends are on either side.
inline float16 edge_c16(float16 v0, float16 v1, float iso, float16 fa, int16 *cross)
{
    const float16 i16 = (float16)(iso);
    *cross = isless(v0, i16) ^ isless(v1, i16);
    float16 n = i16 - v0, d = v1 - v0;
#ifdef SC_MC_HALVE
    // mc_edge_t's halved differences where one overflows, built only for
    // volumes with values from 2^126 on (spec::marching_cubes::HALVE_FROM;
    // below it no difference overflows, and the test would cost the count
    // pass 7 %). On a crossing edge iso lies between the ends, so |n| <= |d|:
    // testing d is enough for the lanes the caller keeps.
    const int16 big = isinf(d);
    if (any16(big)) {
        n = select(n, i16 * 0.5f - v0 * 0.5f, big);
        d = select(d, v1 * 0.5f - v0 * 0.5f, big);
    }
#endif
    float16 t = n / d;
    t = select((float16)(0.0f), t, isgreaterequal(t, (float16)(0.0f)));
    t = select(t, (float16)(1.0f), isgreater(t, (float16)(1.0f)));
    return fa + t;
}

// edge_kind for 16 edges at once, all ends finite: *inside gets the lanes
// with a vertex inside the edge, the return value the lanes that round onto
// an end. fa is the edges' lower coordinate along their axis.
inline int16 edge_kinds16(float16 v0, float16 v1, float iso, float16 fa, int16 *inside)
{
    int16 cross;
    const float16 c = edge_c16(v0, v1, iso, fa, &cross);
    const int16 hit = cross & ((c == fa) | (c == fa + 1.0f));
    *inside = cross & ~hit;
    return hit;
}

// The hits of 16 edges at once, all ends finite (as edge_kinds16), as lane
// bits: the return value the lanes whose vertex rounds onto the lower end,
// *up those that round onto the upper end.
inline uint hit_ends16(float16 v0, float16 v1, float iso, float16 fa, uint *up)
{
    int16 cross;
    const float16 c = edge_c16(v0, v1, iso, fa, &cross);
    *up = lanes_bits(cross & (c == fa + 1.0f));
    return lanes_bits(cross & (c == fa));
}

// True when triangle j of cell (x, y, z) of case cas, flagged as lying in a
// face of the cube (flat[cas] bit j), has an opposite twin in the cell across
// that face: the same three voxel edges, the other winding. Both cells drop
// theirs, as vertex fusion's twin cancellation would. Rare (a fan over a loop
// through all four edges of an ambiguous face), so it may be slow. Twin:
// cpu::marching_cubes::has_twin.
__attribute__((noinline)) bool has_twin(__global const float *vol, uint x, uint y, uint z, uint nx, uint ny,
                     uint nz, float iso, uint cas, uint j, __constant uchar *counts,
                     __constant uchar *tris)
{
    const uint a0 = tris[16 * cas + 3 * j], a1 = tris[16 * cas + 3 * j + 1],
               a2 = tris[16 * cas + 3 * j + 2];
    const uint l0 = edge_lo_corner(a0), l1 = edge_lo_corner(a1), l2 = edge_lo_corner(a2);
    uint f = 3;
    for (uint q = 0; q < 3 && f == 3; ++q) {
        if ((a0 >> 2) != q && (a1 >> 2) != q && (a2 >> 2) != q &&
            ((l0 >> q) & 1) == ((l1 >> q) & 1) && ((l1 >> q) & 1) == ((l2 >> q) & 1))
            f = q;
    }
    if (f == 3)
        return false;
    const uint s = (l0 >> f) & 1;
    uint p[3] = {x, y, z};
    const uint dim[3] = {nx, ny, nz};
    if (s == 0) {
        if (p[f] == 0)
            return false;
        p[f] -= 1;
    } else {
        if (p[f] + 2 >= dim[f])
            return false;
        p[f] += 1;
    }
    const ulong b00 = (ulong)nx * (p[1] + (ulong)ny * p[2]);
    const ulong b10 = b00 + nx, b01 = b00 + (ulong)nx * ny, b11 = b01 + nx;
    float v[8];
    const uint cb = cell_case(vol, b00, b10, b01, b11, p[0], iso, v);
    if (cb >= 256)
        return false;
    for (uint t = 0; t < counts[cb]; ++t) {
        uint m[3];
        bool ok = true;
        for (uint i = 0; i < 3; ++i) {
            const uint e = tris[16 * cb + 3 * t + i], axis = e >> 2, c0 = edge_lo_corner(e);
            ok = ok && axis != f && ((c0 >> f) & 1) == 1 - s;
            m[i] = edge_id(axis, c0 ^ (1u << f));
        }
        // The other winding: a rotation of (a0, a2, a1).
        if (ok && ((m[0] == a0 && m[1] == a2 && m[2] == a1) ||
                   (m[0] == a2 && m[1] == a1 && m[2] == a0) ||
                   (m[0] == a1 && m[1] == a0 && m[2] == a2)))
            return true;
    }
    return false;
}

// Triangles of cell (x, y, z), case cas < 256, dropped as twins.
inline uint twins_of(__global const float *vol, uint x, uint y, uint z, uint nx, uint ny,
                     uint nz, float iso, uint cas, __constant uchar *counts,
                     __constant uchar *tris, __constant uchar *flat)
{
    uint n = 0;
    const uint fl = flat[cas];
    if (fl != 0) {
        for (uint j = 0; j < counts[cas]; ++j)
            n += ((fl >> j) & 1) && has_twin(vol, x, y, z, nx, ny, nz, iso, cas, j, counts, tris);
    }
    return n;
}

// ---- hit points: the vertices that land on a grid point ----

// The first of the nh sorted keys that is not below g.
inline uint lower_bound_keys(__global const uint *keys, uint nh, ulong g)
{
    uint lo = 0, hi = nh;
    while (lo < hi) {
        const uint m = lo + (hi - lo) / 2;
        if ((ulong)keys[m] < g)
            lo = m + 1;
        else
            hi = m;
    }
    return lo;
}

// The hit points that grid row (y, z)'s owned edges at position i round
// onto (mc_direct_hits), appended to keys from *o.
inline void hit_owned(__global const float *vol, ulong b00, ulong b10, ulong b01, uint i,
                      uint nx, uint ny, uint y, uint z, float iso, __global uint *keys, uint *o)
{
    float c;
    const float a = vol[b00 + i];
    const uint g = grid_index(i, y, z, nx, ny);
    uint k;
    if (i + 1 < nx) {
        k = edge_kind(a, vol[b00 + i + 1], iso, i, &c);
        if (k >= EV_LO)
            keys[(*o)++] = k == EV_LO ? g : g + 1;
    }
    k = edge_kind(a, vol[b10 + i], iso, y, &c);
    if (k >= EV_LO)
        keys[(*o)++] = k == EV_LO ? g : g + nx;
    k = edge_kind(a, vol[b01 + i], iso, z, &c);
    if (k >= EV_LO)
        keys[(*o)++] = k == EV_LO ? g : g + nx * ny;
}

// Appends g + i for each lane bit i of `bits`.
inline void put_hits(uint bits, uint g, __global uint *keys, uint *o)
{
    for (uint i = 0; bits != 0; ++i, bits >>= 1)
        if (bits & 1)
            keys[(*o)++] = g + i;
}

// The hit points on the four grid rows of a cell row, walked in x order: a
// cell has an edge whose vertex lands on a grid point only when one of its
// corners is a hit point, so only those cells need the hit-aware steps (the
// others are hit-free even in a row with hits). p[i] .. e[i] are the keys of
// grid row i, whose first grid index is g[i].
typedef struct {
    uint p[4], e[4];
    ulong g[4];
} HitCursor;

// The first key at or after p that is not below g (a short walk: a grid
// row holds few hit points, and at worst nx).
inline uint keys_from(__global const uint *keys, uint nh, uint p, ulong g)
{
    while (p < nh && (ulong)keys[p] < g)
        ++p;
    return p;
}

// Rows r00 and r10 = r00 + 1 are neighbours in grid order, as are r01 and
// r11 = r01 + 1: one search each pair, then walks.
inline void hits_begin(HitCursor *h, __global const uint *keys, uint nh, uint nx, uint r00,
                       uint r01)
{
    for (uint i = 0; i < 4; i += 2) {
        const ulong g = (ulong)(i == 0 ? r00 : r01) * nx;
        h->g[i] = g;
        h->g[i + 1] = g + nx;
        h->p[i] = lower_bound_keys(keys, nh, g);
        h->e[i] = h->p[i + 1] = keys_from(keys, nh, h->p[i], g + nx);
        h->e[i + 1] = keys_from(keys, nh, h->p[i + 1], g + 2 * (ulong)nx);
    }
}

// The least x ≥ x0 of a hit point on the four rows (0xFFFFFFFF if none),
// the rows' hits below x0 passed for good.
inline uint hits_from(HitCursor *h, __global const uint *keys, uint x0)
{
    uint m = 0xFFFFFFFFu;
    for (uint i = 0; i < 4; ++i) {
        while (h->p[i] < h->e[i] && keys[h->p[i]] - h->g[i] < x0)
            ++h->p[i];
        if (h->p[i] < h->e[i])
            m = min(m, (uint)(keys[h->p[i]] - h->g[i]));
    }
    return m;
}

// Coordinate q of the vertex of edge e of cell (x, y, z), of kind k (not
// EV_NONE) and, for EV_IN, coordinate cc along the edge.
inline float corner_coord(uint e, uint k, float cc, uint x, uint y, uint z, uint q)
{
    const uint axis = e >> 2, c0 = edge_lo_corner(e);
    const uint g = (q == 0 ? x : (q == 1 ? y : z)) + ((c0 >> q) & 1);
    if (q != axis)
        return (float)g;
    return k == EV_IN ? cc : (float)(k == EV_HI ? g + 1 : g);
}

inline void put3(__global float *pos, uint v, float a, float b, float c)
{
    pos[3 * v] = a;
    pos[3 * v + 1] = b;
    pos[3 * v + 2] = c;
}

// The kinds k[12] and coordinates c[12] of the twelve edges of cell (x, y,
// z) in table order (common/mc_cell.h's edge numbering), from its values v[8].
#define CELL_EDGES                                                                  \
    k[0] = edge_kind(v[0], v[1], iso, x, &c[0]);                                    \
    k[1] = edge_kind(v[2], v[3], iso, x, &c[1]);                                    \
    k[2] = edge_kind(v[4], v[5], iso, x, &c[2]);                                    \
    k[3] = edge_kind(v[6], v[7], iso, x, &c[3]);                                    \
    k[4] = edge_kind(v[0], v[2], iso, y, &c[4]);                                    \
    k[5] = edge_kind(v[1], v[3], iso, y, &c[5]);                                    \
    k[6] = edge_kind(v[4], v[6], iso, y, &c[6]);                                    \
    k[7] = edge_kind(v[5], v[7], iso, y, &c[7]);                                    \
    k[8] = edge_kind(v[0], v[4], iso, z, &c[8]);                                    \
    k[9] = edge_kind(v[1], v[5], iso, z, &c[9]);                                    \
    k[10] = edge_kind(v[2], v[6], iso, z, &c[10]);                                  \
    k[11] = edge_kind(v[3], v[7], iso, z, &c[11]);

// CELL_EDGES where no edge of the cell can round onto a grid point (the
// hit-free rows of mc_direct_triangles): the kinds only, EV_IN where an edge
// crosses with finite ends, as edge_kind returns there (from the case's bits
// when all corners are finite); the coordinates of the few edges whose
// vertices are written come from EDGE_C.
#define CELL_KINDS                                                                  \
    {                                                                               \
        const uint ends[24] = {0, 1, 2, 3, 4, 5, 6, 7, 0, 2, 1, 3,                  \
                               4, 6, 5, 7, 0, 4, 1, 5, 2, 6, 3, 7};                 \
        if (cas < 256) {                                                            \
            for (uint e = 0; e < 12; ++e)                                           \
                k[e] = ((cas >> ends[2 * e]) ^ (cas >> ends[2 * e + 1])) & 1u;      \
        } else {                                                                    \
            for (uint e = 0; e < 12; ++e) {                                         \
                const float p = v[ends[2 * e]], q = v[ends[2 * e + 1]];             \
                k[e] = (isfinite(p) && isfinite(q) && ((p < iso) != (q < iso)))     \
                           ? EV_IN                                                  \
                           : EV_NONE;                                               \
            }                                                                       \
        }                                                                           \
    }

// Coordinate along its axis of the EV_IN vertex of edge e (between corners
// i0 and i1, lower coordinate f): c[e] from CELL_EDGES, or computed here from
// the corners' values, the same float arithmetic as edge_kind, where
// CELL_KINDS ran.
#define EDGE_C(e, i0, i1, f) (hc ? c[e] : (f) + mc_edge_t(CORNER(i0), CORNER(i1), iso))
// Value of corner i of cell x of the cell row (rows b00, b10, b01, b11).
#define CORNER(i) vol[((i) & 4 ? ((i) & 2 ? b11 : b01) : ((i) & 2 ? b10 : b00)) + x + ((i) & 1)]

// Grid index of the point that the vertex of edge e (kind EV_LO or EV_HI) of
// cell (x, y, z) rounds onto.
inline uint hit_point(uint e, uint kind, uint x, uint y, uint z, uint nx, uint ny)
{
    const uint c0 = edge_lo_corner(e);
    const uint cn = kind == EV_LO ? c0 : (c0 | (1u << (e >> 2)));
    return grid_index(x + (cn & 1), y + ((cn >> 1) & 1), z + (cn >> 2), nx, ny);
}

// The vertex of the hit on edge e (kind EV_LO or EV_HI) of cell x of the
// cursor's cell row: edge_vertices + the rank of that corner's grid point
// among the sorted, unique hit points, read off the cursor without a search.
// Each of the cursor's rows starts at its first hit point at or after x (as
// in mc_direct_triangles' hit cells), so the point of corner x is its row's
// first and that of corner x + 1 the first or the next.
inline uint hit_vertex_at(const HitCursor *h, __global const uint *keys, uint e, uint kind,
                          uint x, uint edge_vertices)
{
    const uint c0 = edge_lo_corner(e);
    const uint cn = kind == EV_LO ? c0 : (c0 | (1u << (e >> 2)));
    const uint i = ((cn >> 1) & 1) + 2 * (cn >> 2), p = h->p[i];
    const ulong g = h->g[i] + x + (cn & 1);
    return edge_vertices + ((ulong)keys[p] == g ? p : p + 1);
}

// True when two corners of the triangle on edges ea, eb, ec of cell (x, y, z)
// round onto the same grid point (the triangle collapses: dropped).
inline bool collapses(uint ea, uint eb, uint ec, const uint *k, uint x, uint y, uint z,
                      uint nx, uint ny)
{
    const uint ka = k[ea], kb = k[eb], kc = k[ec];
    const uint none = 0xFFFFFFFFu;
    const uint pa = ka >= EV_LO ? hit_point(ea, ka, x, y, z, nx, ny) : none;
    const uint pb = kb >= EV_LO ? hit_point(eb, kb, x, y, z, nx, ny) : none - 1;
    const uint pc = kc >= EV_LO ? hit_point(ec, kc, x, y, z, nx, ny) : none - 2;
    return pa == pb || pb == pc || pa == pc;
}

// True when one of the four grid rows of cell row gid (gid, gid + 1,
// gid + ny, gid + ny + 1) owns an edge whose vertex lands on a grid point:
// only those rows' edges are the row's cells' edges. From the hits' part of
// the scanned counts (off[2G + r] .. off[2G + r + 1]).
inline bool cell_row_has_hits(__global const uint *off, uint G, uint gid, uint ny)
{
    const uint rows[4] = {gid, gid + 1, gid + ny, gid + ny + 1};
    bool any_hit = false;
    for (uint i = 0; i < 4; ++i)
        any_hit = any_hit || off[2 * G + rows[i] + 1] != off[2 * G + rows[i]];
    return any_hit;
}

// Triangles dropped in cell row (y, z): the count pass's triangles and twins
// less those kept; 0 for a row that is not a cell row.
inline uint row_drops(__global const uint *off, __global const uint *toff, uint tshift, uint G,
                      uint ny, uint nz, int y, int z)
{
    if (y < 0 || z < 0 || y + 1 >= (int)ny || z + 1 >= (int)nz)
        return 0;
    const uint r = (uint)y + ny * (uint)z;
    return off[3 * G + r + 1] - off[3 * G + r] + (off[G + r + 1] - off[G + r]) -
           (toff[tshift + r + 1] - toff[tshift + r]);
}

// Grid row j (0 .. 3: 00, 10, 01, 11) of listed cell row i = w / 4, or
// 0xFFFFFFFF past the list.
inline uint listed_grid_row(__global const uint *list, uint cap, uint ny, uint w)
{
    if (w / 4 >= min(list[0], cap))
        return 0xFFFFFFFFu;
    const uint j = w % 4;
    return list[2 + w / 4] + (j & 1) + ny * (j >> 1);
}

// The marks of grid row g's vertices: its own edge vertices off[g] ..
// off[g + 1], then the hit points on it (after the V edge vertices).
#define GRID_ROW_MARKS(STEP)                                                        \
    for (uint i = off[g]; i < off[g + 1]; ++i)                                      \
        STEP(i);                                                                    \
    const uint v = off[grid_rows];                                                  \
    const ulong g0 = (ulong)g * nx;                                                 \
    for (uint k = lower_bound_keys(keys, nh, g0); k < nh && (ulong)keys[k] < g0 + nx; ++k) \
        STEP(v + k);
