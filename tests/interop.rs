//! The `--interop` routes: the decision for every combination of what a
//! device, a GL context and Vulkan report (pure data), the Vulkan-to-GL
//! half of the external-memory route on whatever Vulkan and GL this machine
//! has (Mesa's lavapipe and llvmpipe on the CPU machines), and, where a
//! device imports external memory, `shapecue edges --interop on` against the
//! host path's image.
//!
//! The GL tests skip with a message where the stack cannot share, unless
//! SHAPECUE_REQUIRE_GL=1 and Mesa's Vulkan driver is installed (CI installs
//! it), where a skip is a failure.

use glam::Vec3;
use shapecue::Error;
use shapecue::gpu::vulkan::VulkanExporter;
use shapecue::render::{Camera, RenderOptions, Renderer};
use shapecue::spec::interop::{
    GL_SHARING_BUILT, InteropMode, InteropOffer, InteropRoute, decide_interop,
};

/// Every combination the decision can be given.
fn offers() -> Vec<InteropOffer> {
    let tri = [None, Some(false), Some(true)];
    let mut all = Vec::new();
    for sharing in [false, true] {
        for external in [false, true] {
            for gl in tri {
                for vk in tri {
                    all.push(InteropOffer {
                        device: "dev".into(),
                        cl_gl_sharing: sharing,
                        cl_external_memory: external,
                        gl_memory_object_fd: gl,
                        vk_external_memory_fd: vk,
                        vk_detail: (vk == Some(false)).then(|| "no loader".into()),
                    });
                }
            }
        }
    }
    all
}

#[test]
fn decision_for_every_combination_of_what_is_reported() {
    for o in offers() {
        let sharing = o.cl_gl_sharing && GL_SHARING_BUILT;
        let external = o.cl_external_memory
            && o.gl_memory_object_fd == Some(true)
            && o.vk_external_memory_fd == Some(true);
        // Why external memory cannot run: the first missing piece.
        let missing = if !o.cl_external_memory {
            "cl_khr_external_memory_opaque_fd"
        } else if o.gl_memory_object_fd != Some(true) {
            "GL_EXT_memory_object_fd"
        } else {
            "VK_KHR_external_memory_fd"
        };
        let case = format!("{o:?}");

        let off = decide_interop(InteropMode::Off, &o).unwrap();
        assert_eq!(off.route, InteropRoute::Host, "{case}");
        assert!(
            !off.shared && off.reason.contains("interop is off"),
            "{case}"
        );

        let auto = decide_interop(InteropMode::Auto, &o).unwrap();
        let want = if sharing {
            InteropRoute::GlSharing
        } else if external {
            InteropRoute::ExternalMemory
        } else {
            InteropRoute::Host
        };
        assert_eq!(auto.route, want, "{case}");
        assert_eq!(auto.shared, want != InteropRoute::Host, "{case}");
        match want {
            InteropRoute::GlSharing => assert!(auto.passed_over.is_empty(), "{case}"),
            InteropRoute::ExternalMemory => {
                assert_eq!(auto.passed_over.len(), 1, "{case}");
                assert!(auto.passed_over[0].contains("cl_khr_gl_sharing"), "{case}");
            }
            InteropRoute::Host => {
                assert_eq!(auto.passed_over.len(), 2, "{case}");
                assert!(auto.reason.contains("cl_khr_gl_sharing"), "{case}");
                assert!(auto.reason.contains(missing), "{}: {case}", auto.reason);
                if o.cl_gl_sharing {
                    // Reported but not carried out: the reason says so.
                    assert!(auto.reason.contains("reports cl_khr_gl_sharing"), "{case}");
                }
            }
        }

        match decide_interop(InteropMode::On, &o) {
            Ok(on) => {
                assert!(want != InteropRoute::Host, "{case}");
                assert_eq!(on.route, want, "{case}");
            }
            Err(e) => {
                assert_eq!(want, InteropRoute::Host, "{case}");
                assert!(matches!(e, Error::DeviceUnsupported { .. }), "{case}");
                assert_eq!(e.exit_code(), 3, "{case}");
                let m = e.to_string();
                for name in [
                    "interop = on",
                    "cl_khr_gl_sharing",
                    "external memory",
                    missing,
                ] {
                    assert!(m.contains(name), "{m}");
                }
            }
        }
    }
}

#[test]
fn the_offer_of_this_machines_device_decides_without_panicking() {
    let Ok(gpu) = shapecue::gpu::Gpu::new(None) else {
        eprintln!("skipped: no OpenCL device");
        return;
    };
    let o = shapecue::api::interop::interop_offer(&gpu, InteropMode::Auto);
    assert_eq!(o.device, gpu.info.name);
    assert_eq!(o.cl_gl_sharing, gpu.info.gl_sharing);
    // GL and Vulkan are asked only when the device could use the answer.
    assert_eq!(o.gl_memory_object_fd.is_some(), o.cl_external_memory);
    let d = decide_interop(InteropMode::Auto, &o).unwrap();
    if !o.cl_external_memory && !o.cl_gl_sharing {
        assert_eq!(d.route, InteropRoute::Host);
    }
    let off = shapecue::api::interop::interop_offer(&gpu, InteropMode::Off);
    assert_eq!(off.gl_memory_object_fd, None);
}

/// Whether a skip must fail: CI asks for GL and installs Mesa's Vulkan.
fn must_run() -> bool {
    std::env::var("SHAPECUE_REQUIRE_GL").is_ok_and(|v| v == "1")
        && std::path::Path::new("/usr/share/vulkan/icd.d/lvp_icd.x86_64.json").exists()
}

fn skip(why: &str) {
    assert!(
        !must_run(),
        "SHAPECUE_REQUIRE_GL=1 and Mesa's Vulkan driver is installed, but {why}"
    );
    eprintln!("skipped: {why}");
}

/// Clip-space quad vertices, in perimeter order.
fn quad(x0: f32, y0: f32, x1: f32, y1: f32) -> [[f32; 4]; 4] {
    [
        [x0, y0, 0.0, 1.0],
        [x1, y0, 0.0, 1.0],
        [x1, y1, 0.0, 1.0],
        [x0, y1, 0.0, 1.0],
    ]
}

#[test]
fn a_buffer_filled_through_vulkan_is_drawn_by_gl() {
    let (w, h) = (64u32, 48u32);
    let mut r = match Renderer::new(RenderOptions {
        width: w,
        height: h,
        msaa: 0,
        background: [1.0, 1.0, 1.0, 1.0],
    }) {
        Ok(r) => r,
        Err(e) => return skip(&format!("no headless GL: {e}")),
    };
    if !r.memory_object_fd() {
        return skip("the GL context does not report GL_EXT_memory_object_fd");
    }
    let uuid = r.device_uuids().first().copied();
    let vk = match VulkanExporter::new(uuid) {
        Ok(v) => v,
        Err(e) => return skip(&format!("no Vulkan device to export from: {e}")),
    };
    // Three quads: the left half, a decoy right-top quadrant that is not in
    // the drawn range, then the bottom-right quadrant.
    let mut verts = Vec::new();
    verts.extend(quad(-1.0, -1.0, 0.0, 1.0));
    verts.extend(quad(0.0, 0.0, 1.0, 1.0));
    verts.extend(quad(0.0, -1.0, 1.0, 0.0));
    let bytes: &[u8] = bytemuck::cast_slice(&verts);
    let mem = vk.export(bytes.len() as u64, true).unwrap();
    mem.write(0, bytes).unwrap();
    let gl = r
        .import_buffer(mem.fd().unwrap(), mem.allocation_size(), bytes.len() as u64)
        .unwrap();
    assert_eq!(gl.vertices(), 12);
    r.begin(&Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO))
        .unwrap();
    let red = [1.0, 0.0, 0.0, 1.0];
    r.draw_imported(&gl, 0, 4, 4, red).unwrap();
    r.draw_imported(&gl, 8, 4, 4, red).unwrap();
    // A range past the end is refused, not drawn.
    assert!(r.draw_imported(&gl, 8, 8, 4, red).is_err());
    let f = r.finish_color().unwrap();
    r.free_imported(gl);
    drop(mem);
    let px = |x: u32, y: u32| f.pixel(x, y).unwrap();
    let (red_px, white) = ([255, 0, 0, 255], [255, 255, 255, 255]);
    assert_eq!(px(5, 5), red_px, "left half (top)");
    assert_eq!(px(5, h - 5), red_px, "left half (bottom)");
    assert_eq!(px(w - 5, h - 5), red_px, "bottom-right quadrant");
    assert_eq!(
        px(w - 5, 5),
        white,
        "top-right quadrant is outside the drawn range"
    );
    // GL sees the memory itself, not a copy made at import: written through
    // Vulkan after GL imported it, it draws the new quad.
    let mem = vk.export(bytes.len() as u64, true).unwrap();
    let gl = r
        .import_buffer(mem.fd().unwrap(), mem.allocation_size(), bytes.len() as u64)
        .unwrap();
    mem.write(0, bytemuck::cast_slice(&quad(0.0, 0.0, 1.0, 1.0)))
        .unwrap();
    r.begin(&Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO))
        .unwrap();
    r.draw_imported(&gl, 0, 4, 4, red).unwrap();
    let f = r.finish_color().unwrap();
    r.free_imported(gl);
    assert_eq!(f.pixel(w - 5, 5).unwrap(), red_px);
    assert_eq!(f.pixel(5, h - 5).unwrap(), white);
}

/// The GPU half: on a device that imports external memory, `--interop on`
/// draws the host path's image. Skipped (with a message) on devices
/// without `cl_khr_external_memory_opaque_fd`, such as PoCL.
#[test]
fn edges_on_external_memory_draws_the_host_image() {
    let Ok(gpu) = shapecue::gpu::Gpu::new(None) else {
        eprintln!("skipped: no OpenCL device");
        return;
    };
    let o = shapecue::api::interop::interop_offer(&gpu, InteropMode::On);
    let d = match decide_interop(InteropMode::On, &o) {
        Ok(d) => d,
        Err(e) => {
            // scripts/gpu-interop.sh sets this on a GPU that should share.
            assert!(
                std::env::var("SHAPECUE_REQUIRE_INTEROP").as_deref() != Ok("1"),
                "SHAPECUE_REQUIRE_INTEROP=1, but {e}"
            );
            eprintln!("skipped (GPU half): {e}");
            return;
        }
    };
    let gpu = std::sync::Arc::new(gpu);
    let (_, mesh) = shapecue::mesh::Generated::Torus.mesh(4000);
    assert_eq!(d.route, InteropRoute::ExternalMemory);
    let mut opts = shapecue::EdgePictureOptions {
        msaa: 0,
        ..Default::default()
    };
    opts.shot.eye = None;
    for caps in shapecue::spec::edges::CapMode::ALL {
        opts.caps = caps;
        opts.interop = InteropMode::Off;
        let host = shapecue::feature_edges_picture_on(&gpu, &mesh, "torus", &opts).unwrap();
        assert_eq!(host.interop.route, InteropRoute::Host);
        opts.interop = InteropMode::On;
        let shared = shapecue::feature_edges_picture_on(&gpu, &mesh, "torus", &opts).unwrap();
        assert_eq!(host.output.kind, shared.output.kind, "{}", caps.name());
        assert_eq!(host.drawn_caps, shared.drawn_caps, "{}", caps.name());
        assert_eq!(shared.interop.route, InteropRoute::ExternalMemory);
        assert!(
            host.frame.as_ref().map(|f| &f.rgba) == shared.frame.as_ref().map(|f| &f.rgba),
            "{}: images differ",
            caps.name()
        );
    }
}

/// The external-memory route's compaction writes, into one buffer, exactly
/// what the host route reads back (checked on any device with an ordinary
/// buffer in place of the imported one): edge quads, then the half-caps,
/// then the adjacency caps.
#[test]
fn compaction_into_one_buffer_matches_the_host_read_back() {
    use shapecue::mesh::edges::EdgeTopology;
    use shapecue::spec::edges::{CapMode, EdgeParams};
    use shapecue::stages::edges::EdgeStage;
    let Ok(gpu) = shapecue::gpu::Gpu::new(None) else {
        eprintln!("skipped: no OpenCL device");
        return;
    };
    let gpu = std::sync::Arc::new(gpu);
    let (_, mesh) = shapecue::mesh::Generated::Torus.mesh(3000);
    let topo = EdgeTopology::new(&mesh, &[], "torus").unwrap();
    let mut cam = Camera::look_at(Vec3::new(3.0, 2.0, 4.0), Vec3::ZERO);
    cam.fov_y_deg = 40.0;
    let p = EdgeParams::new(cam.view(320, 240));
    let mut stage = EdgeStage::new(gpu.clone(), &mesh, &topo).unwrap();
    for mode in CapMode::ALL {
        stage.run(&p, mode).unwrap();
        let host = stage.read_drawn().unwrap();
        let n = stage.shared_vertices(mode);
        let mut dst = gpu.buffer::<f32>(4 * n).unwrap();
        assert!(stage.compact_into(&mut dst, n - 1).is_err(), "too small");
        let d = stage.compact_into(&mut dst, n).unwrap();
        let mut all = vec![[0f32; 4]; n];
        gpu.read(&dst, bytemuck::cast_slice_mut(&mut all)).unwrap();
        let e = d.edges;
        assert!(e > 0, "{}: a torus seen whole draws edges", mode.name());
        assert_eq!(d.kind, host.kind, "{}", mode.name());
        let bits = |v: &[[f32; 4]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&all[..4 * e]), bits(&host.edge_out), "{}", mode.name());
        assert_eq!(d.mh, mode == CapMode::Mh);
        if d.mh {
            assert_eq!(bits(&all[4 * e..7 * e]), bits(&host.cap_mh0));
            assert_eq!(bits(&all[7 * e..10 * e]), bits(&host.cap_mh1));
        }
        let caps = &all[d.caps_at..d.caps_at + 4 * d.adjacency_caps];
        assert_eq!(bits(caps), bits(&host.cap_adj), "{}", mode.name());
        if mode == CapMode::Adjacency {
            assert!(d.adjacency_caps > 0, "adjacency caps drawn");
        }
    }
}
