// radix_sort.cl: stable radix sort of (uint key, uint value) pairs by the low
// key_bits bits of the keys. Host: src/stages/radix_sort.rs; CPU twin with the
// same steps: src/cpu/radix_sort.rs.
// Shared with the host (src/spec/radix_sort.rs): RADIX_BITS = DIGIT_BITS, RADIX,
// the blocks of the MSD pass (blocking(), the same split as BLOCK_RANGE).
//
// One most-significant-digit pass, then a least-significant-digit sort inside
// each bucket. The MSD pass splits the n pairs into G contiguous blocks (the
// last one shorter) and, with d = (key >> shift) & mask the top digit
// (bits [key_bits - RADIX_BITS, key_bits), or all of them for key_bits < RADIX_BITS):
//   radix_histogram    per block   hist[d*G + b] = number of keys of block b with digit d
//   (scan)                         exclusive scan of hist[0 .. RADIX*G) (kernels/scan.cl):
//                                  digit-major order puts every key with a smaller digit,
//                                  or the same digit in an earlier block, before block b's
//   radix_scatter      per block   walks block b in order: out[hist[d*G + b]++] = pair
//   radix_bucket_sort  per bucket  LSD sort of the bucket (contiguous after the scatter,
//                                  bounds read from hist) by the bits below the top digit
// Every step walks its data in input order, so the sort is stable.
//
// Only the MSD pass goes through DRAM (CPUs: docs/notes/isosurface-kernels.md);
// for skewed top digits the host runs plain LSD passes of the same kernels.
//
// Buffers:
//   keys, values          uint[n]         caller's pairs: input, and the output
//   keys_tmp, values_tmp  uint[n]         after the MSD pass (ping-pong in radix_bucket_sort)
//   hist                  uint[RADIX*G]   top-digit counts, then (scanned) offsets
// A work-item owns one block or bucket and streams through it serially with
// RADIX private counters, which suits a CPU device.
//
// On GPUs (Satish, Harris & Garland 2009) LSD passes of WG_BITS-bit digits
// run per work-group of WG work-items on tiles of TILE pairs:
//   radix_wg_histogram  per tile  digit counts in local memory: hist[d*G + g]
//   (scan)                        exclusive scan of hist
//   radix_wg_scatter    per tile  tile staged in local memory, stable local
//                                 ranks (per-item counts, work-group scan), then
//                                 out[hist[d*G + g] + rank] = pair
// Build option: -DRADIX_BITS=<digit width> (the host passes it).

#ifndef RADIX_BITS
#define RADIX_BITS 8
#endif
#define RADIX (1u << RADIX_BITS)
// Passes below the top digit for 32-bit keys.
#define MAX_LOW_PASSES ((32 - 1) / RADIX_BITS)

// [begin, end) of block `b`; written so that begin + block cannot overflow.
#define BLOCK_RANGE(b, block, n)                               \
    const uint begin = (b) * (block);                          \
    const uint end = ((n) - begin > (block)) ? begin + (block) : (n);

__kernel void radix_histogram(const uint n, const uint block, const uint blocks,
                              const uint shift, const uint mask,
                              __global const uint *keys_in, __global uint *hist)
{
    GID_OR_RETURN(blocks)
    BLOCK_RANGE(gid, block, n)
    uint count[RADIX];
    for (uint d = 0; d < RADIX; ++d)
        count[d] = 0;
    for (uint i = begin; i < end; ++i)
        count[(keys_in[i] >> shift) & mask] += 1;
    for (uint d = 0; d < RADIX; ++d)
        hist[d * blocks + gid] = count[d];
}

__kernel void radix_scatter(const uint n, const uint block, const uint blocks,
                            const uint shift, const uint mask,
                            __global const uint *keys_in, __global const uint *values_in,
                            __global const uint *hist,
                            __global uint *keys_out, __global uint *values_out)
{
    GID_OR_RETURN(blocks)
    BLOCK_RANGE(gid, block, n)
    uint next[RADIX];
    for (uint d = 0; d < RADIX; ++d)
        next[d] = hist[d * blocks + gid];
    for (uint i = begin; i < end; ++i) {
        const uint k = keys_in[i];
        const uint p = next[(k >> shift) & mask]++;
        keys_out[p] = k;
        values_out[p] = values_in[i];
    }
}

// Sorts bucket `gid` (the pairs whose top digit is gid, contiguous in
// keys_a/values_a after radix_scatter) by its low `low_bits` bits with LSD
// passes that ping-pong between the bucket's range in the a and b buffers;
// the result always ends in b. The bucket holds the same keys in every pass,
// so the counts of every pass come from one read.
__kernel void radix_bucket_sort(const uint n, const uint blocks, const uint low_bits,
                                __global const uint *hist,
                                __global uint *keys_a, __global uint *values_a,
                                __global uint *keys_b, __global uint *values_b)
{
    GID_OR_RETURN(RADIX)
    const uint begin = hist[gid * blocks];
    const uint end = gid + 1 < RADIX ? hist[(gid + 1) * blocks] : n;
    const uint passes = (low_bits + RADIX_BITS - 1) / RADIX_BITS;
    // Full digits in every pass: when low_bits is not a multiple of
    // RADIX_BITS, the last pass also sees the lowest bits of the top digit,
    // which are the same for the whole bucket (and below key_bits), so they
    // do not change the order.
    const uint mask = RADIX - 1u;
    uint count[MAX_LOW_PASSES * RADIX];
    for (uint d = 0; d < passes * RADIX; ++d)
        count[d] = 0;
    for (uint i = begin; i < end; ++i) {
        const uint k = keys_a[i];
        for (uint p = 0; p < passes; ++p)
            count[p * RADIX + ((k >> (p * RADIX_BITS)) & mask)] += 1;
    }
    __global uint *ks = keys_a;
    __global uint *vs = values_a;
    __global uint *kd = keys_b;
    __global uint *vd = values_b;
    for (uint p = 0; p < passes; ++p) {
        const uint shift = p * RADIX_BITS;
        uint *next = count + p * RADIX;
        uint run = begin;
        for (uint d = 0; d < RADIX; ++d) {
            const uint c = next[d];
            next[d] = run;
            run += c;
        }
        for (uint i = begin; i < end; ++i) {
            const uint k = ks[i];
            const uint at = next[(k >> shift) & mask]++;
            kd[at] = k;
            vd[at] = vs[i];
        }
        __global uint *t = ks;
        ks = kd;
        kd = t;
        t = vs;
        vs = vd;
        vd = t;
    }
    if (ks != keys_b) {
        // An even number of low passes (or none) left the bucket in a.
        for (uint i = begin; i < end; ++i) {
            keys_b[i] = ks[i];
            values_b[i] = vs[i];
        }
    }
}

// ---- Work-group LSD passes (GPUs). Mirrors spec::radix_sort: WG_SIZE,
// WG_ITEMS, WG_BITS. A work-item owns WG_ITEMS consecutive pairs of its tile,
// so ranking work-item by work-item, item by item, keeps the input order.
#define WG_SIZE 64
#define WG_ITEMS 16
#define WG_TILE (WG_SIZE * WG_ITEMS)
#define WG_BITS 4
#define WG_RADIX (1u << WG_BITS)

__kernel __attribute__((reqd_work_group_size(WG_SIZE, 1, 1)))
void radix_wg_histogram(const uint n, const uint shift, const uint mask,
                        __global const uint *keys_in, __global uint *hist)
{
    __local uint count[WG_RADIX];
    const uint t = (uint)get_local_id(0), g = (uint)get_group_id(0);
    const uint groups = (uint)get_num_groups(0);
    if (t < WG_RADIX)
        count[t] = 0;
    barrier(CLK_LOCAL_MEM_FENCE);
    const uint base = g * WG_TILE;
    for (uint i = 0; i < WG_ITEMS; ++i) {
        const uint at = base + i * WG_SIZE + t; // coalesced
        if (at < n)
            atomic_inc(&count[(keys_in[at] >> shift) & mask]);
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    if (t < WG_RADIX)
        hist[t * groups + g] = count[t];
}

__kernel __attribute__((reqd_work_group_size(WG_SIZE, 1, 1)))
void radix_wg_scatter(const uint n, const uint shift, const uint mask,
                      __global const uint *keys_in, __global const uint *values_in,
                      __global const uint *hist,
                      __global uint *keys_out, __global uint *values_out)
{
    __local uint tile[WG_TILE];
    __local uint rank[WG_RADIX * WG_SIZE]; // digit-major: rank[d * WG_SIZE + t]
    __local uint sums[WG_SIZE];
    const uint t = (uint)get_local_id(0), g = (uint)get_group_id(0);
    const uint groups = (uint)get_num_groups(0);
    const uint base = g * WG_TILE;
    for (uint i = 0; i < WG_ITEMS; ++i) {
        const uint at = base + i * WG_SIZE + t;
        tile[i * WG_SIZE + t] = at < n ? keys_in[at] : 0u;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    const uint mine = t * WG_ITEMS; // this work-item's first pair in the tile
    uint c[WG_RADIX];
    for (uint d = 0; d < WG_RADIX; ++d)
        c[d] = 0;
    for (uint i = 0; i < WG_ITEMS; ++i)
        if (base + mine + i < n)
            c[(tile[mine + i] >> shift) & mask] += 1;
    for (uint d = 0; d < WG_RADIX; ++d)
        rank[d * WG_SIZE + t] = c[d];
    barrier(CLK_LOCAL_MEM_FENCE);
    // Exclusive scan of rank[] (WG_RADIX * WG_SIZE entries): each work-item
    // its WG_RADIX consecutive entries, then the work-items' sums.
    uint run = 0;
    for (uint j = 0; j < WG_RADIX; ++j) {
        const uint v = rank[t * WG_RADIX + j];
        rank[t * WG_RADIX + j] = run;
        run += v;
    }
    sums[t] = run;
    barrier(CLK_LOCAL_MEM_FENCE);
    if (t == 0) {
        uint r = 0;
        for (uint s = 0; s < WG_SIZE; ++s) {
            const uint v = sums[s];
            sums[s] = r;
            r += v;
        }
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint j = 0; j < WG_RADIX; ++j)
        rank[t * WG_RADIX + j] += sums[t];
    barrier(CLK_LOCAL_MEM_FENCE);
    // Digit d of this work-item goes to the tile's slots for d (from the
    // scanned histogram) plus the pairs of d before it in the tile.
    for (uint d = 0; d < WG_RADIX; ++d)
        c[d] = hist[d * groups + g] + rank[d * WG_SIZE + t] - rank[d * WG_SIZE];
    for (uint i = 0; i < WG_ITEMS; ++i) {
        const uint at = base + mine + i;
        if (at < n) {
            const uint k = tile[mine + i];
            const uint to = c[(k >> shift) & mask]++;
            keys_out[to] = k;
            values_out[to] = values_in[at];
        }
    }
}
