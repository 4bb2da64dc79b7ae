// mc_direct.h: direct numbering's cell helpers (marching_cubes_direct.cl):
// the kinds of an edge's vertex (inside the edge, or rounding onto a grid
// point), a grid row's offsets, a chunk of 16 cells' cases and edge kinds in
// lanes, the owned edges of a row position, and the twin test of triangles
// lying in a cube face. Uses mc_edge.h (the edge rule) and mc_cell.h (cell
// cases, edge numbering). CPU twin: src/cpu/marching_cubes.rs (edge_vertex,
// has_twin).

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

// Lanes set in a mask of a relational built-in (−1 = true).
inline uint lanes_set(int16 m)
{
    const int8 s8 = m.lo + m.hi;
    const int4 s4 = s8.lo + s8.hi;
    const int2 s2 = s4.lo + s4.hi;
    return (uint)(-(s2.x + s2.y));
}

// edge_kind for 16 edges at once, all ends finite: *inside gets the lanes
// with a vertex inside the edge, the return value the lanes that round onto
// an end. fa is the edges' lower coordinate along their axis.
inline int16 edge_kinds16(float16 v0, float16 v1, float iso, float16 fa, int16 *inside)
{
    const float16 i16 = (float16)(iso);
    const int16 cross = isless(v0, i16) ^ isless(v1, i16);
    float16 t = (i16 - v0) / (v1 - v0);
    t = select((float16)(0.0f), t, isgreaterequal(t, (float16)(0.0f)));
    t = select(t, (float16)(1.0f), isgreater(t, (float16)(1.0f)));
    const float16 c = fa + t;
    const int16 hit = cross & ((c == fa) | (c == fa + 1.0f));
    *inside = cross & ~hit;
    return hit;
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
