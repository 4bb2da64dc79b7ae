//! CPU reference of `kernels/radix_sort.cl`: stable radix sort of (`u32` key,
//! `u32` value) pairs by the low `key_bits` bits of the keys, with the
//! device's steps and data layout: one most-significant-digit pass over the
//! top digit — per-block `histogram` (digit-major: `hist[d × blocks + b]`),
//! exclusive `scan` of the counts ([`crate::cpu::scan`]), in-order `scatter`
//! — then `bucket_sort`, an LSD sort of each bucket by the bits below the top
//! digit. The block length is a parameter: any length gives the same (stable)
//! result, and the device's ([`blocking`]) reproduces its histogram.
//!
//! [`blocking`]: crate::spec::radix_sort::blocking

use crate::error::{Error, Result};
use crate::spec::radix_sort::{DIGIT_BITS, RADIX, digits};

/// Digit of `key` at bit `shift`, under `mask`.
fn digit(key: u32, shift: u32, mask: u32) -> usize {
    ((key >> shift) & mask) as usize
}

/// Per-block digit counts of `keys` split into blocks of `block` keys, in
/// digit-major order: entry `d × blocks + b` counts the keys of block `b`
/// whose digit is `d`. Returns the counts and the number of blocks.
pub fn histogram(keys: &[u32], block: usize, shift: u32, mask: u32) -> (Vec<u32>, usize) {
    let block = block.max(1);
    let blocks = keys.len().div_ceil(block);
    let mut hist = vec![0u32; RADIX * blocks];
    for (b, chunk) in keys.chunks(block).enumerate() {
        for &k in chunk {
            hist[digit(k, shift, mask) * blocks + b] += 1;
        }
    }
    (hist, blocks)
}

/// Moves each pair of block `b`, in order, to `next[d × blocks + b]` (then
/// increments it), where `next` is the exclusive scan of [`histogram`].
// Mirrors radix_scatter of kernels/radix_sort.cl argument for argument (n
// and blocks from the slices).
#[allow(clippy::too_many_arguments)]
pub fn scatter(
    keys: &[u32],
    values: &[u32],
    block: usize,
    shift: u32,
    mask: u32,
    next: &mut [u32],
    keys_out: &mut [u32],
    values_out: &mut [u32],
) {
    let block = block.max(1);
    let blocks = keys.len().div_ceil(block);
    for (i, (&k, &v)) in keys.iter().zip(values).enumerate() {
        let slot = &mut next[digit(k, shift, mask) * blocks + i / block];
        keys_out[*slot as usize] = k;
        values_out[*slot as usize] = v;
        *slot += 1;
    }
}

/// Sorts one bucket (all its keys share the top digit) by its low `low_bits`
/// bits: LSD passes of [`DIGIT_BITS`] bits, each a counting sort walking the
/// pairs in order.
pub fn bucket_sort(keys: &mut [u32], values: &mut [u32], low_bits: u32) {
    let mut keys_tmp = vec![0u32; keys.len()];
    let mut values_tmp = vec![0u32; keys.len()];
    let mut shift = 0;
    while shift < low_bits {
        let mask = (1u32 << (low_bits - shift).min(DIGIT_BITS)) - 1;
        let mut next = vec![0u32; RADIX];
        for &k in keys.iter() {
            next[digit(k, shift, mask)] += 1;
        }
        let mut run = 0;
        for c in next.iter_mut() {
            (*c, run) = (run, run + *c);
        }
        for (&k, &v) in keys.iter().zip(values.iter()) {
            let slot = &mut next[digit(k, shift, mask)];
            keys_tmp[*slot as usize] = k;
            values_tmp[*slot as usize] = v;
            *slot += 1;
        }
        keys.copy_from_slice(&keys_tmp);
        values.copy_from_slice(&values_tmp);
        shift += DIGIT_BITS;
    }
}

/// Sorts the pairs by `key & (2^key_bits − 1)`, stably, in place, with MSD
/// blocks of `block` pairs. Errors with [`Error::InvalidArgument`] when the
/// slices differ in length, `key_bits > 32` or there are more than
/// `u32::MAX` pairs.
pub fn sort_pairs(keys: &mut [u32], values: &mut [u32], key_bits: u32, block: usize) -> Result<()> {
    if keys.len() != values.len() || key_bits > 32 || keys.len() > u32::MAX as usize {
        return Err(Error::InvalidArgument(format!(
            "radix sort reference: {} keys, {} values, key_bits {key_bits}",
            keys.len(),
            values.len()
        )));
    }
    if key_bits == 0 || keys.is_empty() {
        return Ok(());
    }
    let (top, low) = digits(key_bits);
    let mask = (1u32 << top) - 1;
    let (mut next, blocks) = histogram(keys, block, low, mask);
    crate::cpu::scan::exclusive(&mut next)?;
    // bucket d starts where its first block's slot does
    let starts: Vec<usize> = (0..RADIX).map(|d| next[d * blocks] as usize).collect();
    let mut keys_out = vec![0u32; keys.len()];
    let mut values_out = vec![0u32; keys.len()];
    scatter(
        keys,
        values,
        block,
        low,
        mask,
        &mut next,
        &mut keys_out,
        &mut values_out,
    );
    for d in 0..RADIX {
        let end = starts.get(d + 1).copied().unwrap_or(keys.len());
        let range = starts[d]..end;
        bucket_sort(&mut keys_out[range.clone()], &mut values_out[range], low);
    }
    keys.copy_from_slice(&keys_out);
    values.copy_from_slice(&values_out);
    Ok(())
}
