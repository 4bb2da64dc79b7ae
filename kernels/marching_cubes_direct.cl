// marching_cubes_direct.cl: the isosurface value = iso by direct numbering
// (Fusion direct), after Flying Edges (Schroeder, Maynard and Geveci 2015):
// no soup, no sort. Each vertex is made once, by the voxel edge it lies on,
// and numbered by a scan over per-row counts; triangles are written with
// final indices. Twin file: marching_cubes.cl (the soup variants); shared
// cell code: common/mc_cell.h, with direct numbering's own edge kinds, lane
// helpers, twin test and hit-point steps in common/mc_direct.h. Host:
// src/stages/marching_cubes/direct.rs; CPU twin: cpu::marching_cubes::mc_direct
// (same steps, same f32 arithmetic).
//
// A grid row is every grid point with the same (y, z): G = ny·nz of them,
// row r = y + ny·z. Row r owns its x-edges and the y- and z-edges that start
// on it; its vertices are numbered x-edges first, then y, then z, each in x
// order, from off[r] on. Cell row (y, z) reads grid rows 00 = (y, z),
// 10 = (y+1, z), 01 = (y, z+1), 11 = (y+1, z+1).
//   mc_direct_rows       per grid row  where its x-edges cross (info)
//   mc_direct_count      per grid row  vertices, triangles, hits, twins; splits; trim
//   (scan.cl)                          one exclusive scan of rowc[0..4G)
//   mc_direct_hits       per grid row  only with hits: the hit points
//   mc_direct_recount    per cell row  only then: kept triangles
//   mc_direct_triangles  per cell row  positions, triangles with final indices
//   mc_direct_points     per hit       positions of the hit slots
// One work-item walks one row, 16 cells at a time (float16 loads), reading
// nothing outside the row's trim range but the 16-cell chunk that ends at the
// row's end, which stands in for a scalar tail (lanes already seen masked).
//
// Buffers: vol float[N]; counts, tris, flat: the case table (flat: the
// triangles lying in a cube face); info uint[4G]; rowc uint[4G] (scanned in
// place into off); split uint[2G]; trim uint[3G]; tcount uint[G]; hit_keys
// uint[H] (sorted, unique: U); pos float[3(V+U)]; faces uint[3T]; side
// uint[3·20H]; V, T, H the scan's first three partial totals.

// Per grid row, read once (Flying Edges' first pass): info[4r..] = the first
// cell whose x-edge crosses iso or touches a non-finite value (nx if none),
// one past the last such cell (0 if none), and the side of the row's first
// and last value (0 below iso, 1 not below, 2 not finite). Outside
// [first, last + 1) a row is finite and on one side.
__kernel void mc_direct_rows(uint grid_rows, uint nx, __global const float *vol, float iso,
                             __global uint *info)
{
    GID_OR_RETURN(grid_rows);
    const ulong b = (ulong)nx * gid;
    const float16 i16 = (float16)(iso);
    uint xl = nx, xr = 0, x = 0, last = nx;
    int m[16];
    for (; x + 16 < nx; x += 16) {
        ROW_PREFETCH(vol + b + x);
        const float16 a = vload16(0, vol + b + x), c = vload16(0, vol + b + x + 1);
        const int16 bad = ~(isfinite(a) & isfinite(c)) | (isless(a, i16) ^ isless(c, i16));
        if (any16(bad)) {
            if (xl == nx) {
                vstore16(bad, 0, m);
                uint i = 0;
                while (!m[i])
                    ++i;
                xl = x + i;
            }
            last = x;
        }
    }
    if (last != nx) {
        // The last lane of the last chunk that crosses.
        const float16 a = vload16(0, vol + b + last), c = vload16(0, vol + b + last + 1);
        vstore16(~(isfinite(a) & isfinite(c)) | (isless(a, i16) ^ isless(c, i16)), 0, m);
        uint i = 15;
        while (!m[i])
            --i;
        xr = last + i + 1;
    }
    if (x + 1 < nx && nx >= 17) {
        // The tail: the chunk that ends at the row's end, lanes before x off.
        const uint tb = nx - 17;
        const float16 a = vload16(0, vol + b + tb), c = vload16(0, vol + b + tb + 1);
        const float16 lane = (float16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
        const int16 mine = isgreaterequal(lane, (float16)((float)(x - tb)));
        const int16 bad = (~(isfinite(a) & isfinite(c)) | (isless(a, i16) ^ isless(c, i16))) & mine;
        if (any16(bad)) {
            vstore16(bad, 0, m);
            uint i = 0;
            while (!m[i])
                ++i;
            xl = min(xl, tb + i);
            i = 15;
            while (!m[i])
                --i;
            xr = tb + i + 1;
        }
        x = nx;
    }
    for (; x + 1 < nx; ++x) {
        const float a = vol[b + x], c = vol[b + x + 1];
        if (!(isfinite(a) && isfinite(c)) || ((a < iso) != (c < iso))) {
            xl = min(xl, x);
            xr = x + 1;
        }
    }
    const float f = vol[b], l = vol[b + nx - 1];
    info[4 * gid] = xl;
    info[4 * gid + 1] = xr;
    info[4 * gid + 2] = isfinite(f) ? (f < iso ? 0u : 1u) : 2u;
    info[4 * gid + 3] = isfinite(l) ? (l < iso ? 0u : 1u) : 2u;
}

// Per grid row, from info: the x range where its four rows can differ (none:
// nothing read); there, rowc[r] vertices inside its owned edges, rowc[G+r]
// triangles of cell row r, rowc[2G+r] vertices rounding onto a grid point
// ("hits"), rowc[3G+r] triangles dropped as twins across a cube face
// (has_twin); split[2r..] the first y and z vertex of the row; trim[3r..] the
// x range of its non-uniform chunks (Flying Edges' trimming: the later passes
// read nothing outside it) and their chunk mask (chunk_shift: the triangle
// pass skips the uniform chunks inside the range without reading them).
__kernel void mc_direct_count(uint grid_rows, uint nx, uint ny, uint nz,
                              __global const float *vol, float iso, __constant uchar *counts,
                              __constant uchar *tris, __constant uchar *flat,
                              __global const uint *info, __global uint *rowc,
                              __global uint *split, __global uint *trim)
{
    GID_OR_RETURN(grid_rows);
    GRID_ROW_SETUP
    const bool cell = hy && hz;
    // The x range where the four rows (aliased as b00..b11) can differ: left
    // of every row's first crossing they are uniform, and alike if their
    // first values are on one side; likewise right of the last crossing.
    const uint r10 = gid + hy, r01 = gid + (hz ? ny : 0), r11 = r10 + (r01 - gid);
    const uint L = min(min(info[4 * gid], info[4 * r10]), min(info[4 * r01], info[4 * r11]));
    const uint Rx = max(max(info[4 * gid + 1], info[4 * r10 + 1]),
                        max(info[4 * r01 + 1], info[4 * r11 + 1]));
    const uint sl = info[4 * gid + 2], sr = info[4 * gid + 3];
    const bool left = sl != 2 && info[4 * r10 + 2] == sl && info[4 * r01 + 2] == sl &&
                      info[4 * r11 + 2] == sl;
    const bool right = sr != 2 && info[4 * r10 + 3] == sr && info[4 * r01 + 3] == sr &&
                       info[4 * r11 + 3] == sr;
    const uint start = left ? L : 0, pend = right ? Rx : nx;
    // Per position at most one owned edge of each kind and three hits: the
    // packed counts of count_owned add up without carries over a 16-cell
    // chunk, so they are unpacked once per chunk (and per tail position).
    uint n0 = 0, n1 = 0, n2 = 0, hits = 0, ntri = 0, twins = 0, lo = nx, hi = 0;
    uint mask = 0;
    const uint cshift = chunk_shift(nx);
    float v[8];
    float16 a[8];
    const float16 lane = (float16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    // The chunks of the other passes, from the one holding `start` on.
    uint x = start >= pend ? nx : start & ~15u;
    for (; x + 16 < nx && x < pend; x += 16) {
        bool fin;
        const uint16 cv = chunk_cases(vol, b00, b10, b01, b11, x, iso, a, &fin);
        if (fin && all16((cv == (uint16)(0)) | (cv == (uint16)(255))))
            continue;
        lo = min(lo, x);
        hi = x + 16;
        mask |= 1u << ((x >> 4) >> cshift);
        if (fin) {
            // All finite: the owned edges 16 at a time (corner 0 to 1, 2, 4).
            int16 ix, iy, iz;
            const int16 hx = edge_kinds16(a[0], a[1], iso, (float16)((float)x) + lane, &ix);
            const int16 hy = edge_kinds16(a[0], a[2], iso, (float16)((float)y), &iy);
            const int16 hz = edge_kinds16(a[0], a[4], iso, (float16)((float)z), &iz);
            const uint p = owned16(hx, hy, hz, ix, iy, iz, (int16)(-1));
            n0 += p & 0xFF;
            n1 += (p >> 8) & 0xFF;
            n2 += (p >> 16) & 0xFF;
            hits += p >> 24;
            if (cell) {
                uint cs[16];
                vstore16(cv, 0, cs);
                uint fl = 0;
                for (uint i = 0; i < 16; ++i) {
                    ntri += counts[cs[i]];
                    fl |= flat[cs[i]];
                }
                if (fl != 0) {
                    for (uint i = 0; i < 16; ++i) {
                        const uint tw = twins_of(vol, x + i, y, z, nx, ny, nz, iso, cs[i],
                                                 counts, tris, flat);
                        ntri -= tw;
                        twins += tw;
                    }
                }
            }
            continue;
        }
        uint packed = 0;
        for (uint i = x; i < x + 16; ++i) {
            if (cell) {
                const uint cas = cell_case(vol, b00, b10, b01, b11, i, iso, v);
                // A finite cell with all corners on one side: its edges, the
                // row's owned edges at i among them, carry nothing.
                if (cas == 0 || cas == 255)
                    continue;
                packed += count_owned(vol, b00, b10, b01, i, nx, y, z, iso);
                if (cas < 256) {
                    const uint tw =
                        twins_of(vol, i, y, z, nx, ny, nz, iso, cas, counts, tris, flat);
                    ntri += counts[cas] - tw;
                    twins += tw;
                }
            } else {
                packed += count_owned(vol, b00, b10, b01, i, nx, y, z, iso);
            }
        }
        n0 += packed & 0xFF;
        n1 += (packed >> 8) & 0xFF;
        n2 += (packed >> 16) & 0xFF;
        hits += packed >> 24;
    }
    // The tail (cells x .. nx − 2, fewer than 16): one chunk that overlaps
    // the last one, ending at the row's end, with the lanes of cells before
    // x masked off; the y- and z-edges at nx − 1 (corners of the last cell,
    // so uniform with it) added alone.
    bool tail_done = false;
    if (x < pend && x + 1 < nx && nx >= 17) {
        bool fin;
        const uint tb = nx - 17;
        const uint16 cv = chunk_cases(vol, b00, b10, b01, b11, tb, iso, a, &fin);
        if (fin) {
            tail_done = true;
            const int16 mine = isgreaterequal(lane, (float16)((float)(x - tb)));
            const int16 triv = (cv == (uint16)(0)) | (cv == (uint16)(255));
            if (!all16(triv | ~mine)) {
                lo = min(lo, x);
                hi = nx;
                mask |= 1u << ((x >> 4) >> cshift);
                int16 ix, iy, iz;
                const int16 hx = edge_kinds16(a[0], a[1], iso, (float16)((float)tb) + lane, &ix);
                const int16 hy = edge_kinds16(a[0], a[2], iso, (float16)((float)y), &iy);
                const int16 hz = edge_kinds16(a[0], a[4], iso, (float16)((float)z), &iz);
                // With the y- and z-edges at nx − 1 (no x-edge there).
                const uint p = owned16(hx, hy, hz, ix, iy, iz, mine) +
                               count_owned(vol, b00, b10, b01, nx - 1, nx, y, z, iso);
                n0 += p & 0xFF;
                n1 += (p >> 8) & 0xFF;
                n2 += (p >> 16) & 0xFF;
                hits += p >> 24;
                if (cell) {
                    uint cs[16];
                    vstore16(cv, 0, cs);
                    uint fl = 0;
                    for (uint i = x - tb; i < 16; ++i) {
                        ntri += counts[cs[i]];
                        fl |= flat[cs[i]];
                    }
                    for (uint i = x - tb; fl != 0 && i < 16; ++i) {
                        const uint tw = twins_of(vol, tb + i, y, z, nx, ny, nz, iso, cs[i],
                                                 counts, tris, flat);
                        ntri -= tw;
                        twins += tw;
                    }
                }
            }
        }
    }
    if (!tail_done && x < pend && !tail_uniform(vol, b00, b10, b01, b11, x, nx, iso)) {
        lo = min(lo, x);
        hi = nx;
        mask |= 1u << ((x >> 4) >> cshift);
        for (uint i = x; i < nx; ++i) {
            const uint packed = count_owned(vol, b00, b10, b01, i, nx, y, z, iso);
            n0 += packed & 0xFF;
            n1 += (packed >> 8) & 0xFF;
            n2 += (packed >> 16) & 0xFF;
            hits += packed >> 24;
            if (cell && i + 1 < nx) {
                const uint cas = cell_case(vol, b00, b10, b01, b11, i, iso, v);
                if (cas < 256) {
                    const uint tw =
                        twins_of(vol, i, y, z, nx, ny, nz, iso, cas, counts, tris, flat);
                    ntri += counts[cas] - tw;
                    twins += tw;
                }
            }
        }
    }
    rowc[gid] = n0 + n1 + n2;
    rowc[grid_rows + gid] = ntri;
    rowc[2 * grid_rows + gid] = hits;
    rowc[3 * grid_rows + gid] = twins;
    split[2 * gid] = n0;
    split[2 * gid + 1] = n0 + n1;
    trim[3 * gid] = lo;
    trim[3 * gid + 1] = hi;
    trim[3 * gid + 2] = mask;
}

// Only with hits (vertices rounding onto a grid point), per grid row: the
// grid indices of its hit points, listed in keys (sorted and made unique on
// the host). With no hit and a finite volume no triangle can collapse and the
// only twins (a flat triangle and its mirror across the face) are found by
// has_twin; otherwise the host checks the triangles listed in `side` and runs
// vertex fusion's clean-up only when it would change the mesh
// (docs/notes/isosurface-kernels.md).
__kernel void mc_direct_hits(uint grid_rows, uint nx, uint ny, uint nz,
                             __global const float *vol, float iso, __global const uint *off,
                             __global const uint *trim, uint hit_base, uint hit_end,
                             __global uint *keys)
{
    GID_OR_RETURN(grid_rows);
    GRID_ROW_SETUP
    const uint lo = trim[3 * gid], hi = trim[3 * gid + 1];
    const uint first = off[2 * grid_rows + gid];
    const uint end = gid + 1 < grid_rows ? off[2 * grid_rows + gid + 1] : hit_end;
    if (first == end)
        return;
    uint o = first - hit_base;
    const uint done = end - hit_base;
    const float16 lane = (float16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    uint x = lo;
    // 16 positions at a time: where their owned edges' ends are finite, the
    // hits in lanes (the keys' order is free: the host sorts them); the row
    // done once its count of hits is written.
    for (; x + 16 < nx && x < hi && o < done; x += 16) {
        const float16 a = vload16(0, vol + b00 + x), ax = vload16(0, vol + b00 + x + 1);
        const float16 ay = vload16(0, vol + b10 + x), az = vload16(0, vol + b01 + x);
        if (!all16(isfinite(a) & isfinite(ax) & isfinite(ay) & isfinite(az))) {
            for (uint i = x; i < x + 16; ++i)
                hit_owned(vol, b00, b10, b01, i, nx, ny, y, z, iso, keys, &o);
            continue;
        }
        const uint g = grid_index(x, y, z, nx, ny);
        uint ux, uy, uz;
        put_hits(hit_ends16(a, ax, iso, (float16)((float)x) + lane, &ux), g, keys, &o);
        put_hits(ux, g + 1, keys, &o);
        put_hits(hit_ends16(a, ay, iso, (float16)((float)y), &uy), g, keys, &o);
        put_hits(uy, g + nx, keys, &o);
        put_hits(hit_ends16(a, az, iso, (float16)((float)z), &uz), g, keys, &o);
        put_hits(uz, g + nx * ny, keys, &o);
    }
    if (o >= done)
        return;
    // The tail, unless the chunk that ends at the row's end is uniform.
    if (x < hi && x + 1 < nx && nx >= 17 && chunk_uniform(vol, b00, b10, b01, b11, nx - 17, iso))
        return;
    for (; x < hi; ++x)
        hit_owned(vol, b00, b10, b01, x, nx, ny, y, z, iso, keys, &o);
}

// Only where there are hits: the triangles of each cell row that are kept
// (twins across faces and collapsing triangles dropped) into tcount[r]; only
// the cells with a corner on a hit point are looked at again, and rows whose
// four grid rows have no hit keep their count from the first scan.
__kernel void mc_direct_recount(uint grid_rows, uint nx, uint ny, uint nz,
                                __global const float *vol, float iso, __constant uchar *counts,
                                __constant uchar *tris, __constant uchar *flat,
                                __global const uint *off, __global const uint *trim,
                                __global uint *tcount, uint nh, __global const uint *keys)
{
    GID_OR_RETURN(grid_rows);
    GRID_ROW_SETUP
    const uint G = grid_rows;
    if (!(hy && hz)) {
        tcount[gid] = 0;
        return;
    }
    const uint before = off[G + gid + 1] - off[G + gid];
    if (!cell_row_has_hits(off, G, gid, ny)) {
        tcount[gid] = before;
        return;
    }
    // Only a cell with a corner on a hit point can lose a collapsing
    // triangle: the count of the first scan less those, cell by cell over
    // the hit points of the row's four grid rows (cells hx − 1 and hx of a
    // hit at hx), each cell once.
    const uint lo = trim[3 * gid], hi = trim[3 * gid + 1];
    HitCursor h;
    hits_begin(&h, keys, nh, nx, gid, gid + ny);
    float v[8], c[12];
    uint k[12];
    uint dropped = 0;
    for (uint from = 0;;) {
        const uint hx = hits_from(&h, keys, from);
        if (hx == 0xFFFFFFFFu)
            break;
        for (uint x = max(from, max(hx, 1u) - 1); x <= hx; ++x) {
            if (x < lo || x >= hi || x + 1 >= nx)
                continue;
            const uint cas = cell_case(vol, b00, b10, b01, b11, x, iso, v);
            if (cas == 0 || cas >= 255)
                continue;
            CELL_EDGES
            const uint nt = counts[cas], fl = flat[cas];
            for (uint j = 0; j < nt; ++j) {
                if (((fl >> j) & 1) &&
                    has_twin(vol, x, y, z, nx, ny, nz, iso, cas, j, counts, tris))
                    continue;
                dropped += collapses(tris[16 * cas + 3 * j], tris[16 * cas + 3 * j + 1],
                                     tris[16 * cas + 3 * j + 2], k, x, y, z, nx, ny);
            }
        }
        from = hx + 1;
    }
    const uint n = before - dropped;
    tcount[gid] = n;
}

// One cell of mc_direct_triangles: the positions of the vertices it owns
// and its triangles from faces[out] on. i00x .. i10z are the indices of the
// next interior vertex of each (row, axis) the cell row uses: x00 x10 x01
// x11 y00 y01 z00 z10. Returns the triangles written (bits 8..) and which
// of the edges 0, 1, 2, 3, 4, 6, 8, 10 hold an interior vertex (bits 0..7,
// for the caller's counts). hc: a corner of the cell is a hit point (the
// kinds and coordinates of every edge, hit vertices' ranks read off the row's
// hit cursor hcur, collapsing triangles dropped, triangles with a hit corner
// listed in `side`); else the kinds from the case alone and only the
// written coordinates.
__attribute__((always_inline)) inline uint
emit_cell(__global const float *vol, uint nx, uint ny, uint nz, uint x, uint y, uint z,
          ulong b00, ulong b10, ulong b01, ulong b11, float iso, __constant uchar *counts,
          __constant uchar *tris, __constant uchar *flat, uint cas, const float *v, uint i00x,
          uint i10x, uint i01x, uint i11x, uint i00y, uint i01y, uint i00z, uint i10z,
          uint out, uint edge_vertices, uint nh, __global const uint *hit_keys,
          __global float *pos, __global uint *faces, uint side_cap, __global uint *side,
          volatile __global uint *side_n, const HitCursor *hcur, const bool hc)
{
    // The last cell row of y (z) also writes the vertices of row 10 (01),
    // which is not a cell row; the last cell of a row those at x = nx − 1.
    const bool wy = y + 2 == ny, wz = z + 2 == nz;
    const float fx = (float)x, fy = (float)y, fz = (float)z;
    float c[12];
    uint k[12], id[12];
    if (hc) {
        CELL_EDGES
    } else {
        CELL_KINDS
    }
    id[0] = i00x;
    id[1] = i10x;
    id[2] = i01x;
    id[3] = i11x;
    id[4] = i00y;
    id[5] = id[4] + (k[4] == EV_IN);
    id[6] = i01y;
    id[7] = id[6] + (k[6] == EV_IN);
    id[8] = i00z;
    id[9] = id[8] + (k[8] == EV_IN);
    id[10] = i10z;
    id[11] = id[10] + (k[10] == EV_IN);
    // Corners of this cell on grid points (collapses need two).
    uint ch = 0;
    if (hc) {
        for (uint e = 0; e < 12; ++e) {
            if (k[e] >= EV_LO) {
                id[e] = hit_vertex_at(hcur, hit_keys, e, k[e], x, edge_vertices);
                ++ch;
            }
        }
    }
    if (k[0] == EV_IN)
        put3(pos, id[0], EDGE_C(0, 0, 1, fx), fy, fz);
    if (k[4] == EV_IN)
        put3(pos, id[4], fx, EDGE_C(4, 0, 2, fy), fz);
    if (k[8] == EV_IN)
        put3(pos, id[8], fx, fy, EDGE_C(8, 0, 4, fz));
    if (wy) {
        if (k[1] == EV_IN)
            put3(pos, id[1], EDGE_C(1, 2, 3, fx), fy + 1.0f, fz);
        if (k[10] == EV_IN)
            put3(pos, id[10], fx, fy + 1.0f, EDGE_C(10, 2, 6, fz));
    }
    if (wz) {
        if (k[2] == EV_IN)
            put3(pos, id[2], EDGE_C(2, 4, 5, fx), fy, fz + 1.0f);
        if (k[6] == EV_IN)
            put3(pos, id[6], fx, EDGE_C(6, 4, 6, fy), fz + 1.0f);
    }
    if (wy && wz && k[3] == EV_IN)
        put3(pos, id[3], EDGE_C(3, 6, 7, fx), fy + 1.0f, fz + 1.0f);
    if (x + 2 == nx) {
        if (k[5] == EV_IN)
            put3(pos, id[5], fx + 1.0f, EDGE_C(5, 1, 3, fy), fz);
        if (k[9] == EV_IN)
            put3(pos, id[9], fx + 1.0f, fy, EDGE_C(9, 1, 5, fz));
        if (wy && k[11] == EV_IN)
            put3(pos, id[11], fx + 1.0f, fy + 1.0f, EDGE_C(11, 3, 7, fz));
        if (wz && k[7] == EV_IN)
            put3(pos, id[7], fx + 1.0f, EDGE_C(7, 5, 7, fy), fz + 1.0f);
    }
    uint written = 0;
    if (cas < 256) {
        const uint nt = counts[cas], fl = flat[cas];
        for (uint j = 0; j < nt; ++j) {
            if (((fl >> j) & 1) && has_twin(vol, x, y, z, nx, ny, nz, iso, cas, j, counts, tris))
                continue;
            const uint ea = tris[16 * cas + 3 * j], eb = tris[16 * cas + 3 * j + 1],
                       ec = tris[16 * cas + 3 * j + 2];
            if (ch >= 2 && collapses(ea, eb, ec, k, x, y, z, nx, ny))
                continue;
            faces[out] = id[ea];
            faces[out + 1] = id[eb];
            faces[out + 2] = id[ec];
            // A triangle with a corner on a grid point lying in a grid plane
            // may have a twin (the cell's across the plane): its corners
            // listed for the host to decide whether the clean-up must run.
            if (ch != 0 && (k[ea] >= EV_LO || k[eb] >= EV_LO || k[ec] >= EV_LO)) {
                uint plane = 0;
                for (uint q = 0; q < 3; ++q) {
                    const float pa = corner_coord(ea, k[ea], c[ea], x, y, z, q);
                    const float pb = corner_coord(eb, k[eb], c[eb], x, y, z, q);
                    const float pc = corner_coord(ec, k[ec], c[ec], x, y, z, q);
                    plane |= pa == pb && pb == pc && pa == floor(pa);
                }
                if (plane) {
                    const uint o = atomic_inc(&side_n[0]);
                    if (o < side_cap) {
                        side[3 * o] = id[ea];
                        side[3 * o + 1] = id[eb];
                        side[3 * o + 2] = id[ec];
                    }
                }
            }
            out += 3;
            ++written;
        }
    }
    return (written << 8) | (uint)(k[0] == EV_IN) | ((uint)(k[1] == EV_IN) << 1) |
           ((uint)(k[2] == EV_IN) << 2) | ((uint)(k[3] == EV_IN) << 3) |
           ((uint)(k[4] == EV_IN) << 4) | ((uint)(k[6] == EV_IN) << 5) |
           ((uint)(k[8] == EV_IN) << 6) | ((uint)(k[10] == EV_IN) << 7);
}

// emit_cell for a cell with a corner on a hit point, its case and values
// read here: a call, so that the loop of the hit-free cells stays as lean in
// a row with hits as in one without.
__attribute__((noinline)) uint
emit_hit_cell(__global const float *vol, uint nx, uint ny, uint nz, uint x, uint y, uint z,
              ulong b00, ulong b10, ulong b01, ulong b11, float iso, __constant uchar *counts,
              __constant uchar *tris, __constant uchar *flat, uint i00x, uint i10x, uint i01x,
              uint i11x, uint i00y, uint i01y, uint i00z, uint i10z, uint out,
              uint edge_vertices, uint nh, __global const uint *hit_keys, __global float *pos,
              __global uint *faces, uint side_cap, __global uint *side,
              volatile __global uint *side_n, const HitCursor *hcur)
{
    float v[8];
    const uint cas = cell_case(vol, b00, b10, b01, b11, x, iso, v);
    if (cas == 0 || cas == 255)
        return 0;
    return emit_cell(vol, nx, ny, nz, x, y, z, b00, b10, b01, b11, iso, counts, tris, flat, cas,
                     v, i00x, i10x, i01x, i11x, i00y, i01y, i00z, i10z, out, edge_vertices, nh,
                     hit_keys, pos, faces, side_cap, side, side_n, hcur, true);
}

// The cells of one cell row of mc_direct_triangles, from the row's first
// vertex indices (i00x .. i10z, see emit_cell) and first triangle (out).
__attribute__((always_inline)) inline void
triangles_row(__global const float *vol, uint nx, uint ny, uint nz, uint y, uint z, ulong b00,
              ulong b10, ulong b01, ulong b11, float iso, __constant uchar *counts,
              __constant uchar *tris, __constant uchar *flat, uint lo, uint hi, uint i00x,
              uint i10x, uint i01x, uint i11x, uint i00y, uint i01y, uint i00z, uint i10z,
              uint out, uint edge_vertices, uint nh, __global const uint *hit_keys,
              __global float *pos, __global uint *faces, uint side_cap, __global uint *side,
              volatile __global uint *side_n, uint gid, uint mask, const bool row_hits)
{
    const uint cshift = chunk_shift(nx);
    // The least x' ≥ x of a hit point on the four grid rows (hits_from),
    // found again only once x passes it.
    HitCursor h;
    uint hnext = 0xFFFFFFFFu;
    if (row_hits) {
        hits_begin(&h, hit_keys, nh, nx, gid, gid + ny);
        hnext = hits_from(&h, hit_keys, lo);
    }
    float v[8];
    float16 a[8];
    // Cells of the current chunk known (from its vector cases) to be finite
    // with all corners on one side: bit x − base.
    uint skip = 0, base = lo;
    // The current chunk's cases, when it is finite (chunk_fin).
    uint cs[16];
    bool chunk_fin = false;
    for (uint x = lo; x < hi && x + 1 < nx; ++x) {
        // The chunks of mc_direct_count: 16 cells from each multiple of 16
        // that has 16 more values after it (lo is one of them, or the tail),
        // and for the tail the chunk that ends at the row's end.
        if ((x & 15) == 0) {
            // A chunk the count pass found uniform: not read again.
            if (!((mask >> ((x >> 4) >> cshift)) & 1)) {
                x += 15;
                continue;
            }
            skip = 0;
            chunk_fin = false;
            base = x + 16 < nx ? x : (nx >= 17 ? nx - 17 : x);
            if (x + 16 < nx || nx >= 17) {
                bool fin;
                const uint16 cv = chunk_cases(vol, b00, b10, b01, b11, base, iso, a, &fin);
                if (fin) {
                    const int16 triv = (cv == (uint16)(0)) | (cv == (uint16)(255));
                    if (all16(triv)) {
                        x = base + 15;
                        continue;
                    }
                    skip = lanes_bits(triv);
                    vstore16(cv, 0, cs);
                    chunk_fin = true;
                }
            }
        }
        if ((skip >> (x - base)) & 1)
            continue;
        if (row_hits && x > hnext)
            hnext = hits_from(&h, hit_keys, x);
        uint r;
        if (row_hits && hnext <= x + 1) {
            r = emit_hit_cell(vol, nx, ny, nz, x, y, z, b00, b10, b01, b11, iso, counts, tris,
                              flat, i00x, i10x, i01x, i11x, i00y, i01y, i00z, i10z, out,
                              edge_vertices, nh, hit_keys, pos, faces, side_cap, side, side_n,
                              &h);
        } else {
            // A cell of a finite chunk reads only the corner values it needs
            // (EDGE_C), its case known from the chunk.
            const uint cas = chunk_fin ? cs[x - base] : cell_case(vol, b00, b10, b01, b11, x, iso, v);
            // All corners finite and on one side: nothing to write or count.
            if (cas == 0 || cas == 255)
                continue;
            r = emit_cell(vol, nx, ny, nz, x, y, z, b00, b10, b01, b11, iso, counts, tris, flat,
                          cas, v, i00x, i10x, i01x, i11x, i00y, i01y, i00z, i10z, out,
                          edge_vertices, nh, hit_keys, pos, faces, side_cap, side, side_n, 0,
                          false);
        }
        out += 3 * (r >> 8);
        i00x += r & 1;
        i10x += (r >> 1) & 1;
        i01x += (r >> 2) & 1;
        i11x += (r >> 3) & 1;
        i00y += (r >> 4) & 1;
        i01y += (r >> 5) & 1;
        i00z += (r >> 6) & 1;
        i10z += (r >> 7) & 1;
    }
}

// Per cell row: positions of the vertices the row owns and its triangles with
// final indices (a hit corner: edge_vertices + the rank of its point among
// the sorted, unique hit points); triangles with a hit corner lying in a grid
// plane are also listed in `side` (their corners) for the host's twin check. Only
// the cells with a corner on a hit point take the hit-aware steps
// (emit_hit_cell, a call); the rows whose four grid rows own no hit (nearly
// all of them) run a copy of the loop compiled without the hit cursor and
// the call (triangles_row with row_hits false).
__kernel void mc_direct_triangles(uint grid_rows, uint nx, uint ny, uint nz,
                                  __global const float *vol, float iso,
                                  __constant uchar *counts, __constant uchar *tris,
                                  __constant uchar *flat, __global const uint *off,
                                  __global const uint *split, __global const uint *trim,
                                  __global const uint *toff, uint tshift, uint tbase,
                                  uint edge_vertices, uint nh, __global const uint *hit_keys,
                                  __global float *pos, __global uint *faces, uint side_cap,
                                  __global uint *side, volatile __global uint *side_n)
{
    GID_OR_RETURN(grid_rows);
    GRID_ROW_SETUP
    if (!(hy && hz))
        return;
    const uint lo = trim[3 * gid], hi = trim[3 * gid + 1];
    if (lo >= hi)
        return;
    const uint r10 = gid + 1, r01 = gid + ny, r11 = gid + ny + 1;
    // Next interior vertex of each row's x, y and z edges (those a cell row
    // uses), from the first: x00 y00 z00 x10 z10 x01 y01 x11.
    const uint i00x = off[gid], i00y = i00x + split[2 * gid], i00z = i00x + split[2 * gid + 1];
    const uint i10x = off[r10], i10z = i10x + split[2 * r10 + 1];
    const uint i01x = off[r01], i01y = i01x + split[2 * r01];
    const uint i11x = off[r11];
    // First triangle of the row: toff[tshift + r] − tbase (the triangles'
    // part of off, which starts at edge_vertices, or the scan of the
    // recount where there are hits).
    const uint out = 3 * (toff[tshift + gid] - tbase);
    if (nh != 0 && cell_row_has_hits(off, grid_rows, gid, ny))
        triangles_row(vol, nx, ny, nz, y, z, b00, b10, b01, b11, iso, counts, tris, flat, lo,
                      hi, i00x, i10x, i01x, i11x, i00y, i01y, i00z, i10z, out, edge_vertices,
                      nh, hit_keys, pos, faces, side_cap, side, side_n, gid, trim[3 * gid + 2], true);
    else
        triangles_row(vol, nx, ny, nz, y, z, b00, b10, b01, b11, iso, counts, tris, flat, lo,
                      hi, i00x, i10x, i01x, i11x, i00y, i01y, i00z, i10z, out, edge_vertices,
                      nh, hit_keys, pos, faces, side_cap, side, side_n, gid, trim[3 * gid + 2], false);
}

// Per hit point: the position of its vertex (slot V + its rank among the
// sorted, unique hit points).
__kernel void mc_direct_points(uint nh, __global const uint *hit_keys, uint nx, uint ny,
                               uint edge_vertices, __global float *pos)
{
    GID_OR_RETURN(nh);
    const uint g = hit_keys[gid];
    put3(pos, edge_vertices + gid, (float)(g % nx), (float)((g / nx) % ny),
         (float)(g / (nx * ny)));
}

// The check that dropped triangles (twins across a cube face, collapses onto
// hit points) left no vertex unused, made near them: a vertex of grid row g
// is used by cells of the four cell rows around g only, so only the grid
// rows of a cell row that dropped triangles can own an unused vertex, and
// only the cell rows around those can use it.
//   mc_direct_unused_rows   per grid row     the cell rows that dropped
//                                            triangles, listed (at most D, the
//                                            dropped triangles)
//   mc_direct_unused_clear  4 per listed row the marks of its grid rows'
//                                            vertices (edge vertices, hit points)
//   mc_direct_unused_mark   9 per listed row the vertices that the kept
//                                            triangles of the 3 × 3 cell rows
//                                            around it use
//   mc_direct_unused_count  4 per listed row its grid rows' marks still clear,
//                                            each grid row counted once
// toff[tshift + r] − tbase: the first kept triangle of cell row r (as for
// mc_direct_triangles); list[0]: the listed rows, list[1]: the unused count,
// list[2..]: the rows (row_drops, listed_grid_row, GRID_ROW_MARKS in
// common/mc_direct.h). Twin:
// cpu::marching_cubes::direct_unused_near.

__kernel void mc_direct_unused_rows(uint grid_rows, uint ny, uint nz, __global const uint *off,
                                    __global const uint *toff, uint tshift, uint cap,
                                    volatile __global uint *list)
{
    GID_OR_RETURN(grid_rows);
    if (row_drops(off, toff, tshift, grid_rows, ny, nz, gid % ny, gid / ny) == 0)
        return;
    const uint o = atomic_inc(&list[0]);
    if (o < cap)
        list[2 + o] = gid;
}

__kernel void mc_direct_unused_clear(uint grid_rows, uint nx, uint ny, uint nz,
                                     __global const uint *off, uint nh,
                                     __global const uint *keys, uint cap,
                                     __global const uint *list, __global uint *mark)
{
    const uint g = listed_grid_row(list, cap, ny, get_global_id(0));
    if (g == 0xFFFFFFFFu)
        return;
#define CLEAR(i) mark[i] = 0
    GRID_ROW_MARKS(CLEAR)
#undef CLEAR
}

__kernel void mc_direct_unused_mark(uint grid_rows, uint ny, uint nz, __global const uint *toff,
                                    uint tshift, uint tbase, uint nv, __global const uint *faces,
                                    uint cap, __global const uint *list, __global uint *mark)
{
    const uint w = get_global_id(0);
    if (w / 9 >= min(list[0], cap))
        return;
    const uint r = list[2 + w / 9];
    const int y = (int)(r % ny) + (int)(w % 3) - 1, z = (int)(r / ny) + (int)((w / 3) % 3) - 1;
    if (y < 0 || z < 0 || y + 1 >= (int)ny || z + 1 >= (int)nz)
        return;
    const uint c = (uint)y + ny * (uint)z;
    const uint a = 3 * (toff[tshift + c] - tbase), b = 3 * (toff[tshift + c + 1] - tbase);
    for (uint i = a; i < b; ++i)
        if (faces[i] < nv)
            mark[faces[i]] = 1;
}

__kernel void mc_direct_unused_count(uint grid_rows, uint nx, uint ny, uint nz,
                                     __global const uint *off, __global const uint *toff,
                                     uint tshift, uint nh, __global const uint *keys,
                                     __global const uint *mark, uint cap,
                                     __global uint *list)
{
    const uint w = get_global_id(0);
    const uint g = listed_grid_row(list, cap, ny, w);
    if (g == 0xFFFFFFFFu)
        return;
    // Counted by the first of g's cell rows (y − 1, z − 1), (y, z − 1),
    // (y − 1, z), (y, z) that dropped triangles: w's own is the (3 − j)th.
    const int y = g % ny, z = g / ny;
    const uint j = w % 4;
    for (uint q = 0; q < 3 - j; ++q)
        if (row_drops(off, toff, tshift, grid_rows, ny, nz, y - 1 + (int)(q & 1),
                      z - 1 + (int)(q >> 1)) != 0)
            return;
    uint n = 0;
#define COUNT(i) n += mark[i] == 0
    GRID_ROW_MARKS(COUNT)
#undef COUNT
    if (n != 0)
        atomic_add(&list[1], n);
}
