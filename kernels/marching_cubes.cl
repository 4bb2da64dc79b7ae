// marching_cubes.cl: the isosurface value = iso of a scalar volume as a
// triangle soup with one key per soup vertex, for vertex fusion
// (vertex_fusion.cl; Fusion hash, edge, none), and the gradient normals of
// any extracted mesh. Direct numbering (Fusion direct, no soup) is its twin
// file marching_cubes_direct.cl; both read cells through common/mc_cell.h.
//
// Griffin et al. 2012, §3.4: classify, scan, triangles. Host:
// src/stages/marching_cubes/soup.rs; CPU twin with the same step names and
// the same f32 arithmetic: src/cpu/marching_cubes.rs. Shared with the host
// (src/spec/marching_cubes.rs): the case table (counts, tris; 0xFF = END),
// cell_rows, the soup bound; mode = Fusion::code (src/spec/vertex_fusion.rs).
//   mc_classify          per cell row  triangles the row emits (table counts)
//   (scan.cl)                          exclusive scan of the row counts → offsets
//   mc_triangles         per cell row  soup positions, indices, one key per vertex
//   mc_iota              per soup vertex  faces of the unfused soup
//   mc_gradient_normals  per vertex    unit normals from the volume gradient
// A work-item of the cell-row passes walks one row of cells along x (all
// cells with the same y, z), 16 cells at a time with float16 loads: a chunk
// whose 4×17 values are all on one side of iso is skipped.
//
// Buffers (N = nx·ny·nz voxels, R = (ny−1)(nz−1) cell rows, S soup vertices):
//   vol    float[N]   values, x fastest
//   counts uchar[256] triangles per case;  tris uchar[256·16] edge ids, 0xFF ends a row
//   row_tris uint[R]  mc_classify output;  row_off uint[R] its exclusive scan
//   pos    float[3S]  soup positions in index space (world = origin + spacing·p, on the host)
//   key    uint[S]    hash of the position (mode 1) or exact key (mode 2); absent in mode 0
//   idx    uint[S]    soup index (the "full index buffer"; sorted along with the keys)
//   counters uint[2]  [0] soup vertices that did not fit (nothing is written past cap)
//
// Triangles are wound so normals point to values >= iso (outward for signed
// distance fields). A cell with a non-finite corner emits nothing. A vertex
// whose coordinate rounds onto an edge endpoint is placed exactly at that
// grid point and gets the point's key 4g+3 (others: 4g+axis, g = lower
// endpoint's linear index), so fusion merges all vertices at a grid point
// whose value equals iso. Cell conventions: common/mc_cell.h.

#define ROW_SETUP                                                                   \
    const uint y = gid % (ny - 1), z = gid / (ny - 1);                              \
    const ulong b00 = (ulong)nx * (y + (ulong)ny * z);                              \
    const ulong b10 = b00 + nx, b01 = b00 + (ulong)nx * ny, b11 = b01 + nx;

__kernel void mc_classify(uint rows, uint nx, uint ny, __global const float *vol, float iso,
                          __constant uchar *counts, __global uint *row_tris)
{
    GID_OR_RETURN(rows);
    ROW_SETUP
    float v[8];
    uint total = 0;
    uint x = 0;
    for (; x + 16 < nx; x += 16) {
        if (chunk_uniform(vol, b00, b10, b01, b11, x, iso))
            continue;
        for (uint i = x; i < x + 16; ++i) {
            const uint cas = cell_case(vol, b00, b10, b01, b11, i, iso, v);
            total += cas < 256 ? counts[cas] : 0;
        }
    }
    for (; x + 1 < nx; ++x) {
        const uint cas = cell_case(vol, b00, b10, b01, b11, x, iso, v);
        total += cas < 256 ? counts[cas] : 0;
    }
    row_tris[gid] = total;
}

// Writes the triangles of cell (x, y, z) of case `cas` at soup slot `out`
// onward; returns the next free slot.
inline uint emit_cell(uint x, uint y, uint z, uint nx, uint ny, float iso, uint cas,
                      const float *v, __constant uchar *counts, __constant uchar *tris,
                      uint out, uint cap, uint mode, __global float *pos, __global uint *key,
                      __global uint *idx, volatile __global uint *counters)
{
    const uint nt = counts[cas];
    for (uint i = 0; i < 3 * nt; ++i) {
        const uint e = tris[16 * cas + i];
        const uint axis = e >> 2, c0 = edge_lo_corner(e), c1 = c0 | (1u << axis);
        uint g[3];
        g[0] = x + (c0 & 1);
        g[1] = y + ((c0 >> 1) & 1);
        g[2] = z + (c0 >> 2);
        const float v0 = v[c0], v1 = v[c1];
        const float t = mc_edge_t(v0, v1, iso);
        const float a = (float)g[axis];
        const float cc = a + t;
        float p[3];
        p[0] = (float)g[0];
        p[1] = (float)g[1];
        p[2] = (float)g[2];
        const uint lin = grid_index(g[0], g[1], g[2], nx, ny);
        const uint step = axis == 0 ? 1u : (axis == 1 ? nx : nx * ny);
        uint kk;
        if (cc == a) {
            kk = 4 * lin + 3;
        } else if (cc == (float)(g[axis] + 1)) {
            p[axis] = cc;
            kk = 4 * (lin + step) + 3;
        } else {
            p[axis] = cc;
            kk = 4 * lin + axis;
        }
        if (out < cap) {
            pos[3 * out] = p[0];
            pos[3 * out + 1] = p[1];
            pos[3 * out + 2] = p[2];
            if (mode != 0) {
                key[out] = mode == 1 ? fuse_hash(p[0], p[1], p[2]) : kk;
                idx[out] = out;
            }
        } else {
            atomic_inc(&counters[0]);
        }
        ++out;
    }
    return out;
}

__kernel void mc_triangles(uint rows, uint nx, uint ny, __global const float *vol, float iso,
                           __constant uchar *counts, __constant uchar *tris,
                           __global const uint *row_off, uint cap, uint mode,
                           __global float *pos, __global uint *key, __global uint *idx,
                           volatile __global uint *counters)
{
    GID_OR_RETURN(rows);
    ROW_SETUP
    float v[8];
    uint out = 3 * row_off[gid];
    uint x = 0;
    for (; x + 16 < nx; x += 16) {
        if (chunk_uniform(vol, b00, b10, b01, b11, x, iso))
            continue;
        for (uint i = x; i < x + 16; ++i) {
            const uint cas = cell_case(vol, b00, b10, b01, b11, i, iso, v);
            if (cas < 256)
                out = emit_cell(i, y, z, nx, ny, iso, cas, v, counts, tris, out, cap, mode, pos,
                                key, idx, counters);
        }
    }
    for (; x + 1 < nx; ++x) {
        const uint cas = cell_case(vol, b00, b10, b01, b11, x, iso, v);
        if (cas < 256)
            out = emit_cell(x, y, z, nx, ny, iso, cas, v, counts, tris, out, cap, mode, pos, key,
                            idx, counters);
    }
}

// Faces of the unfused soup (--fusion none): face t is (3t, 3t+1, 3t+2).
__kernel void mc_iota(uint n, __global uint *out)
{
    GID_OR_RETURN(n);
    out[gid] = gid;
}

// Central-difference gradient of the volume at grid point g along `axis`, in
// world units (one-sided at the border; 0 when the axis has one sample).
inline float grad_axis(__global const float *vol, uint x, uint y, uint z, uint nx, uint ny,
                       uint nz, uint axis, float h)
{
    uint n = axis == 0 ? nx : (axis == 1 ? ny : nz);
    uint c = axis == 0 ? x : (axis == 1 ? y : z);
    uint lo = c > 0 ? c - 1 : c, hi = c + 1 < n ? c + 1 : c;
    if (hi == lo)
        return 0.0f;
    uint xl = axis == 0 ? lo : x, yl = axis == 1 ? lo : y, zl = axis == 2 ? lo : z;
    uint xh = axis == 0 ? hi : x, yh = axis == 1 ? hi : y, zh = axis == 2 ? hi : z;
    return (vol[grid_index(xh, yh, zh, nx, ny)] - vol[grid_index(xl, yl, zl, nx, ny)]) /
           ((float)(hi - lo) * h);
}

// Unit normals of mesh vertices (index-space positions) from the volume
// gradient, trilinearly interpolated from the grid points of the enclosing
// cell; pointing to increasing values like the triangles' winding. (0,0,0)
// where the gradient vanishes or is not finite. CPU twin:
// cpu::marching_cubes::gradient_normals (in f64).
__kernel void mc_gradient_normals(uint nv, __global const float *pos, __global const float *vol,
                                  uint nx, uint ny, uint nz, float hx, float hy, float hz,
                                  __global float *nrm)
{
    GID_OR_RETURN(nv);
    float p[3], f[3];
    uint b[3];
    const uint d[3] = {nx, ny, nz};
    for (uint a = 0; a < 3; ++a) {
        p[a] = pos[3 * gid + a];
        const uint top = d[a] >= 2 ? d[a] - 2 : 0;
        b[a] = min((uint)max(p[a], 0.0f), top);
        f[a] = clamp(p[a] - (float)b[a], 0.0f, 1.0f);
    }
    float n[3] = {0.0f, 0.0f, 0.0f};
    for (uint c = 0; c < 8; ++c) {
        const uint o0 = c & 1, o1 = (c >> 1) & 1, o2 = c >> 2;
        const uint gx = min(b[0] + o0, nx - 1), gy = min(b[1] + o1, ny - 1), gz = min(b[2] + o2, nz - 1);
        const float w = (o0 ? f[0] : 1.0f - f[0]) * (o1 ? f[1] : 1.0f - f[1]) *
                        (o2 ? f[2] : 1.0f - f[2]);
        n[0] += w * grad_axis(vol, gx, gy, gz, nx, ny, nz, 0, hx);
        n[1] += w * grad_axis(vol, gx, gy, gz, nx, ny, nz, 1, hy);
        n[2] += w * grad_axis(vol, gx, gy, gz, nx, ny, nz, 2, hz);
    }
    const float len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const bool ok = isfinite(len) && len > 0.0f;
    for (uint a = 0; a < 3; ++a)
        nrm[3 * gid + a] = ok ? n[a] / len : 0.0f;
}
