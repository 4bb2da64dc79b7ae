//! Radix sort and scan benches (`kernels/radix_sort.cl` ↔
//! `src/stages/radix_sort.rs`, `kernels/scan.cl` ↔ `src/stages/scan.rs`).
//!
//! Groups, for n = 1M (2^20) and 8M (2^23) random inputs already on the device:
//! - `radix_sort/device/<n>`: kernel time of one sort of n (u32 key, u32 value)
//!   pairs by 32-bit keys, from OpenCL profiling events
//!   ([`RadixSort::last_ms`]); the unsorted input is restored by a device
//!   copy before every sort, outside the timing.
//! - `radix_sort/device-wall/<n>`: host wall time of the same call (enqueue
//!   to finish).
//! - `scan/device/<n>`, `scan/device-wall/<n>`: the same for an out-of-place
//!   exclusive scan of n u32 values below 256 (total read back included).
//!
//! A warm-up call before each group pays for JIT compilation.
//! `SHAPECUE_DEVICE` picks the device as for the CLI.

mod common;

use criterion::measurement::WallTime;
use criterion::{
    BenchmarkGroup, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use opencl3::memory::Buffer;
use shapecue::gpu::Gpu;
use shapecue::mesh::splitmix;
use shapecue::spec::radix_sort::Strategy;
use shapecue::stages::radix_sort::RadixSort;
use shapecue::stages::scan::Scan;
use std::time::{Duration, Instant};

const SIZES: [(&str, usize); 2] = [("1m", 1 << 20), ("8m", 8 << 20)];

fn random(n: usize, bound: f64, seed: u64) -> Vec<u32> {
    let mut s = seed;
    (0..n).map(|_| (splitmix(&mut s) * bound) as u32).collect()
}

fn upload(gpu: &Gpu, data: &[u32]) -> Buffer<u32> {
    let mut b = gpu.buffer::<u32>(data.len()).expect("allocation");
    gpu.write(&mut b, data).expect("upload");
    b
}

fn configure(g: &mut BenchmarkGroup<'_, WallTime>, n: usize) {
    let big = n > 2 << 20;
    g.sample_size(if big { 10 } else { 20 })
        .sampling_mode(if big {
            SamplingMode::Flat
        } else {
            SamplingMode::Linear
        })
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(if big { 12 } else { 6 }))
        .throughput(Throughput::Elements(n as u64));
}

/// A sort of n pairs with its pristine input on the device.
struct SortInput {
    keys0: Buffer<u32>,
    values0: Buffer<u32>,
    keys: Buffer<u32>,
    values: Buffer<u32>,
    n: usize,
}

impl SortInput {
    fn new(gpu: &Gpu, n: usize) -> SortInput {
        let keys = random(n, 4294967296.0, 42);
        let index: Vec<u32> = (0..n as u32).collect();
        SortInput {
            keys0: upload(gpu, &keys),
            values0: upload(gpu, &index),
            keys: upload(gpu, &keys),
            values: upload(gpu, &index),
            n,
        }
    }

    /// Restores the unsorted pairs (device copy, finished before returning).
    fn restore(&mut self, gpu: &Gpu) {
        let bytes = self.n * 4;
        // SAFETY: all four buffers hold n elements.
        unsafe {
            let q = gpu.queue();
            q.enqueue_copy_buffer(&self.keys0, &mut self.keys, 0, 0, bytes, &[])
                .expect("copy");
            q.enqueue_copy_buffer(&self.values0, &mut self.values, 0, 0, bytes, &[])
                .expect("copy");
        }
        gpu.finish().expect("finish");
    }

    /// Runs `iters` sorts; returns (kernel time, wall time).
    fn run(&mut self, gpu: &Gpu, sorter: &mut RadixSort, iters: u64) -> (Duration, Duration) {
        let (mut kernel_ms, mut wall) = (0.0, Duration::ZERO);
        for _ in 0..iters {
            self.restore(gpu);
            let t0 = Instant::now();
            sorter
                .sort_pairs(&mut self.keys, &mut self.values, self.n, 32)
                .expect("sort");
            wall += t0.elapsed();
            kernel_ms += sorter.last_ms();
        }
        (Duration::from_secs_f64(kernel_ms * 1e-3), wall)
    }
}

fn benches(c: &mut Criterion) {
    let Some(gpu) = common::gpu("radix_sort") else {
        return;
    };
    let mut sorter = RadixSort::new(gpu.clone()).expect("radix sort kernels");
    let mut scan = Scan::new(gpu.clone()).expect("scan kernels");

    for (name, n) in SIZES {
        let mut input = SortInput::new(&gpu, n);
        let (k, w) = input.run(&gpu, &mut sorter, 2); // JIT warm-up
        eprintln!(
            "radix_sort bench: {name}: warm-up (2 sorts) kernel {:.1} ms, wall {:.1} ms, scratch {} MiB",
            k.as_secs_f64() * 1e3,
            w.as_secs_f64() * 1e3,
            sorter.scratch_bytes() >> 20
        );
        // The device's own strategy (buckets or LSD per call on CPU devices,
        // work-groups on GPUs), then each strategy forced, kernel time.
        let default = sorter.last_strategy();
        for (variant, wall, strategy) in [
            ("device", false, None),
            ("device-wall", true, None),
            ("work-groups", false, Some(Strategy::WorkGroups)),
            ("lsd", false, Some(Strategy::Lsd)),
        ] {
            match strategy {
                Some(s) => sorter.set_strategy(Some(s)),
                None if default == Some(Strategy::WorkGroups) => {
                    sorter.set_strategy(Some(Strategy::WorkGroups))
                }
                None => sorter.set_strategy(None),
            }
            if strategy.is_some() {
                input.run(&gpu, &mut sorter, 1); // JIT warm-up
            }
            let mut g = c.benchmark_group("radix_sort");
            configure(&mut g, n);
            g.bench_function(format!("{variant}/{name}"), |b| {
                b.iter_custom(|iters| {
                    let (k, w) = input.run(&gpu, &mut sorter, iters);
                    if wall { w } else { k }
                })
            });
            g.finish();
        }
        sorter.set_strategy(if default == Some(Strategy::WorkGroups) {
            default
        } else {
            None
        });
        drop(input);

        let values = upload(&gpu, &random(n, 256.0, 43));
        let output = gpu.buffer::<u32>(n).expect("allocation");
        scan.exclusive(&values, &output, n).expect("scan"); // JIT warm-up
        for (variant, wall) in [("device", false), ("device-wall", true)] {
            let mut g = c.benchmark_group("scan");
            configure(&mut g, n);
            g.bench_function(format!("{variant}/{name}"), |b| {
                b.iter_custom(|iters| {
                    let (mut kernel_ms, mut w) = (0.0, Duration::ZERO);
                    for _ in 0..iters {
                        let t0 = Instant::now();
                        scan.exclusive(&values, &output, n).expect("scan");
                        w += t0.elapsed();
                        kernel_ms += scan.last_ms();
                    }
                    if wall {
                        w
                    } else {
                        Duration::from_secs_f64(kernel_ms * 1e-3)
                    }
                })
            });
            g.finish();
        }
    }
}

criterion_group!(radix_sort_benches, benches);
criterion_main!(radix_sort_benches);
