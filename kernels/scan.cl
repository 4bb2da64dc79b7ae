// scan.cl: exclusive prefix sum of n uints (out[i] = in[0] + ... + in[i-1]),
// in place or out of place, with the total in 64 bits so that a sum past
// UINT_MAX is reported instead of wrapping. Host: src/stages/scan.rs; CPU
// twin: src/cpu/scan.rs.
// Shared with the host (src/spec/scan.rs): the chunking (chunking(), the same
// split as CHUNK_RANGE) and the partials length (MAX_CHUNKS).
//
// Reduce-then-scan over C contiguous chunks of `chunk` elements each (the
// last one shorter), C at most a few thousand, chosen by the host:
//   scan_block_sums  per chunk   partials[c] = Σ in[chunk c], serially
//   scan_partials    one item    exclusive scan of partials[0..C) in place; total[0] = Σ
//   scan_apply       per chunk   rescans chunk c from partials[c], writing out;
//                                does nothing when total[0] > UINT_MAX
// Contiguous chunks walked serially suit a CPU device (each work-item streams
// through its own cache lines; PoCL runs the work-items of a group one after
// another). A GPU would want interleaved chunks and a work-group scan instead.
//
// Buffers:
//   in        uint[n]   values (may be the same buffer as out)
//   out       uint[n]   exclusive prefix sums
//   partials  ulong[C]  chunk sums, then chunk offsets
//   total     ulong[1]  sum of all n values
// in and out may alias, so neither is `restrict`: a work-item reads in[i]
// before it writes out[i], and no two work-items touch the same element.

// [begin, end) of chunk `c`; written so that begin + chunk cannot overflow.
#define CHUNK_RANGE(c, chunk, n)                               \
    const uint begin = (c) * (chunk);                          \
    const uint end = ((n) - begin > (chunk)) ? begin + (chunk) : (n);

__kernel void scan_block_sums(const uint n, const uint chunk, const uint chunks,
                              __global const uint *in, __global ulong *partials)
{
    GID_OR_RETURN(chunks)
    CHUNK_RANGE(gid, chunk, n)
    // A chunk of up to 2^32 values below 2^32 fits a ulong; so does the total.
    ulong s = 0;
    for (uint i = begin; i < end; ++i)
        s += in[i];
    partials[gid] = s;
}

// A few thousand partials: one work-item scans them serially (microseconds);
// the host caps C so this never needs a second level.
__kernel void scan_partials(const uint chunks, __global ulong *partials,
                            __global ulong *total)
{
    GID_OR_RETURN(1)
    ulong run = 0;
    for (uint c = 0; c < chunks; ++c) {
        const ulong v = partials[c];
        partials[c] = run;
        run += v;
    }
    total[0] = run;
}

__kernel void scan_apply(const uint n, const uint chunk, const uint chunks,
                         __global const uint *in, __global uint *out,
                         __global const ulong *partials, __global const ulong *total)
{
    GID_OR_RETURN(chunks)
    // Overflow: leave `out` (and so an in-place input) untouched; the host
    // reads the total and reports it.
    if (total[0] > (ulong)UINT_MAX) return;
    CHUNK_RANGE(gid, chunk, n)
    uint run = (uint)partials[gid];
    for (uint i = begin; i < end; ++i) {
        const uint v = in[i];
        out[i] = run;
        run += v;
    }
}
