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
// Only the MSD pass goes through DRAM; each bucket is then sorted in the
// core's cache. Keys whose top digit is mostly the same would leave one
// work-item most of the pairs, so for those the host runs plain LSD passes
// (radix_histogram, scan, radix_scatter per digit, shift/mask picking it).
// Why this shape: docs/notes/isosurface-kernels.md.
//
// Buffers:
//   keys, values          uint[n]         caller's pairs: input, and the output
//   keys_tmp, values_tmp  uint[n]         after the MSD pass (ping-pong in radix_bucket_sort)
//   hist                  uint[RADIX*G]   top-digit counts, then (scanned) offsets
// A work-item owns one block (histogram, scatter) or one bucket (bucket sort),
// keeps its RADIX counters in a private array and streams through its data
// serially, which suits a CPU device (PoCL does not vectorise loops over
// private arrays across work-items, and need not here).
//
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
