//! Radix sort of (key, value) pairs: device vs CPU reference vs `std`'s
//! stable `sort_by_key`, with values = original index so that stability is
//! checked exactly. Sizes around the work-group and block boundaries; random,
//! all-equal, sorted and reverse-sorted keys; key widths 8/16/24/32 and odd
//! widths; keys with bits set above `key_bits` (only the low bits order the
//! pairs, the high bits travel with them); keys that all share their top
//! digit (one bucket holds everything).

mod common;

use common::{download, gpu, random, upload};

use shapecue::Error;
use shapecue::cpu::radix_sort as cpu;
use shapecue::spec::radix_sort::{MAX_BLOCKS, MIN_BLOCK, Strategy, blocking, digits};
use shapecue::stages::radix_sort::RadixSort;

/// `n` deterministic 32-bit keys.
fn random_keys(n: usize, seed: u64) -> Vec<u32> {
    random(n, 1 << 32, seed)
}

const SIZES: [usize; 9] = [0, 1, 2, 63, 64, 65, 1000, MIN_BLOCK * 3 + 1, (1 << 20) + 7];

/// The key patterns every size is tested with.
fn patterns(n: usize, seed: u64) -> Vec<(&'static str, Vec<u32>)> {
    let random = random_keys(n, seed);
    let mut sorted = random.clone();
    sorted.sort_unstable();
    let reverse: Vec<u32> = sorted.iter().rev().copied().collect();
    // few distinct keys: long runs of equal keys in every bucket
    let few: Vec<u32> = random.iter().map(|k| k % 7 * 0x0101_0101).collect();
    // one top digit: every pair in one bucket (one work-item sorts them all)
    let one_bucket: Vec<u32> = random.iter().map(|k| k & 0x00ff_ffff).collect();
    vec![
        ("random", random),
        ("all equal", vec![0xabcd_1234; n]),
        ("sorted", sorted),
        ("reverse", reverse),
        ("few distinct", few),
        ("one top digit", one_bucket),
    ]
}

/// What a stable sort by the low `key_bits` bits gives, from `std`.
fn expected(keys: &[u32], key_bits: u32) -> (Vec<u32>, Vec<u32>) {
    let mask = if key_bits == 32 {
        u32::MAX
    } else {
        (1u32 << key_bits) - 1
    };
    let mut pairs: Vec<(u32, u32)> = keys.iter().copied().zip(0..).collect();
    pairs.sort_by_key(|&(k, _)| k & mask); // stable
    pairs.into_iter().unzip()
}

/// Sorts `keys` (values = original index) on the device and with the CPU
/// reference and checks both against `std`.
fn check(sorter: &mut RadixSort, what: &str, keys: &[u32], key_bits: u32) {
    let g = gpu();
    let n = keys.len();
    let (want_keys, want_values) = expected(keys, key_bits);
    let index: Vec<u32> = (0..n as u32).collect();

    let (mut ck, mut cv) = (keys.to_vec(), index.clone());
    cpu::sort_pairs(&mut ck, &mut cv, key_bits, blocking(n).0).unwrap();
    assert!(
        ck == want_keys && cv == want_values,
        "cpu: {what}, n = {n}, bits = {key_bits}"
    );

    let (mut kb, mut vb) = (upload(&g, keys), upload(&g, &index));
    sorter.sort_pairs(&mut kb, &mut vb, n, key_bits).unwrap();
    let (dk, dv) = (download(&g, &kb, n), download(&g, &vb, n));
    if dk != want_keys || dv != want_values {
        let first = (0..n).find(|&i| dk[i] != want_keys[i] || dv[i] != want_values[i]);
        panic!(
            "device: {what}, n = {n}, bits = {key_bits}: first difference at {first:?}: \
             got {:?}, want {:?}",
            first.map(|i| (dk[i], dv[i])),
            first.map(|i| (want_keys[i], want_values[i]))
        );
    }
}

#[test]
fn every_size_and_pattern_with_32_bit_keys() {
    let mut sorter = RadixSort::new(gpu()).unwrap();
    for (i, &n) in SIZES.iter().enumerate() {
        for (what, keys) in patterns(n, 100 + i as u64) {
            check(&mut sorter, what, &keys, 32);
        }
    }
}

#[test]
fn key_widths_8_16_24_and_odd_ones() {
    let mut sorter = RadixSort::new(gpu()).unwrap();
    for (i, &n) in SIZES.iter().enumerate() {
        let keys = random_keys(n, 200 + i as u64);
        for bits in [8, 16, 24] {
            // keys already below 2^bits, and full 32-bit keys whose high bits must be ignored
            let low: Vec<u32> = keys.iter().map(|k| k >> (32 - bits)).collect();
            check(&mut sorter, "random below 2^bits", &low, bits);
            check(&mut sorter, "high bits set", &keys, bits);
        }
    }
    // widths that end mid-digit (passes with a partial mask) and the extremes
    let keys = random_keys(100_003, 7);
    for bits in [1, 5, 12, 13, 20, 31] {
        check(&mut sorter, "odd width, high bits set", &keys, bits);
    }
}

#[test]
fn high_bits_beyond_key_bits_do_not_order_the_pairs() {
    // 12-bit keys whose bits 12..32 are noise: pass 2 must look only at bits 8..12
    let mut sorter = RadixSort::new(gpu()).unwrap();
    let n = 50_000;
    let noise = random_keys(n, 11);
    let keys: Vec<u32> = (0..n as u32)
        .map(|i| (noise[i as usize] & !0xfff) | ((n as u32 - i) % 4096))
        .collect();
    check(&mut sorter, "12-bit keys with noise above", &keys, 12);
    // and the sort leaves the high bits in place
    let g = gpu();
    let (mut kb, mut vb) = (upload(&g, &keys), upload(&g, &vec![0; n]));
    sorter.sort_pairs(&mut kb, &mut vb, n, 12).unwrap();
    let mut got = download(&g, &kb, n);
    let mut orig = keys.clone();
    got.sort_unstable();
    orig.sort_unstable();
    assert_eq!(got, orig);
}

#[test]
fn zero_key_bits_leaves_the_pairs_alone() {
    let g = gpu();
    let mut sorter = RadixSort::new(g.clone()).unwrap();
    let keys = random_keys(1000, 3);
    let (mut kb, mut vb) = (
        upload(&g, &keys),
        upload(&g, &(0..1000).collect::<Vec<_>>()),
    );
    sorter.sort_pairs(&mut kb, &mut vb, 1000, 0).unwrap();
    assert_eq!(download(&g, &kb, 1000), keys);
    assert_eq!(digits(0), (0, 0));
    assert_eq!(digits(5), (5, 0));
    assert_eq!(digits(32), (8, 24));
}

#[test]
fn only_the_first_n_pairs_are_sorted() {
    let g = gpu();
    let mut sorter = RadixSort::new(g.clone()).unwrap();
    let keys = random_keys(5000, 4);
    let (mut kb, mut vb) = (
        upload(&g, &keys),
        upload(&g, &(0..5000).collect::<Vec<_>>()),
    );
    sorter.sort_pairs(&mut kb, &mut vb, 3000, 32).unwrap();
    let got = download(&g, &kb, 5000);
    assert_eq!(got[..3000], expected(&keys[..3000], 32).0[..]);
    assert_eq!(got[3000..], keys[3000..]);
}

#[test]
fn scratch_grows_and_is_reused() {
    let g = gpu();
    let mut sorter = RadixSort::new(g.clone()).unwrap();
    let big = MIN_BLOCK * MAX_BLOCKS + 5;
    check(&mut sorter, "small first", &random_keys(1000, 1), 32);
    let small_bytes = sorter.scratch_bytes();
    check(&mut sorter, "then big", &random_keys(big, 2), 32);
    let big_bytes = sorter.scratch_bytes();
    assert!(big_bytes >= 8 * big as u64 && big_bytes > small_bytes);
    check(&mut sorter, "then small again", &random_keys(70_000, 3), 24);
    assert_eq!(sorter.scratch_bytes(), big_bytes);
    assert!(sorter.last_ms() > 0.0 && sorter.last_ms().is_finite());
}

#[test]
fn bad_arguments_are_errors() {
    let g = gpu();
    let mut sorter = RadixSort::new(g.clone()).unwrap();
    let mut k = g.buffer::<u32>(10).unwrap();
    let mut v = g.buffer::<u32>(20).unwrap();
    assert!(matches!(
        sorter.sort_pairs(&mut k, &mut v, 10, 33),
        Err(Error::InvalidArgument(_))
    ));
    match sorter.sort_pairs(&mut k, &mut v, 20, 32) {
        Err(Error::InvalidArgument(m)) => assert!(m.contains("keys buffer holds 10"), "{m}"),
        other => panic!("expected InvalidArgument, got {other:?}"),
    }
    let (mut a, mut b) = (vec![1u32; 3], vec![0u32; 2]);
    assert!(cpu::sort_pairs(&mut a, &mut b, 32, 1).is_err());
}

#[test]
fn the_cpu_reference_gives_the_same_result_for_any_block_length() {
    let keys = random_keys(10_007, 9);
    let (want_keys, want_values) = expected(&keys, 32);
    for block in [1, 7, 64, 1000, 10_007, 20_000] {
        let (mut k, mut v) = (keys.clone(), (0..10_007).collect::<Vec<u32>>());
        cpu::sort_pairs(&mut k, &mut v, 32, block).unwrap();
        assert!(k == want_keys && v == want_values, "block {block}");
    }
}

#[test]
fn skewed_keys_take_the_lsd_path_and_spread_keys_the_bucket_path() {
    let mut sorter = RadixSort::new(gpu()).unwrap();
    // the CPU devices' choice per call (GPUs default to work-groups)
    sorter.set_strategy(None);
    let n = (1 << 20) + 7;
    let keys = random_keys(n, 12);
    check(&mut sorter, "random", &keys, 32);
    assert_eq!(sorter.last_strategy(), Some(Strategy::Buckets));
    for (what, keys) in patterns(n, 13).into_iter().skip(1) {
        check(&mut sorter, what, &keys, 32);
        let want = match what {
            "sorted" | "reverse" => Strategy::Buckets,
            _ => Strategy::Lsd, // all equal, 7 distinct keys, one top digit
        };
        assert_eq!(sorter.last_strategy(), Some(want), "{what}");
    }
    // both paths with a key width that is not a multiple of 8 (odd pass count: copy back)
    let low: Vec<u32> = keys.iter().map(|k| k & 0x000f_ffff).collect();
    check(&mut sorter, "20-bit keys, noise above", &keys, 20);
    assert_eq!(sorter.last_strategy(), Some(Strategy::Buckets));
    check(&mut sorter, "20-bit keys under key_bits = 28", &low, 28);
    assert_eq!(sorter.last_strategy(), Some(Strategy::Lsd));
    // 18-bit keys: four top digits under key_bits = 24; three LSD passes end with a copy
    let low18: Vec<u32> = keys.iter().map(|k| k & 0x0003_ffff).collect();
    check(&mut sorter, "18-bit keys under key_bits = 24", &low18, 24);
    assert_eq!(sorter.last_strategy(), Some(Strategy::Lsd));
    check(&mut sorter, "nothing to do", &low[..1], 24);
    assert_eq!(sorter.last_strategy(), None);
}

/// The GPU strategy (work-group tiles, local ranks, 4-bit LSD passes) and the
/// plain LSD passes, forced on whatever device runs the tests: every size,
/// pattern and key width gives `std`'s stable order.
#[test]
fn work_group_and_lsd_strategies_sort_every_size_pattern_and_width() {
    for strategy in [Strategy::WorkGroups, Strategy::Lsd] {
        let mut sorter = RadixSort::new(gpu()).unwrap();
        sorter.set_strategy(Some(strategy));
        for (i, &n) in SIZES.iter().enumerate() {
            for (what, keys) in patterns(n, 300 + i as u64) {
                check(&mut sorter, what, &keys, 32);
                if n >= 2 {
                    assert_eq!(sorter.last_strategy(), Some(strategy), "{what}");
                }
            }
        }
        let keys = random_keys(100_003, 9);
        for bits in [1, 4, 5, 8, 12, 13, 20, 24, 31] {
            check(&mut sorter, "odd width, high bits set", &keys, bits);
        }
        // tiles that end mid-tile and sizes around a tile
        for n in [1023, 1024, 1025, 4097] {
            check(&mut sorter, "around a tile", &random_keys(n, n as u64), 32);
        }
    }
}
