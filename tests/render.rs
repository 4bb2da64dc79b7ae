//! The headless GL renderer: shading, clip-space quads (House & Li's edge-out
//! layout and its NaN marker), MSAA, depth read-back, PNG output, cameras and
//! several renderers per process.
//!
//! Without libEGL/Mesa the GL tests print why and pass (skip); set
//! `SHAPECUE_REQUIRE_GL=1` to make them fail instead (CI, where GL must work).

mod common;

use glam::{DVec3, DVec4, Vec3, Vec4};
use shapecue::Error;
use shapecue::render::{Camera, Frame, Light, MeshStyle, RenderOptions, Renderer};

const BG: [f32; 4] = [0.0, 0.0, 1.0, 1.0];
const BG8: [u8; 4] = [0, 0, 255, 255];

fn opts(width: u32, height: u32, msaa: u32) -> RenderOptions {
    RenderOptions {
        width,
        height,
        msaa,
        background: BG,
    }
}

/// A renderer, or `None` (with a message) when this machine has no headless GL.
fn renderer(o: RenderOptions) -> Option<Renderer> {
    common::unless_no_gl(Renderer::new(o))
        .map(|r| r.unwrap_or_else(|e| panic!("Renderer::new({o:?}): {e}")))
}

/// Unit cube [-0.5, 0.5]³ as 12 unwelded triangles (3 vertices each, flat
/// normals), counter-clockwise seen from outside.
/// Positions, normals and faces of a triangle mesh.
type Soup = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[u32; 3]>);

fn cube() -> Soup {
    let (mut p, mut n, mut f) = (Vec::new(), Vec::new(), Vec::new());
    let e = [Vec3::X, Vec3::Y, Vec3::Z];
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let normal = e[axis] * sign;
            // (u, v, normal) right-handed, so the corners below run counter-clockwise.
            let (mut u, mut v) = (e[(axis + 1) % 3], e[(axis + 2) % 3]);
            if sign < 0.0 {
                std::mem::swap(&mut u, &mut v);
            }
            let corner = |a: f32, b: f32| (0.5 * (normal + u * a + v * b)).to_array();
            let quad = [
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            ];
            for tri in [[0, 1, 2], [0, 2, 3]] {
                let base = p.len() as u32;
                for k in tri {
                    p.push(quad[k]);
                    n.push(normal.to_array());
                }
                f.push([base, base + 1, base + 2]);
            }
        }
    }
    (p, n, f)
}

const FULL: [[f32; 4]; 4] = [
    [-1.0, -1.0, 0.0, 1.0],
    [1.0, -1.0, 0.0, 1.0],
    [1.0, 1.0, 0.0, 1.0],
    [-1.0, 1.0, 0.0, 1.0],
];

/// A frame filled by one full-screen clip-space quad of colour `c`.
fn fill(r: &mut Renderer, c: [f32; 4]) -> Frame {
    r.begin(&camera()).unwrap();
    r.draw_clip_quads(&FULL, c).unwrap();
    r.finish().unwrap()
}

fn camera() -> Camera {
    Camera::look_at(Vec3::new(3.0, 2.0, 4.0), Vec3::ZERO)
}

fn draw_cube(r: &mut Renderer, cam: &Camera, style: MeshStyle) -> Frame {
    let (p, n, f) = cube();
    r.begin(cam).unwrap();
    r.draw_mesh(&p, &n, &[], &f, style).unwrap();
    r.finish().unwrap()
}

/// Pixel (column, row from the top) under a world point.
fn pixel_of(cam: &Camera, w: u32, h: u32, p: Vec3) -> (u32, u32) {
    let c = cam.view_proj(w as f32 / h as f32) * Vec4::from((p, 1.0));
    let ndc = c.truncate() / c.w;
    (
        ((ndc.x + 1.0) * 0.5 * w as f32) as u32,
        ((1.0 - ndc.y) * 0.5 * h as f32) as u32,
    )
}

#[test]
fn cube_centre_is_shaded_corners_are_background_and_lambert_follows_the_light() {
    let Some(mut r) = renderer(opts(96, 96, 0)) else {
        return;
    };
    let cam = camera();
    let frame = draw_cube(&mut r, &cam, MeshStyle::default());
    assert_ne!(
        frame.pixel(48, 48).unwrap(),
        BG8,
        "centre must show the cube"
    );
    for (x, y) in [(0, 0), (95, 0), (0, 95), (95, 95)] {
        assert_eq!(frame.pixel(x, y).unwrap(), BG8, "corner ({x},{y})");
    }

    // Headlight: brightness at a face centre = 0.8·(0.15 + 0.85·n·v̂).
    let eye = cam.eye;
    let mut prev = 256.0;
    for (centre, normal) in [(Vec3::Z, Vec3::Z), (Vec3::X, Vec3::X), (Vec3::Y, Vec3::Y)] {
        let c = centre * 0.5;
        let (x, y) = pixel_of(&cam, 96, 96, c);
        let got = frame.pixel(x, y).unwrap()[0] as f32;
        let want = 255.0 * 0.8 * (0.15 + 0.85 * normal.dot((eye - c).normalize()));
        assert!((got - want).abs() < 8.0, "face {normal}: {got} vs {want}");
        assert!(got < prev, "faces more oblique to the eye are darker");
        prev = got;
    }

    // A fixed light along +Z: the +Z face is lit head-on, the +X face at a
    // grazing angle (ambient only).
    let style = MeshStyle {
        light: Light::Directional(Vec3::Z),
        ambient: 0.1,
        color: [1.0, 1.0, 1.0],
    };
    let frame = draw_cube(&mut r, &cam, style);
    let lum = |p: Vec3| {
        let (x, y) = pixel_of(&cam, 96, 96, p);
        frame.pixel(x, y).unwrap()[1]
    };
    let (facing, grazing) = (lum(Vec3::Z * 0.5), lum(Vec3::X * 0.5));
    assert_eq!(facing, 255);
    assert!((grazing as i32 - 26).abs() <= 1, "ambient only: {grazing}");
}

#[test]
fn a_clip_space_quad_covers_exactly_the_left_half() {
    for msaa in [0, 4] {
        let Some(mut r) = renderer(opts(64, 32, msaa)) else {
            return;
        };
        r.begin(&camera()).unwrap();
        // House & Li order (s0 − p, s1 − p, s1 + p, s0 + p): the edge runs
        // down the middle of the left half, p points right.
        let quad = [
            [-1.0, 1.0, 0.0, 1.0],
            [-1.0, -1.0, 0.0, 1.0],
            [0.0, -1.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, 1.0],
        ];
        r.draw_clip_quads(&quad, [1.0, 0.0, 0.0, 1.0]).unwrap();
        let f = r.finish().unwrap();
        for y in 0..32 {
            for x in (0..30).chain(34..64) {
                let want = if x < 32 { [255, 0, 0, 255] } else { BG8 };
                assert_eq!(f.pixel(x, y).unwrap(), want, "msaa {msaa}, pixel ({x},{y})");
            }
        }
        // The w of each vertex is honoured (projection-space input): the same
        // quad scaled by w = 2 covers the same pixels.
        r.begin(&camera()).unwrap();
        let scaled: Vec<[f32; 4]> = quad.iter().map(|v| v.map(|c| c * 2.0)).collect();
        r.draw_clip_quads(&scaled, [1.0, 0.0, 0.0, 1.0]).unwrap();
        assert_eq!(r.finish().unwrap(), f);
    }
}

#[test]
fn quads_and_triangles_with_the_nan_marker_draw_nothing() {
    let Some(mut r) = renderer(opts(32, 32, 4)) else {
        return;
    };
    let nan = f32::NAN;
    // First vertex marked, the others a full-screen quad: must still be skipped.
    let marked = [
        [nan, 0.0, -1.0, 1.0],
        [1.0, -1.0, 0.0, 1.0],
        [1.0, 1.0, 0.0, 1.0],
        [-1.0, 1.0, 0.0, 1.0],
    ];
    let all_marked = [[nan, 0.0, -1.0, 1.0]; 4];
    let mcguire = [[0.0, 0.0, -1.0, 1.0]; 4];
    r.begin(&camera()).unwrap();
    r.draw_clip_quads(&marked, [1.0, 0.0, 0.0, 1.0]).unwrap();
    r.draw_clip_quads(&all_marked, [1.0, 0.0, 0.0, 1.0])
        .unwrap();
    r.draw_clip_quads(&mcguire, [1.0, 0.0, 0.0, 1.0]).unwrap();
    r.draw_clip_triangles(&marked[..3], [1.0, 0.0, 0.0, 1.0])
        .unwrap();
    let f = r.finish().unwrap();
    assert!(
        f.rgba.chunks(4).all(|p| p == BG8),
        "a marked primitive was drawn"
    );
    assert!(f.depth.iter().all(|&d| d == 1.0));

    // A marked quad next to a drawable one: only the drawable one appears.
    let mut both = marked.to_vec();
    both.extend(FULL);
    r.begin(&camera()).unwrap();
    r.draw_clip_quads(&both, [0.0, 1.0, 0.0, 1.0]).unwrap();
    let f = r.finish().unwrap();
    assert!(f.rgba.chunks(4).all(|p| p == [0, 255, 0, 255]));

    // Half-caps: 3 vertices per triangle.
    let tri = [
        [-1.0, -1.0, 0.0, 1.0],
        [1.0, -1.0, 0.0, 1.0],
        [-1.0, 1.0, 0.0, 1.0],
    ];
    let mut caps = marked[..3].to_vec();
    caps.extend(tri);
    r.begin(&camera()).unwrap();
    r.draw_clip_triangles(&caps, [0.0, 1.0, 0.0, 1.0]).unwrap();
    let f = r.finish().unwrap();
    assert_eq!(
        f.pixel(2, 29).unwrap(),
        [0, 255, 0, 255],
        "lower-left triangle drawn"
    );
    assert_eq!(f.pixel(29, 2).unwrap(), BG8, "upper-right stays background");
}

#[test]
fn msaa_changes_only_the_silhouette() {
    let Some(mut r0) = renderer(opts(80, 60, 0)) else {
        return;
    };
    let Some(mut r4) = renderer(opts(80, 60, 4)) else {
        return;
    };
    let cam = camera();
    let (a, b) = (
        draw_cube(&mut r0, &cam, MeshStyle::default()),
        draw_cube(&mut r4, &cam, MeshStyle::default()),
    );
    let (mut interior, mut differ) = (0, 0);
    for y in 1..59 {
        for x in 1..79 {
            let uniform = (-1i32..=1)
                .flat_map(|dy| (-1i32..=1).map(move |dx| (dx, dy)))
                .all(|(dx, dy)| {
                    a.pixel((x as i32 + dx) as u32, (y as i32 + dy) as u32) == a.pixel(x, y)
                });
            if uniform {
                interior += 1;
                assert_eq!(a.pixel(x, y), b.pixel(x, y), "interior pixel ({x},{y})");
            }
            differ += (a.pixel(x, y) != b.pixel(x, y)) as u32;
        }
    }
    assert!(interior > 2000, "{interior} interior pixels compared");
    assert!(differ > 0, "MSAA 4 must antialias the silhouette");
}

#[test]
fn depth_reads_back_window_depth() {
    let Some(mut r) = renderer(opts(64, 64, 0)) else {
        return;
    };
    let cam = camera();
    let f = draw_cube(&mut r, &cam, MeshStyle::default());
    assert_eq!(f.depth_at(0, 0), Some(1.0), "background depth is 1");
    let d = f.depth_at(32, 32).unwrap();
    assert!(d > 0.0 && d < 1.0, "centre depth {d}");

    // Oracle: cast the ray through the pixel centre, intersect the cube (slab
    // test), project the hit to window depth.
    let vp = cam.view_proj(1.0).as_dmat4();
    let inv = vp.inverse();
    let (px, py) = (32.5f64, 32.5f64);
    let ndc = |z: f64| {
        let p = inv * DVec4::new(px / 32.0 - 1.0, 1.0 - py / 32.0, z, 1.0);
        p.truncate() / p.w
    };
    let (o, dir) = (ndc(-1.0), (ndc(1.0) - ndc(-1.0)).normalize());
    let t0 = (DVec3::splat(-0.5) - o) / dir;
    let t1 = (DVec3::splat(0.5) - o) / dir;
    let t_near = t0.min(t1).max_element();
    let hit = vp * DVec4::from((o + dir * t_near, 1.0));
    let want = (0.5 * (hit.z / hit.w) + 0.5) as f32;
    // The polygon offset (factor 1, units 1) pushes the mesh back by about
    // one pixel's depth slope: bound it by the slope read from the neighbours.
    let slope = [(33, 32), (31, 32), (32, 33), (32, 31)]
        .iter()
        .map(|&(x, y)| (f.depth_at(x, y).unwrap() - d).abs())
        .fold(0.0f32, f32::max);
    assert!(
        d >= want - 1e-6 && d - want <= 1.5 * slope + 1e-6,
        "depth {d} vs ray hit {want} (slope {slope} per pixel)"
    );
}

#[test]
fn lines_are_the_requested_pixel_width_and_win_over_the_mesh() {
    let Some(mut r) = renderer(opts(64, 32, 0)) else {
        return;
    };
    // Orthographic, 2 world units tall: 16 pixels per unit.
    let mut cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
    cam.ortho_height = Some(2.0);
    r.begin(&cam).unwrap();
    r.draw_lines(
        &[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
        [1.0, 1.0, 0.0, 1.0],
        4.0,
    )
    .unwrap();
    let f = r.finish().unwrap();
    let rows: Vec<u32> = (0..32)
        .filter(|&y| f.pixel(32, y) == Some([255, 255, 0, 255]))
        .collect();
    assert_eq!(rows, [14, 15, 16, 17]);
    // Square caps: the line ends 2 px past x = ±1 (pixels 16 and 48).
    let cols = (0..64)
        .filter(|&x| f.pixel(x, 16) == Some([255, 255, 0, 255]))
        .count();
    assert_eq!(cols, 32 + 4);

    // A line along a visible cube edge is not hidden by the faces meeting there.
    let cam = camera();
    let (p, n, faces) = cube();
    let edge = [[0.5, -0.5, 0.5], [0.5, 0.5, 0.5]];
    r.begin(&cam).unwrap();
    r.draw_mesh(&p, &n, &[], &faces, MeshStyle::default())
        .unwrap();
    r.draw_lines(&edge, [1.0, 0.0, 0.0, 1.0], 3.0).unwrap();
    let f = r.finish().unwrap();
    for t in [0.25f32, 0.5, 0.75] {
        let w = Vec3::from(edge[0]).lerp(Vec3::from(edge[1]), t);
        let (x, y) = pixel_of(&cam, 64, 32, w);
        assert_eq!(
            f.pixel(x, y).unwrap(),
            [255, 0, 0, 255],
            "edge point {w} at ({x},{y})"
        );
    }
}

#[test]
fn camera_validation_names_the_problem() {
    let ok = camera();
    ok.validate().unwrap();
    let cases: [(&str, Camera); 7] = [
        ("coincide", Camera::look_at(Vec3::ONE, Vec3::ONE)),
        (
            "non-finite",
            Camera {
                eye: Vec3::new(f32::NAN, 0.0, 0.0),
                ..ok
            },
        ),
        (
            "non-finite",
            Camera {
                far: f32::INFINITY,
                ..ok
            },
        ),
        (
            "parallel",
            Camera {
                up: Vec3::new(3.0, 2.0, 4.0),
                ..ok
            },
        ),
        ("near", Camera { near: 0.0, ..ok }),
        ("far", Camera { far: ok.near, ..ok }),
        (
            "field of view",
            Camera {
                fov_y_deg: 180.0,
                ..ok
            },
        ),
    ];
    for (what, cam) in cases {
        match cam.validate() {
            Err(Error::InvalidArgument(msg)) => assert!(msg.contains(what), "{what}: {msg}"),
            other => panic!("{what}: expected an error, got {other:?}"),
        }
    }
    // Looking straight down picks another up vector instead of failing.
    Camera::look_at(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO)
        .validate()
        .unwrap();
    let fit = Camera::fit(
        Vec3::splat(-1.0),
        Vec3::splat(1.0),
        Vec3::new(1.0, 1.0, 1.0),
        0.5,
    )
    .unwrap();
    fit.validate().unwrap();
    // Every box corner lands inside the (portrait) view and the depth range.
    let vp = fit.view_proj(0.5);
    for i in 0..8 {
        let c = Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32) * 2.0 - 1.0;
        let p = vp * Vec4::from((c, 1.0));
        let ndc = p.truncate() / p.w;
        assert!(ndc.abs().max_element() < 1.0, "corner {c} at {ndc}");
    }
    assert!(Camera::fit(Vec3::ZERO, Vec3::ONE, Vec3::ZERO, 1.0).is_err());

    // The renderer refuses a bad camera at begin().
    if let Some(mut r) = renderer(opts(8, 8, 0)) {
        let bad = Camera {
            eye: Vec3::ZERO,
            ..Camera::look_at(Vec3::ONE, Vec3::ZERO)
        };
        assert!(matches!(r.begin(&bad), Err(Error::InvalidArgument(_))));
        // and drawing outside begin()..finish()
        assert!(r.draw_clip_quads(&[], [1.0; 4]).is_err());
        assert!(r.finish().is_err());
    }
}

#[test]
fn png_round_trip() {
    let Some(mut r) = renderer(opts(40, 30, 4)) else {
        return;
    };
    let f = draw_cube(&mut r, &camera(), MeshStyle::default());
    let dir = std::env::temp_dir().join(format!("shapecue-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cube.png");
    f.save_png(&path).unwrap();
    let back = image::open(&path).unwrap().to_rgba8();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(back.dimensions(), (40, 30));
    assert_eq!(back.as_raw(), &f.rgba);
    assert_eq!(back, f.to_image());
    // Top row first: the cube is not in the top-left corner, so that pixel is background.
    assert_eq!(back.get_pixel(0, 0).0, BG8);

    let bad = Frame {
        width: 2,
        height: 2,
        rgba: vec![0; 16],
        depth: vec![1.0; 4],
    };
    match bad.save_png(std::path::Path::new("/nonexistent-dir/x.png")) {
        Err(Error::Write { path, .. }) => assert!(path.ends_with("x.png")),
        other => panic!("expected a write error, got {other:?}"),
    }
}

#[test]
fn options_are_checked() {
    for (w, h, msaa) in [(0, 8, 0), (8, 0, 0), (8, 8, 3), (8, 8, 16)] {
        match Renderer::new(opts(w, h, msaa)) {
            Err(Error::InvalidArgument(_)) => {}
            Err(e @ Error::NoGl { .. }) => eprintln!("skipping GL test: {e}"),
            Err(e) => panic!("{w}x{h} msaa {msaa}: unexpected {e}"),
            Ok(_) => panic!("{w}x{h} msaa {msaa} accepted"),
        }
    }
}

#[test]
fn renderers_run_one_after_another_side_by_side_and_on_many_threads() {
    let Some(first) = renderer(opts(16, 16, 0)) else {
        return;
    };
    eprintln!("{}", first.gl_info());
    assert!(first.gl_info().contains("OpenGL"));
    drop(first);
    // Sequential: create, use, drop, several times.
    for i in 0..3 {
        let mut r = Renderer::new(opts(16, 16, 4)).unwrap();
        let f = fill(&mut r, [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(f.pixel(8, 8), Some([255, 0, 0, 255]), "renderer {i}");
    }
    // Two alive on one thread, taking turns (each call makes its context current).
    let mut a = Renderer::new(opts(16, 16, 0)).unwrap();
    let mut b = Renderer::new(opts(8, 8, 4)).unwrap();
    a.begin(&camera()).unwrap();
    assert_eq!(
        fill(&mut b, [0.0, 1.0, 0.0, 1.0]).pixel(4, 4),
        Some([0, 255, 0, 255])
    );
    a.draw_clip_quads(&FULL, [1.0, 0.0, 0.0, 1.0]).unwrap();
    assert_eq!(a.finish().unwrap().pixel(8, 8), Some([255, 0, 0, 255]));
    drop(a);
    assert_eq!(
        fill(&mut b, [0.0, 0.0, 0.0, 1.0]).pixel(4, 4),
        Some([0, 0, 0, 255])
    );
    drop(b);
    // Parallel threads, each with its own renderer.
    let handles: Vec<_> = (0..4)
        .map(|t| {
            std::thread::spawn(move || {
                let mut r = Renderer::new(opts(24, 24, if t % 2 == 0 { 0 } else { 4 })).unwrap();
                let shade = t as f32 / 4.0;
                for _ in 0..3 {
                    let f = fill(&mut r, [shade, 1.0, 0.0, 1.0]);
                    assert_eq!(f.pixel(12, 12).unwrap()[1], 255, "thread {t}");
                }
                let f = draw_cube(&mut r, &camera(), MeshStyle::default());
                assert_ne!(f.pixel(12, 12).unwrap(), BG8, "thread {t}");
            })
        })
        .collect();
    for h in handles {
        h.join().unwrap();
    }
}

#[test]
fn a_reconfigured_renderer_draws_what_a_new_one_draws() {
    let Some(mut r) = renderer(opts(40, 30, 4)) else {
        return;
    };
    let cam = camera();
    let first = draw_cube(&mut r, &cam, MeshStyle::default());
    for o in [
        opts(64, 48, 0),
        opts(40, 30, 4),
        opts(33, 17, 2),
        opts(33, 17, 2),
    ] {
        r.reconfigure(o).unwrap();
        let mut fresh = Renderer::new(o).unwrap();
        let a = draw_cube(&mut r, &cam, MeshStyle::default());
        let b = draw_cube(&mut fresh, &cam, MeshStyle::default());
        assert_eq!((a.width, a.height), (o.width, o.height));
        assert!(a == b, "{o:?}: reconfigured vs new renderer");
    }
    r.reconfigure(opts(40, 30, 4)).unwrap();
    assert!(draw_cube(&mut r, &cam, MeshStyle::default()) == first);
    // Bad options are refused and the renderer keeps its old ones.
    for (w, h, msaa) in [(0, 8, 0), (8, 8, 3), (8, 8, 16), (1 << 20, 8, 0)] {
        assert!(
            matches!(
                r.reconfigure(opts(w, h, msaa)),
                Err(Error::InvalidArgument(_))
            ),
            "{w}x{h} msaa {msaa}"
        );
        assert_eq!(r.options(), opts(40, 30, 4));
    }
    assert!(draw_cube(&mut r, &cam, MeshStyle::default()) == first);
}

#[test]
fn an_uploaded_mesh_is_drawn_in_every_view_without_uploading_again() {
    let Some(mut r) = renderer(opts(48, 48, 0)) else {
        return;
    };
    let (p, n, f) = cube();
    // Nothing uploaded yet: a clear error, not an empty picture.
    r.begin(&camera()).unwrap();
    let e = r.draw_uploaded(MeshStyle::default()).unwrap_err();
    assert!(e.to_string().contains("no mesh uploaded"), "{e}");
    r.finish().unwrap();
    r.upload_topology(&f).unwrap();
    r.upload_pose(&p, &n, &[]).unwrap();
    let eyes = [
        Vec3::new(3.0, 2.0, 4.0),
        Vec3::new(-3.0, 1.0, 2.0),
        Vec3::new(0.5, -4.0, 1.0),
    ];
    for eye in eyes {
        let cam = Camera::look_at(eye, Vec3::ZERO);
        r.begin(&cam).unwrap();
        r.draw_uploaded(MeshStyle::default()).unwrap();
        let a = r.finish().unwrap();
        assert!(a == draw_cube(&mut r, &cam, MeshStyle::default()), "{eye}");
    }
    // Three draw_mesh calls upload three times; the uploaded views none.
    assert_eq!(r.uploads().topology, 1 + 3);
    assert_eq!(r.uploads().pose, 1 + 3);
    // Faces past the pose's vertices and bad poses are refused by name.
    r.upload_pose(&p[..10], &n[..10], &[]).unwrap();
    r.begin(&camera()).unwrap();
    let e = r.draw_uploaded(MeshStyle::default()).unwrap_err();
    assert!(e.to_string().contains("past the 10 vertices"), "{e}");
    r.finish().unwrap();
    let mut bad = p.clone();
    bad[7][1] = f32::NAN;
    let e = r.upload_pose(&bad, &n, &[]).unwrap_err();
    assert!(e.to_string().contains("vertex 7"), "{e}");
    let e = r.upload_pose(&p, &n[..3], &[]).unwrap_err();
    assert!(e.to_string().contains("normals"), "{e}");
}
