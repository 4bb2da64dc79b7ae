// mc_cell.h: the cell arithmetic both marching-cubes kernel files share
// (marching_cubes.cl, the soup; marching_cubes_direct.cl, direct numbering):
// reading a cell's eight values and its case, skipping uniform 16-cell
// chunks, grid indices and the table's edge numbering. CPU twin:
// src/cpu/marching_cubes.rs (cell_case, the edge numbering of its header).
//
// Conventions: corner c of a cell is at offset (c&1, (c>>1)&1, c>>2); bit c of
// the case is set when value < iso (inside); edge e runs along axis e/4 and
// e%4 picks the other two offsets (low bit: first other axis in x,y,z order).
// b00, b10, b01, b11 are the offsets of the four value rows of a cell row:
// (y, z), (y+1, z), (y, z+1), (y+1, z+1).

// On CPU devices the host builds with -DSC_CPU_PREFETCH=N: rows streamed by
// one work-item after another are fetched N values ahead of their loads (the
// loads otherwise wait on memory; docs/notes/peer-comparisons.md). A hint
// only: results do not change.
#ifdef SC_CPU_PREFETCH
#define ROW_PREFETCH(p) __builtin_prefetch((p) + SC_CPU_PREFETCH)
#else
#define ROW_PREFETCH(p)
#endif

// any() and all() of a 16-lane mask (a lane is true when its sign bit is
// set, as the built-ins read it) in four halving steps. PoCL lowers the
// built-ins to sixteen lane extracts and tests each (a third of the row
// pass's samples on the ironProt volume under perf); these are four shuffles.
inline bool any16(int16 m)
{
    const int8 a = m.lo | m.hi;
    const int4 b = a.lo | a.hi;
    const int2 c = b.lo | b.hi;
    return (c.x | c.y) < 0;
}

inline bool all16(int16 m)
{
    const int8 a = m.lo & m.hi;
    const int4 b = a.lo & a.hi;
    const int2 c = b.lo & b.hi;
    return (c.x & c.y) < 0;
}

// True when the 16 cells x .. x+15 of a row are all inside or all outside
// (and finite): they emit nothing. Explicit float16 code (PoCL compiles it
// for the host CPU, two 8-wide AVX2 halves here, where its work-item loop
// vectoriser gives up on the row loop: the build log's "AVX vector ... changes
// the ABI" warnings are about these float16 helpers), so a row is
// skimmed 16 cells at a time and only mixed chunks go through the per-cell
// path. Reads the 17 values x .. x+16 of the four rows.
inline bool chunk_uniform(__global const float *vol, ulong b00, ulong b10, ulong b01, ulong b11,
                          uint x, float iso)
{
    ROW_PREFETCH(vol + b00 + x);
    ROW_PREFETCH(vol + b10 + x);
    ROW_PREFETCH(vol + b01 + x);
    ROW_PREFETCH(vol + b11 + x);
    const float16 a = vload16(0, vol + b00 + x), b = vload16(0, vol + b10 + x);
    const float16 c = vload16(0, vol + b01 + x), d = vload16(0, vol + b11 + x);
    const float4 t = (float4)(vol[b00 + x + 16], vol[b10 + x + 16], vol[b01 + x + 16],
                              vol[b11 + x + 16]);
    const float16 i16 = (float16)(iso);
    const float4 i4 = (float4)(iso);
    const int16 fin = isfinite(a) & isfinite(b) & isfinite(c) & isfinite(d);
    const int16 in = isless(a, i16) & isless(b, i16) & isless(c, i16) & isless(d, i16);
    const int16 out = isgreaterequal(a, i16) & isgreaterequal(b, i16) &
                      isgreaterequal(c, i16) & isgreaterequal(d, i16);
    const int4 tf = isfinite(t), tin = isless(t, i4), tout = isgreaterequal(t, i4);
    // The 17th values joined to the first four lanes: one test per mask.
    const int16 t16 = (int16)(tf, tf, tf, tf), tin16 = (int16)(tin, tin, tin, tin);
    const int16 tout16 = (int16)(tout, tout, tout, tout);
    if (!all16(fin & t16))
        return false;
    return all16(in & tin16) || all16(out & tout16);
}

// The case of cell x of a row (bit c set when corner c is inside), or 256
// when a corner is not finite (the cell emits nothing).
inline uint cell_case(__global const float *vol, ulong b00, ulong b10, ulong b01, ulong b11,
                      uint x, float iso, float *v)
{
    v[0] = vol[b00 + x];
    v[1] = vol[b00 + x + 1];
    v[2] = vol[b10 + x];
    v[3] = vol[b10 + x + 1];
    v[4] = vol[b01 + x];
    v[5] = vol[b01 + x + 1];
    v[6] = vol[b11 + x];
    v[7] = vol[b11 + x + 1];
    // Branch-free and unrolled: the corners' sides and finiteness as bits.
    const uint cas = (uint)(v[0] < iso) | ((uint)(v[1] < iso) << 1) | ((uint)(v[2] < iso) << 2) |
                     ((uint)(v[3] < iso) << 3) | ((uint)(v[4] < iso) << 4) |
                     ((uint)(v[5] < iso) << 5) | ((uint)(v[6] < iso) << 6) |
                     ((uint)(v[7] < iso) << 7);
    const int ok = isfinite(v[0]) & isfinite(v[1]) & isfinite(v[2]) & isfinite(v[3]) &
                   isfinite(v[4]) & isfinite(v[5]) & isfinite(v[6]) & isfinite(v[7]);
    return ok ? cas : 256;
}

// Linear index of grid point (x, y, z).
inline uint grid_index(uint x, uint y, uint z, uint nx, uint ny)
{
    return x + nx * (y + ny * z);
}

// Lower corner of edge e (table numbering), and the edge along `axis` whose
// lower corner is c0 (its inverse).
inline uint edge_lo_corner(uint e)
{
    const uint axis = e >> 2, k = e & 3;
    const uint lo_axis = axis == 0 ? 1 : 0, hi_axis = axis == 2 ? 1 : 2;
    return ((k & 1) << lo_axis) | ((k >> 1) << hi_axis);
}

inline uint edge_id(uint axis, uint c0)
{
    const uint lo_axis = axis == 0 ? 1 : 0, hi_axis = axis == 2 ? 1 : 2;
    return 4 * axis + ((c0 >> lo_axis) & 1) + 2 * ((c0 >> hi_axis) & 1);
}
