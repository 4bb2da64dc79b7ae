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
    let gather_only = |n: &&str| n.ends_with("_corners") || n.ends_with("_sum");
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
