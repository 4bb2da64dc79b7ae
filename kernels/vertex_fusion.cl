// vertex_fusion.cl: marching-cubes triangle soup → indexed mesh with shared
// vertices (Griffin et al. 2012, §3.4). Host: src/stages/vertex_fusion.rs; CPU twin with
// the same step names: src/cpu/vertex_fusion.rs.
// Shared with the host (src/spec/vertex_fusion.rs): the Fusion variant and its
// mc_triangles mode code, and the bounds of the buffers below.
//   (mc_triangles)           soup positions, one key per vertex, soup indices
//   (radix_sort.cl)          stable sort of (key, soup index) pairs
//   fuse_index        per sorted entry j: walk back to the first entry with the
//                     same key, then forward comparing positions (hash keys can
//                     collide; exact keys cannot, so the first entry is it);
//                     rep[soup index] = that entry's soup index — the lowest
//                     soup index at this position, as the sort is stable
//   fuse_triangles    per soup triangle: keep it unless two fused corners are
//                     the same vertex (a zero-length edge: iso equal to voxel
//                     values); flag kept triangles lying in a grid plane
//   (scan.cl)         candidates compacted: fuse_candidates writes (hash of the
//                     sorted vertex set, triangle), radix-sorted, then
//   fuse_cancel       drops pairs of opposite twins (zero-thickness sheets)
//   fuse_mark         marks the vertices kept triangles use
//   (scan.cl)         exclusive scans of the keep and referenced flags
//   fuse_compact_vertices / fuse_compact_faces   unique vertex buffer, faces
//
// Buffers (S soup vertices, T = S/3 soup triangles):
//   keys uint[S], vals uint[S] sorted pairs; pos float[3S] soup positions
//   rep uint[S]; keep, cand, cand_off, face_off uint[T]; ckeys, cvals uint[C];
//   ref uint[S], vert_id uint[S]
//   out_pos float[3V], out_faces uint[3F]

__kernel void fuse_index(uint n, __global const uint *keys, __global const uint *vals,
                         __global const float *pos, uint compare_positions,
                         __global uint *rep)
{
    GID_OR_RETURN(n);
    const uint k = keys[gid];
    uint j = gid;
    while (j > 0 && keys[j - 1] == k)
        --j;
    const uint v = vals[gid];
    uint r = vals[j];
    if (compare_positions) {
        const float x = pos[3 * v], y = pos[3 * v + 1], z = pos[3 * v + 2];
        // Terminates at gid at the latest (the entry itself).
        for (; j <= gid; ++j) {
            const uint c = vals[j];
            if (pos[3 * c] == x && pos[3 * c + 1] == y && pos[3 * c + 2] == z) {
                r = c;
                break;
            }
        }
    }
    rep[v] = r;
}

__kernel void fuse_clear(uint n, __global uint *flags)
{
    GID_OR_RETURN(n);
    flags[gid] = 0;
}

// A corner index at or past n (a broken producer) is never followed: the
// triangle is kept with no twin search, fuse_mark skips that corner and
// fuse_compact_faces writes it as 0xFFFFFFFF, which the host's check of the
// faces reports, naming the face.
__kernel void fuse_triangles(uint nt, uint n, __global const uint *rep,
                             __global const float *pos, __global uint *keep, __global uint *cand)
{
    GID_OR_RETURN(nt);
    const uint a = rep[3 * gid], b = rep[3 * gid + 1], c = rep[3 * gid + 2];
    if (a >= n || b >= n || c >= n) {
        keep[gid] = 1;
        cand[gid] = 0;
        return;
    }
    const uint k = (a != b) & (b != c) & (a != c);
    keep[gid] = k;
    // A kept triangle lying in a grid plane (one integral coordinate shared
    // by its three vertices) may have a twin from the cell on the other side.
    uint cd = 0;
    if (k) {
        for (uint ax = 0; ax < 3; ++ax) {
            const float pa = pos[3 * a + ax], pb = pos[3 * b + ax], pc = pos[3 * c + ax];
            if (pa == pb && pb == pc && pa == floor(pa))
                cd = 1;
        }
    }
    cand[gid] = cd;
}

// Sorted vertex set of a triangle and its orientation (1: (a, b, c) is an
// even permutation of the sorted set).
inline uint tri_set(uint a, uint b, uint c, uint *s0, uint *s1, uint *s2)
{
    *s0 = min(a, min(b, c));
    *s2 = max(a, max(b, c));
    *s1 = a ^ b ^ c ^ *s0 ^ *s2;
    if (a == *s0)
        return b < c;
    if (b == *s0)
        return c < a;
    return a < b;
}

__kernel void fuse_candidates(uint nt, __global const uint *rep, __global const uint *cand,
                              __global const uint *cand_off, __global uint *ckeys,
                              __global uint *cvals)
{
    GID_OR_RETURN(nt);
    if (!cand[gid])
        return;
    uint s0, s1, s2;
    tri_set(rep[3 * gid], rep[3 * gid + 1], rep[3 * gid + 2], &s0, &s1, &s2);
    const uint o = cand_off[gid];
    ckeys[o] = fuse_hash(as_float(s0), as_float(s1), as_float(s2));
    cvals[o] = gid;
}

// Opposite twins (the same three vertices, opposite winding) bound no volume:
// a sheet of zero thickness where voxel values equal iso. Within a set of
// equal triangles, the first min(n+, n−) of each winding (in soup order) are
// dropped, so what remains is manifold there.
__kernel void fuse_cancel(uint nc, __global const uint *ckeys, __global const uint *cvals,
                          __global const uint *rep, __global uint *keep)
{
    GID_OR_RETURN(nc);
    const uint k = ckeys[gid];
    uint s = gid;
    while (s > 0 && ckeys[s - 1] == k)
        --s;
    const uint t = cvals[gid];
    uint m0, m1, m2;
    const uint mine = tri_set(rep[3 * t], rep[3 * t + 1], rep[3 * t + 2], &m0, &m1, &m2);
    uint plus = 0, minus = 0, rank = 0;
    for (uint j = s; j < nc && ckeys[j] == k; ++j) {
        const uint u = cvals[j];
        uint q0, q1, q2;
        const uint o = tri_set(rep[3 * u], rep[3 * u + 1], rep[3 * u + 2], &q0, &q1, &q2);
        if (q0 != m0 || q1 != m1 || q2 != m2)
            continue;
        plus += o;
        minus += 1 - o;
        if (j < gid && o == mine)
            ++rank;
    }
    if (rank < min(plus, minus))
        keep[t] = 0;
}

__kernel void fuse_mark(uint nt, uint n, __global const uint *rep, __global const uint *keep,
                        __global uint *ref)
{
    GID_OR_RETURN(nt);
    if (keep[gid]) {
        // Benign race: every writer stores 1. Corners past n: see
        // fuse_triangles.
        for (uint q = 0; q < 3; ++q) {
            const uint v = rep[3 * gid + q];
            if (v < n)
                ref[v] = 1;
        }
    }
}

__kernel void fuse_compact_vertices(uint n, __global const uint *ref,
                                    __global const uint *vert_id, __global const float *pos,
                                    __global float *out_pos)
{
    GID_OR_RETURN(n);
    if (ref[gid]) {
        const uint o = vert_id[gid];
        out_pos[3 * o] = pos[3 * gid];
        out_pos[3 * o + 1] = pos[3 * gid + 1];
        out_pos[3 * o + 2] = pos[3 * gid + 2];
    }
}

__kernel void fuse_compact_faces(uint nt, uint n, __global const uint *rep,
                                 __global const uint *keep, __global const uint *face_off,
                                 __global const uint *vert_id, __global uint *out_faces)
{
    GID_OR_RETURN(nt);
    if (keep[gid]) {
        const uint o = face_off[gid];
        // Corners past n: see fuse_triangles.
        for (uint q = 0; q < 3; ++q) {
            const uint v = rep[3 * gid + q];
            out_faces[3 * o + q] = v < n ? vert_id[v] : 0xFFFFFFFFu;
        }
    }
}
