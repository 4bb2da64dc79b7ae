// radix_sort.cl: one pass of a stable least-significant-digit radix sort of
// (uint key, uint value) pairs. Host: src/stages/radix_sort.rs (runs one pass
// per RADIX_BITS-bit digit, ping-ponging between the caller's buffers and
// scratch); CPU twin with the same steps: src/cpu/radix_sort.rs.
//
// The n pairs are split into G contiguous blocks of `block` pairs (the last
// one shorter). Per pass, with d = (key >> shift) & mask:
//   radix_histogram  per block  hist[d*G + b] = number of keys of block b with digit d
//   (scan)                      exclusive scan of hist[0 .. RADIX*G) (kernels/scan.cl):
//                               digit-major order puts every key with a smaller digit,
//                               or the same digit in an earlier block, before block b's
//   radix_scatter    per block  walks block b in order, out[hist[d*G + b]++] = pair
// Walking each block in input order makes the pass stable, and so the sort.
// `mask` is RADIX - 1 except on the last pass of a key width that is not a
// multiple of RADIX_BITS, so bits above the requested width never take part.
//
// Buffers:
//   keys_in, values_in    uint[n]        pairs before the pass
//   keys_out, values_out  uint[n]        pairs after the pass
//   hist                  uint[RADIX*G]  digit counts, then (after the scan) offsets
// One work-item owns one block: it keeps RADIX counters in a private array
// and streams through its block serially, which suits a CPU device (PoCL does
// not vectorise loops over private arrays across work-items; it need not).
//
// Build option: -DRADIX_BITS=<bits per pass> (the host passes it).

#ifndef RADIX_BITS
#define RADIX_BITS 8
#endif
#define RADIX (1u << RADIX_BITS)

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
