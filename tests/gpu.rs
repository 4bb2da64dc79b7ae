//! The OpenCL layer: device discovery and program building.

use shapecue::Error;
use shapecue::gpu::{Gpu, KernelFile, kernel_file, list_devices};

#[test]
fn devices_are_listed_with_their_capabilities() {
    let devs = list_devices().expect("an OpenCL platform (PoCL) is installed");
    assert!(!devs.is_empty());
    for (i, d) in devs.iter().enumerate() {
        assert_eq!(d.index, i);
        assert!(d.compute_units > 0 && d.global_mem > 0, "{d:?}");
    }
}

#[test]
fn a_build_failure_returns_the_file_and_the_build_log() {
    let gpu = Gpu::new(None).unwrap();
    let bad = KernelFile {
        name: "kernels/broken.cl",
        source: "__kernel void k(__global float *x) {\n  x[0] = undefined_thing;\n}\n",
        headers: &[],
    };
    match gpu.program(&bad, "") {
        Err(Error::Build { file, log, .. }) => {
            assert_eq!(file, "kernels/broken.cl");
            assert!(log.contains("undefined_thing"), "log: {log}");
            // the #line marker makes the log point at the real file and line
            assert!(log.contains("broken.cl:2"), "log: {log}");
        }
        other => panic!("expected a build error, got {other:?}"),
    }
}

#[test]
fn every_embedded_kernel_family_builds_in_every_variant() {
    let gpu = Gpu::new(None).unwrap();
    let f = kernel_file("curvature").unwrap();
    // Without SC_GATHER the program holds the atomic scheme's kernels, with
    // it the gather scheme's (per-face kernels on 1 or 16 lanes).
    for opts in [
        "",
        "-DSC_COMPAT",
        "-DSC_DOUBLE",
        "-DSC_DOUBLE -DSC_COMPAT",
        "-DSC_GATHER",
        "-DSC_GATHER -DSC_LANES=16",
        "-DSC_GATHER -DSC_DOUBLE -DSC_COMPAT",
    ] {
        if opts.contains("DOUBLE") && !gpu.info.fp64 {
            continue;
        }
        gpu.program(&f, opts)
            .unwrap_or_else(|e| panic!("{opts}: {e}"));
        // built once per process: the second request is the cached program
        let a = gpu.program(&f, opts).unwrap();
        let b = gpu.program(&f, opts).unwrap();
        assert!(std::sync::Arc::ptr_eq(&a, &b));
    }
    assert!(kernel_file("nonexistent").is_none());
}

/// `Gpu::zero` fills with the widest pattern that divides the length; every
/// length and element size clears exactly the first `len` elements.
#[test]
fn zero_clears_exactly_the_first_len_elements() {
    let gpu = Gpu::new(None).unwrap();
    fn check<T: bytemuck::Pod + PartialEq + std::fmt::Debug>(gpu: &Gpu, one: T) {
        let total = 700;
        for len in [
            1usize, 2, 3, 7, 8, 31, 32, 33, 64, 96, 128, 129, 256, 513, 640, 700,
        ] {
            let mut b = gpu.buffer::<T>(total).unwrap();
            gpu.write(&mut b, &vec![one; total]).unwrap();
            gpu.zero(&mut b, len).unwrap();
            let mut out = vec![one; total];
            gpu.read(&b, &mut out).unwrap();
            let zero = T::zeroed();
            assert!(out[..len].iter().all(|v| *v == zero), "{len}: {out:?}");
            assert!(out[len..].iter().all(|v| *v == one), "{len}: past the end");
        }
    }
    check::<u8>(&gpu, 7);
    check::<u32>(&gpu, 0xdead_beef);
    check::<f64>(&gpu, 1.5);
    check::<[u8; 3]>(&gpu, [1, 2, 3]);
    check::<[u32; 3]>(&gpu, [1, 2, 3]);
}
