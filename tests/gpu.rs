//! The OpenCL layer: device discovery and program building.

use shapecue::Error;
use shapecue::gpu::{Gpu, KernelFile, list_devices};
use shapecue::spec::kernels::KernelEntry;
use shapecue::stages::kernel_files;

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
        includes: &[],
    };
    match gpu.program(&bad, "") {
        Err(Error::Build { file, log, .. }) => {
            assert_eq!(file, "kernels/broken.cl");
            // The compiler's own message, in whatever form its driver
            // writes it (clang-based CPU runtimes and NVIDIA's differ).
            assert!(log.contains("undefined_thing"), "log: {log}");
            // Where the log names the file, the #line marker makes it the
            // real file and line: `broken.cl:2:` (clang) or `broken.cl(2)`.
            if log.contains("broken.cl") {
                assert!(
                    ["broken.cl:2", "broken.cl(2)", "broken.cl\", line 2"]
                        .iter()
                        .any(|f| log.contains(f)),
                    "log: {log}"
                );
            }
        }
        other => panic!("expected a build error, got {other:?}"),
    }
}

#[test]
fn every_embedded_kernel_family_builds_in_every_variant() {
    let gpu = Gpu::new(None).unwrap();
    let f = kernel_files::CURVATURE;
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

/// Every family's kernel file builds, and every entry point its kernel enum
/// names exists in it, so a renamed kernel fails here and not at a launch.
#[test]
fn every_kernel_file_builds_and_holds_every_entry_its_enum_names() {
    use shapecue::spec::{
        ao::AoKernel, curvature::CurvKernel, edges::EdgesKernel, feature_lines::LinesKernel,
        marching_cubes::McKernel, mesh_sdf::MsdfKernel, radix_sort::RadixKernel, scan::ScanKernel,
        sdf_lines::SdflKernel, skinning::SkinKernel, vertex_fusion::FuseKernel,
    };
    fn names<K: KernelEntry>(all: &[K]) -> Vec<&'static str> {
        all.iter().map(|k| k.entry()).collect()
    }
    let gpu = Gpu::new(None).unwrap();
    // (file, build options, the entries it must hold)
    let curv = names(CurvKernel::ALL);
    let gather_only =
        |n: &&str| n.ends_with("_corners") || n.ends_with("_sum") || n.starts_with("curv_ring_");
    let atomic: Vec<_> = curv.iter().copied().filter(|n| !gather_only(n)).collect();
    let gather: Vec<_> = curv
        .iter()
        .copied()
        .filter(|n| {
            gather_only(n)
                || ![
                    "curv_clear",
                    "curv_normals_areas",
                    "curv_tensor",
                    "curv_dcurv",
                ]
                .contains(n)
        })
        .collect();
    let mc = names(McKernel::ALL);
    let (direct, soup): (Vec<_>, Vec<_>) = mc.iter().partition(|n| n.starts_with("mc_direct_"));
    let edges: Vec<_> = names(EdgesKernel::ALL)
        .into_iter()
        .filter(|n| *n != "edges_probe_layout") // appended by the layout probe test
        .collect();
    let msdf_opts = shapecue::stages::mesh_sdf::build_options();
    let bvh_opts = shapecue::stages::bvh::build_options();
    let bvh: Vec<_> = names(shapecue::spec::bvh::BvhKernel::ALL)
        .into_iter()
        .filter(|n| *n != "bvh_probe_layout") // appended by the layout probe test
        .collect();
    let isect_opts = shapecue::stages::intersections::build_options();
    let isect: Vec<_> = names(shapecue::spec::intersections::IsectKernel::ALL)
        .into_iter()
        .filter(|n| *n != "isect_probe_layout") // appended by the layout probe test
        .collect();
    let cases: Vec<(KernelFile, &str, Vec<&str>)> = vec![
        (kernel_files::CURVATURE, "", atomic),
        (kernel_files::CURVATURE, "-DSC_GATHER", gather),
        (kernel_files::SCAN, "", names(ScanKernel::ALL)),
        (kernel_files::RADIX_SORT, "", names(RadixKernel::ALL)),
        (kernel_files::SKINNING, "", names(SkinKernel::ALL)),
        (kernel_files::AO, "", names(AoKernel::ALL)),
        (kernel_files::FEATURE_LINES, "", names(LinesKernel::ALL)),
        (
            kernel_files::MARCHING_CUBES,
            "",
            soup.into_iter().copied().collect(),
        ),
        (
            kernel_files::MARCHING_CUBES_DIRECT,
            "",
            direct.into_iter().copied().collect(),
        ),
        (kernel_files::VERTEX_FUSION, "", names(FuseKernel::ALL)),
        (kernel_files::EDGES, "", edges),
        (kernel_files::SDF_LINES, "", names(SdflKernel::ALL)),
        (kernel_files::MESH_SDF, &msdf_opts, names(MsdfKernel::ALL)),
        (kernel_files::BVH, &bvh_opts, bvh),
        (kernel_files::INTERSECTIONS, &isect_opts, isect),
    ];
    assert_eq!(
        kernel_files::ALL.len(),
        cases
            .iter()
            .map(|c| c.0.name)
            .collect::<std::collections::BTreeSet<_>>()
            .len(),
        "every kernel file is checked"
    );
    for (file, opts, entries) in cases {
        let p = gpu
            .program(&file, opts)
            .unwrap_or_else(|e| panic!("{} {opts}: {e}", file.name));
        assert!(!entries.is_empty(), "{}", file.name);
        for name in entries {
            gpu.kernel(&p, name)
                .unwrap_or_else(|e| panic!("{} {opts}: no entry point {name}: {e}", file.name));
        }
    }
}

/// Built-ins and pragmas a device may round its own way. A kernel that used
/// one would match its CPU twin on the CPU runtimes of CI and not on a GPU;
/// kernels/common/strict.h says why each is left out.
const ROUNDED_THEIR_OWN_WAY: &[&str] = &[
    // native_* and half_* of the math built-ins (their accuracy is the
    // device's own), written out so that a field named half_width passes
    "native_cos(",
    "native_divide(",
    "native_exp",
    "native_log",
    "native_powr(",
    "native_recip(",
    "native_rsqrt(",
    "native_sin(",
    "native_sqrt(",
    "native_tan(",
    "half_cos(",
    "half_divide(",
    "half_exp",
    "half_log",
    "half_powr(",
    "half_recip(",
    "half_rsqrt(",
    "half_sin(",
    "half_sqrt(",
    "half_tan(",
    "dot(",
    "length(",
    "fast_length(",
    "normalize(",
    "fast_normalize(",
    "cross(",
    "distance(",
    "mad(",
    "fma(",
    "rsqrt(",
    "FP_CONTRACT ON",
    "-cl-fast-relaxed-math",
    "-cl-mad-enable",
    "-cl-unsafe-math-optimizations",
];

#[test]
fn no_kernel_uses_a_builtin_that_a_gpu_rounds_its_own_way() {
    let mut found = Vec::new();
    for file in kernel_files::ALL {
        let texts = std::iter::once((file.name, file.source))
            .chain(file.headers.iter().copied())
            .chain(file.includes.iter().copied());
        for (name, text) in texts {
            for (i, line) in text.lines().enumerate() {
                // comments may name them (strict.h does)
                let code = line.split("//").next().unwrap_or("");
                for bad in ROUNDED_THEIR_OWN_WAY {
                    let hit = code.match_indices(bad).any(|(at, _)| {
                        // a whole identifier: `vload3(` is not `load3(`
                        !code[..at]
                            .chars()
                            .next_back()
                            .is_some_and(|c| c.is_alphanumeric() || c == '_')
                    });
                    if hit {
                        found.push(format!("{name}:{}: {bad}: {}", i + 1, line.trim()));
                    }
                }
            }
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}

#[test]
fn every_program_opens_with_the_strict_rules_unless_built_relaxed() {
    use shapecue::gpu::{FpMode, STRICT_HEADER, assemble_as};
    for file in kernel_files::ALL {
        let strict = assemble_as(file, FpMode::Strict);
        let first_code = strict
            .lines()
            .find(|l| !l.trim().is_empty() && !l.starts_with("//") && !l.starts_with("#line"))
            .unwrap_or("");
        assert_eq!(
            first_code, "#pragma OPENCL FP_CONTRACT OFF",
            "{}",
            file.name
        );
        assert!(strict.contains(STRICT_HEADER.1), "{}", file.name);
        let relaxed = assemble_as(file, FpMode::Relaxed);
        assert!(!relaxed.contains("FP_CONTRACT OFF"), "{}", file.name);
        assert!(
            relaxed.starts_with("#pragma OPENCL FP_CONTRACT ON"),
            "{}",
            file.name
        );
    }
}

/// a·b + c and a / b and sqrt(a) over a million inputs, on the device and in
/// Rust (each operation rounded on its own). Built strictly, the device
/// gives Rust's bits wherever it reports correctly rounded divide and square
/// root; built relaxed it may fuse and approximate (PoCL fuses: about one
/// in five of the products and sums differ there).
#[test]
fn strict_builds_round_every_operation_as_the_twins_do() {
    use shapecue::gpu::{FpMode, buf, launch};
    let file = KernelFile {
        name: "kernels/fp_probe.cl",
        source: "__kernel void fp_probe(__global const float *a, __global float *o) {\n\
                 uint i = get_global_id(0);\n\
                 float x = a[3 * i], y = a[3 * i + 1], z = a[3 * i + 2];\n\
                 o[3 * i] = x * y + z; o[3 * i + 1] = x / y; o[3 * i + 2] = sqrt(x);\n}\n",
        headers: &[],
        includes: &[],
    };
    let n = 1usize << 20;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let a: Vec<f32> = (0..3 * n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            0.1 + 3.0 * (state >> 40) as f32 / (1u64 << 24) as f32
        })
        .collect();
    let differ = |fp: FpMode| -> [usize; 3] {
        let gpu = Gpu::with_fp(None, fp).unwrap();
        let p = gpu.program(&file, "").unwrap();
        let k = gpu.kernel(&p, "fp_probe").unwrap();
        let mut ab = gpu.buffer::<f32>(3 * n).unwrap();
        gpu.write(&mut ab, &a).unwrap();
        let ob = gpu.buffer::<f32>(3 * n).unwrap();
        launch(&gpu, &k, n, &[buf(&ab), buf(&ob)]).unwrap();
        let mut o = vec![0f32; 3 * n];
        gpu.read(&ob, &mut o).unwrap();
        let mut d = [0; 3];
        for i in 0..n {
            let (x, y, z) = (a[3 * i], a[3 * i + 1], a[3 * i + 2]);
            let m = std::hint::black_box(x * y);
            d[0] += usize::from((m + z).to_bits() != o[3 * i].to_bits());
            d[1] += usize::from((x / y).to_bits() != o[3 * i + 1].to_bits());
            d[2] += usize::from(x.sqrt().to_bits() != o[3 * i + 2].to_bits());
        }
        d
    };
    let gpu = Gpu::new(None).unwrap();
    let strict = differ(FpMode::Strict);
    let relaxed = differ(FpMode::Relaxed);
    eprintln!(
        "{}: of {n}, fused/divided/rooted differently: strict {strict:?}, relaxed {relaxed:?}",
        gpu.info.name
    );
    assert_eq!(
        strict[0], 0,
        "products and sums are not fused in strict builds"
    );
    if gpu.info.correctly_rounded_div_sqrt {
        assert_eq!(
            strict,
            [0, 0, 0],
            "strict divide and square root are correctly rounded"
        );
    }
}

/// Staged uploads (pinned staging, chunk by chunk, then a device copy) write
/// exactly what a plain write does, across a chunk boundary and a short last
/// chunk; GPUs take this path for every large write.
#[test]
fn staged_uploads_write_every_byte_across_chunks() {
    let gpu = Gpu::new(None).unwrap();
    let n = shapecue::gpu::STAGING_BYTES / 4 + 12_345;
    let data: Vec<u32> = (0..n as u32)
        .map(|i| i.wrapping_mul(2_654_435_761))
        .collect();
    let mut b = gpu.buffer::<u32>(n).unwrap();
    gpu.write_staged(&mut b, &data).unwrap();
    let mut back = vec![0u32; n];
    gpu.read(&b, &mut back).unwrap();
    assert!(back == data, "staged upload differs");
    // the small case: one partial chunk
    let mut s = gpu.buffer::<u32>(7).unwrap();
    gpu.write_staged(&mut s, &data[..7]).unwrap();
    let mut back = vec![0u32; 7];
    gpu.read(&s, &mut back).unwrap();
    assert_eq!(back, data[..7]);
}
