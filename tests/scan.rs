//! Exclusive scan (and the sum alone): device vs CPU reference over sizes
//! around the work-group and chunk boundaries, in place and out of place,
//! and overflow of the total reported as an error with the output left
//! unchanged.

mod common;

use common::{download, gpu, random, upload};

use shapecue::Error;
use shapecue::cpu::scan as cpu;
use shapecue::spec::scan::{MAX_CHUNKS, MIN_CHUNK, chunking};
use shapecue::stages::scan::Scan;

/// Scans `data` on the device out of place and in place and checks both
/// against the CPU reference.
fn check(scan: &mut Scan, data: &[u32]) {
    let g = gpu();
    let n = data.len();
    let mut want = data.to_vec();
    let want_total = cpu::exclusive(&mut want).unwrap();

    let input = upload(&g, data);
    let output = g.buffer::<u32>(n).unwrap();
    assert_eq!(scan.sum(&input, n).unwrap(), want_total, "sum, n = {n}");
    let total = scan.exclusive(&input, &output, n).unwrap();
    assert_eq!(total, want_total, "n = {n}");
    assert_eq!(download(&g, &output, n), want, "out of place, n = {n}");
    assert_eq!(download(&g, &input, n), data, "input changed, n = {n}");

    let total = scan.exclusive(&input, &input, n).unwrap();
    assert_eq!(total, want_total, "in place, n = {n}");
    assert_eq!(download(&g, &input, n), want, "in place, n = {n}");
}

#[test]
fn matches_the_reference_around_every_boundary() {
    let mut scan = Scan::new(gpu()).unwrap();
    let big = MAX_CHUNKS * MIN_CHUNK; // where chunks start growing past MIN_CHUNK
    let sizes = [
        1,
        2,
        63,
        64,
        65,
        255,
        256,
        257,
        1000,
        MIN_CHUNK * 64 + 1,
        big - 1,
        big,
        big + 1,
        (1 << 20) + 7,
        3 << 20,
    ];
    for (i, &n) in sizes.iter().enumerate() {
        check(&mut scan, &random(n, 1000, 17 + i as u64));
    }
    // every chunk count path: chunking keeps chunks <= MAX_CHUNKS and covers n
    for &n in &sizes {
        let (chunk, chunks) = chunking(n);
        assert!(chunks <= MAX_CHUNKS && chunk * chunks >= n && chunk * (chunks - 1) < n);
    }
}

#[test]
fn all_zeros_all_ones_and_a_single_large_value() {
    let mut scan = Scan::new(gpu()).unwrap();
    check(&mut scan, &vec![0; 100_003]);
    check(&mut scan, &vec![1; 100_003]);
    let mut v = vec![0u32; 70_001];
    v[4242] = u32::MAX;
    check(&mut scan, &v);
}

#[test]
fn zero_values_return_zero_and_touch_nothing() {
    let g = gpu();
    let mut scan = Scan::new(g.clone()).unwrap();
    let b = upload(&g, &[7]);
    assert_eq!(scan.exclusive(&b, &b, 0).unwrap(), 0);
    assert_eq!(download(&g, &b, 1), [7]);
    assert_eq!(scan.last_ms(), 0.0);
    let mut empty: Vec<u32> = Vec::new();
    assert_eq!(cpu::exclusive(&mut empty).unwrap(), 0);
}

#[test]
fn a_total_of_exactly_u32_max_is_fine() {
    let mut scan = Scan::new(gpu()).unwrap();
    check(&mut scan, &[u32::MAX - 1, 1]);
    check(&mut scan, &[0, u32::MAX, 0]);
    // many moderate values: 2^20 × 4096 would be 2^32; one less fits
    let mut v = vec![4096u32; 1 << 20];
    v[0] = 4095;
    check(&mut scan, &v);
}

/// Overflow of the total is an error on both sides and leaves the output
/// (here the in-place input, and a separate output) unchanged.
fn assert_overflow(scan: &mut Scan, data: &[u32]) {
    let g = gpu();
    let n = data.len();
    let mut host = data.to_vec();
    assert!(matches!(
        cpu::exclusive(&mut host),
        Err(Error::InvalidInput { .. })
    ));
    assert_eq!(host, data, "the reference changed its input on overflow");

    let input = upload(&g, data);
    let output = upload(&g, &vec![0xdead_beef; n]);
    match scan.exclusive(&input, &output, n) {
        Err(e @ Error::InvalidInput { .. }) => {
            assert!(e.to_string().contains("exceeds u32::MAX"), "{e}")
        }
        other => panic!("n = {n}: expected an overflow error, got {other:?}"),
    }
    assert!(download(&g, &output, n).iter().all(|&x| x == 0xdead_beef));
    assert!(scan.exclusive(&input, &input, n).is_err());
    assert_eq!(download(&g, &input, n), data, "in-place input changed");
}

#[test]
fn overflow_of_the_total_is_an_error_not_a_wrap() {
    let mut scan = Scan::new(gpu()).unwrap();
    assert_overflow(&mut scan, &[u32::MAX, 1]);
    assert_overflow(&mut scan, &[1, u32::MAX]);
    assert_overflow(&mut scan, &[u32::MAX; 3]);
    // exactly 2^32 from many moderate values, spread over every chunk
    assert_overflow(&mut scan, &vec![4096u32; 1 << 20]);
    // values near the top, large n: the running sum would wrap many times
    assert_overflow(&mut scan, &random(300_000, 1 << 32, 5));
    // the scan still works after an overflow
    check(&mut scan, &random(5000, 1 << 16, 6));
}

#[test]
fn short_buffers_are_rejected() {
    let g = gpu();
    let mut scan = Scan::new(g.clone()).unwrap();
    let small = g.buffer::<u32>(10).unwrap();
    let large = g.buffer::<u32>(20).unwrap();
    for (a, b) in [(&small, &large), (&large, &small)] {
        match scan.exclusive(a, b, 20) {
            Err(Error::InvalidArgument(m)) => assert!(m.contains("holds 10"), "{m}"),
            other => panic!("expected InvalidArgument, got {other:?}"),
        }
    }
}

#[test]
fn kernel_time_is_reported() {
    let g = gpu();
    let mut scan = Scan::new(g.clone()).unwrap();
    let b = upload(&g, &random(100_000, 100, 9));
    scan.exclusive(&b, &b, 100_000).unwrap();
    assert!(scan.last_ms() > 0.0 && scan.last_ms().is_finite());
    assert_eq!(scan.scratch_bytes(), 8 * (MAX_CHUNKS as u64 + 1));
}
