//! Coherence of the line families over an animation's frames: the delay
//! of births and the Schmitt trigger on the signs of K and H, device
//! against twin frame by frame (the hysteresis' two thresholds are in
//! tests/feature_lines.rs), and scenes of a skinned animation with
//! coherence off and on: the first frame is the same bits, the pieces'
//! faces and barycentric coordinates name the same rest-mesh points as
//! their world coordinates on each pose, and the NPZ files of every frame.

mod common;

use common::{gpu, only};
use shapecue::cpu::feature_lines::{Hold, lines_vertex};
use shapecue::cpu::feature_lines_curves::{
    CurveTerms, ScaledThresholds, boundary_mask, lines_curves, lines_dt1q1, lines_pose_held,
    lines_view,
};
use shapecue::mesh::{self, Mesh};
use shapecue::spec::feature_lines::{LineFamily, LineInputs, Segment};
use shapecue::spec::view::View;
use shapecue::stages::feature_lines::{HoldAt, LineExtractor, LineOptions};

/// The twin's held signs of K and H and emax dmax (`lines_pose_held`).
type Signs<'a> = (&'a mut [u32], &'a mut [[f32; 3]]);

/// A flat grid in z = 0 (normal +z, d1 +x, d2 +y, no curvature
/// derivative) whose principal curvatures a test sets per frame, seen from
/// above, with the CPU twin of the curve families on it.
struct Plane {
    m: Mesh,
    pos: Vec<[f32; 3]>,
    frame: [Vec<[f32; 3]>; 3],
    dk: Vec<[f32; 4]>,
    bnd: Vec<u32>,
    rings: (Vec<u32>, Vec<u32>),
    view: View,
}

impl Plane {
    /// The grid of `n` × `n` vertices over [-1, 1]².
    fn new(n: usize) -> Plane {
        let m = mesh::plane(n, 2.0);
        let nv = m.n_vertices();
        Plane {
            pos: m.positions.iter().map(|p| p.map(|c| c as f32)).collect(),
            frame: [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].map(|d| vec![d; nv]),
            dk: vec![[0.0; 4]; nv],
            bnd: boundary_mask(&m.faces),
            rings: mesh::topology::one_rings(nv, &m.faces),
            view: View::from_eye([0.0, 0.0, 3.0], false),
            m,
        }
    }

    /// The line inputs with the principal curvatures `k`.
    fn inputs<'a>(&'a self, k: &'a [[f32; 2]]) -> LineInputs<'a> {
        let [nrm, d1, d2] = &self.frame;
        LineInputs {
            pos: &self.pos,
            nrm,
            d1,
            d2,
            k,
            dk: &self.dk,
        }
    }

    /// The twin's segments of `opts`'s curve families on `li`, the signs
    /// of K and H held as `lines_pose_held` holds them (`signs`, `mode`,
    /// `band`) and the families as `hold` holds them.
    fn twin(
        &self,
        li: &LineInputs,
        opts: &LineOptions,
        (signs, mode, band): (Signs, u32, f32),
        hold: &mut Hold,
    ) -> Vec<Segment> {
        let t = lines_vertex(li, self.view);
        let p = lines_pose_held(li, false, signs, mode, [band; 3]);
        let w = lines_view(li, &p, &t, self.view, opts.curves.unit_light());
        let (off, ring) = &self.rings;
        let dt = lines_dt1q1(&self.m.faces, li, off, ring, &w, &t);
        let terms = CurveTerms {
            vertex: &t,
            pose: &p,
            view: &w,
            dt: &dt,
            bnd: &self.bnd,
        };
        let thr = ScaledThresholds::of(&opts.curves, 1.0, (0.0, 0.0));
        lines_curves(&self.m.faces, &self.pos, &terms, &opts.curves, thr, hold)
    }
}

/// Both lists hold the same segments (ends within `tol`, same family and
/// edges), in any order.
fn same(dev: &[Segment], cpu: &[Segment], tol: f32, what: &str) {
    let key = |s: &Segment| {
        let mut e = s.ends;
        e.sort();
        (s.family, e)
    };
    let mut a: Vec<&Segment> = dev.iter().collect();
    let mut b: Vec<&Segment> = cpu.iter().collect();
    a.sort_by_key(|s| key(s));
    b.sort_by_key(|s| key(s));
    assert_eq!(
        a.len(),
        b.len(),
        "{what}: {} vs {} segments",
        a.len(),
        b.len()
    );
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(key(x), key(y), "{what}");
        let d = |p: [f32; 3], q: [f32; 3]| (0..3).all(|k| (p[k] - q[k]).abs() < tol);
        assert!(
            (d(x.a, y.a) && d(x.b, y.b)) || (d(x.a, y.b) && d(x.b, y.a)),
            "{what}: {x:?} vs {y:?}"
        );
    }
}

/// Coherence's delay of births, on a plane whose Gaussian curvature is
/// set per frame (K = k1 with k2 = 1): a large circle of K = 0 on every
/// frame, a small one that blinks on one frame, and a small one that
/// appears on frame 2 and stays. Without coherence each is drawn where
/// present; with births delayed by one (two) frames the blink is never
/// drawn and the late circle from frame 3 (4), the large circle always. The
/// device equals its twin frame by frame.
#[test]
fn coherence_delays_the_birth_of_lines_away_from_every_line_of_their_family() {
    let plane = Plane::new(81);
    let (m, pos) = (&plane.m, &plane.pos);
    let nv = m.n_vertices();
    let (big, blink, late) = (
        ([-0.4f32, 0.0], 0.35f32),
        ([0.5f32, 0.5], 0.12f32),
        ([0.5f32, -0.5], 0.12f32),
    );
    let circle = |p: [f32; 3], (c, r): ([f32; 2], f32)| {
        (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) - r * r
    };
    let field = |k: usize| -> Vec<[f32; 2]> {
        pos.iter()
            .map(|&p| {
                let mut f = circle(p, big);
                if k == 3 {
                    f *= circle(p, blink);
                }
                if k >= 2 {
                    f *= circle(p, late);
                }
                [f, 1.0]
            })
            .collect()
    };
    let opts = only(&[LineFamily::KZero], |o| o.cull = false);
    let near = |s: &[Segment], (c, r): ([f32; 2], f32)| {
        s.iter()
            .filter(|s| (circle(s.a, (c, 0.0)).sqrt() - r).abs() < 0.05)
            .count()
    };
    for birth in [0u32, 1, 2] {
        let mut ex = LineExtractor::new(gpu(), nv, &m.faces).unwrap();
        let (mut held, mut nearv) = (vec![0u32; m.faces.len()], vec![0u32; nv]);
        for k in 0..7 {
            let kk = field(k);
            let li = plane.inputs(&kk);
            ex.hold_at(Some(HoldAt {
                slot: 0,
                frame: k,
                follows: k.checked_sub(1),
                low: 0.5,
                birth,
                band: 0.0,
            }))
            .unwrap();
            let (dev, _) = ex.extract(&li, plane.view, 1.0, opts).unwrap();
            // The twin from its own marks.
            let (mut nh, mut nn) = (vec![0u32; m.faces.len()], vec![0u32; nv]);
            let mut hold = Hold {
                held: &held,
                near: &nearv,
                next_held: &mut nh,
                next_near: &mut nn,
                low: 0.5,
                birth: if k == 0 { 0 } else { birth },
            };
            let cpu = plane.twin(&li, &opts, ((&mut [], &mut []), 0, 0.0), &mut hold);
            same(&dev, &cpu, 1e-5, &format!("birth {birth}, frame {k}"));
            let marks = ex.read_marks(0).unwrap().unwrap();
            assert_eq!(
                (marks.held, marks.near),
                (nh.clone(), nn.clone()),
                "marks, birth {birth}, frame {k}"
            );
            (held, nearv) = (nh, nn);
            let drawn = |c| near(&dev, c) > 0;
            assert!(drawn(big), "birth {birth}, frame {k}: the large circle");
            assert_eq!(
                drawn(blink),
                k == 3 && birth == 0,
                "birth {birth}, frame {k}: the blink"
            );
            let from = 2 + birth as usize;
            assert_eq!(
                drawn(late),
                k >= from,
                "birth {birth}, frame {k}: the late circle"
            );
        }
    }
}

/// Coherence's Schmitt trigger on the signs of K: a plane whose K jitters
/// about 0 (well within the band) in one half, with a fixed circle in the
/// other. Without the trigger the jitter draws other K = 0 segments every
/// frame; with it, each vertex keeps its first frame's sign there, so every
/// frame crosses the same edges as the first; the circle is unchanged. The
/// device equals its twin frame by frame.
#[test]
fn the_signs_of_k_hold_within_their_band() {
    let plane = Plane::new(61);
    let (m, pos) = (&plane.m, &plane.pos);
    let nv = m.n_vertices();
    let field = |k: usize| -> Vec<[f32; 2]> {
        pos.iter()
            .map(|&[x, y, _]| {
                let f = if x > 0.1 {
                    let t = k as f32;
                    0.01 * (37.0 * x + 1.7 * t).sin() * (23.0 * y - 2.3 * t).cos()
                } else {
                    (x + 0.5).powi(2) + y * y - 0.3 * 0.3
                };
                [f, 1.0]
            })
            .collect()
    };
    let opts = only(&[LineFamily::KZero], |o| o.cull = false);
    let edges = |s: &[Segment], right: bool| -> Vec<[[u32; 2]; 2]> {
        let mut e: Vec<[[u32; 2]; 2]> = (s.iter())
            .filter(|s| {
                let xs = s.ends.as_flattened().iter().map(|&v| pos[v as usize][0]);
                match right {
                    true => xs.fold(f32::MAX, f32::min) > 0.1,
                    false => xs.fold(f32::MIN, f32::max) < 0.05,
                }
            })
            .map(|s| {
                let mut e = s.ends;
                e.sort();
                e
            })
            .collect();
        e.sort();
        e
    };
    for band in [0.0f32, 0.1] {
        let mut ex = LineExtractor::new(gpu(), nv, &m.faces).unwrap();
        let mut signs = vec![0u32; nv];
        let mut evec = vec![[0f32; 3]; nv];
        let mut first: Option<(Vec<_>, Vec<_>)> = None;
        let mut changed = 0;
        for k in 0..5 {
            let kk = field(k);
            let li = plane.inputs(&kk);
            ex.hold_at(Some(HoldAt {
                slot: 0,
                frame: k,
                follows: k.checked_sub(1),
                low: 1.0,
                birth: 0,
                band,
            }))
            .unwrap();
            let (dev, _) = ex.extract(&li, plane.view, 1.0, opts).unwrap();
            let mode = match (band > 0.0, k) {
                (false, _) => 0,
                (true, 0) => 1,
                (true, _) => 2,
            };
            let signs = (&mut signs[..], &mut evec[..]);
            let cpu = plane.twin(&li, &opts, (signs, mode, band), &mut Hold::none());
            same(&dev, &cpu, 1e-5, &format!("band {band}, frame {k}"));
            let now = (edges(&dev, false), edges(&dev, true));
            assert!(
                !now.0.is_empty() && !now.1.is_empty(),
                "band {band}, frame {k}"
            );
            match &first {
                None => first = Some(now),
                Some(f) => {
                    assert_eq!(f.0, now.0, "band {band}, frame {k}: the circle");
                    changed += usize::from(f.1 != now.1);
                }
            }
        }
        match band > 0.0 {
            true => assert_eq!(changed, 0, "held signs cross the first frame's edges"),
            false => assert_eq!(changed, 4, "jitter crosses other edges every frame"),
        }
    }
}

/// A scene of the bundled Fox walking (frames 0..8), with the line
/// families coherence acts on, each view's pieces kept in memory.
fn fox_scene(coherence: &str, dir: &std::path::Path) -> shapecue::api::Scene {
    let fox = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/Fox.glb");
    let text = format!(
        "[input]\ngltf = {:?}\nclip = \"Walk\"\nweld = true\n[frames]\nend = 8\n\
         [[camera]]\ndirection = [1.0, 0.4, 0.2]\n\
         [effects]\ncontours = {{}}\nsuggestive_contours = {{}}\nridges = {{}}\nvalleys = {{}}\n\
         k_zero = {{}}\n[lines]\ncoherence = \"{coherence}\"\n\
         [output]\nsize = [320, 240]\nformats = [\"npz\"]\ndir = {:?}\n",
        fox.display().to_string(),
        dir.display().to_string()
    );
    shapecue::api::Scene::from_str(std::path::Path::new("fox.toml"), &text).unwrap()
}

/// Scenes of an animation: coherence on draws the first frame as off does,
/// bit for bit, and says so in the run's notes; every piece's face and
/// barycentric coordinates give back its world ends on that frame's pose;
/// the NPZ of every frame is written.
#[test]
fn a_scene_holds_its_lines_from_the_first_frame_on_and_keeps_their_provenance() {
    let dir = common::scratch("coherence-fox");
    let gpu = gpu();
    let fox = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/Fox.glb");
    let rest = shapecue::mesh::skinned::load_gltf(&fox)
        .unwrap()
        .welded()
        .0
        .rest;
    let faces = rest.faces.clone();
    let (lo, hi) = rest.bounds();
    let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let mut runs = Vec::new();
    for c in ["off", "on"] {
        let scene = fox_scene(c, &dir);
        let mut views = Vec::new();
        let report =
            shapecue::api::lines_on(&gpu, &scene, shapecue::api::LineFiles::Memory, &mut |v| {
                views.push(v);
                Ok(())
            })
            .unwrap();
        let held = report.notes.iter().any(|n| n.contains("coherence"));
        assert_eq!(held, c == "on", "{c}: {:?}", report.notes);
        assert_eq!(views.len(), 8);
        for v in &views {
            let n = v.npz.as_ref().expect("the scene writes NPZ");
            let a = &n.arrays;
            assert!(!a.face.is_empty(), "frame {}: pieces", v.frame);
            for i in 0..a.face.len() {
                let f = a.face[i];
                assert!(f >= 0, "frame {}: piece {i} lies on a face", v.frame);
                let at = |w: [f32; 3], k: usize| -> f64 {
                    (0..3)
                        .map(|j| f64::from(w[j]) * n.positions[faces[f as usize][j] as usize][k])
                        .sum()
                };
                for (w, p) in [(a.bary[i][0], a.a[i]), (a.bary[i][1], a.b[i])] {
                    let d = (0..3)
                        .map(|k| (at(w, k) - f64::from(p[k])).abs())
                        .fold(0.0, f64::max);
                    assert!(
                        d < 1e-4 * diag,
                        "frame {}: piece {i} is {d} off its face",
                        v.frame
                    );
                }
            }
        }
        runs.push(views);
    }
    let bits =
        |v: &shapecue::api::LineView| -> Vec<u32> { bytemuck::cast_slice(&v.segments).to_vec() };
    assert!(
        bits(&runs[0][0]) == bits(&runs[1][0]),
        "frame 0: the same bits"
    );
    assert!(
        (1..8).any(|k| bits(&runs[0][k]) != bits(&runs[1][k])),
        "coherence changes some later frame"
    );
}

/// The same scene run into its folder writes an NPZ per frame and view.
#[test]
fn a_scene_writes_the_pieces_of_every_frame_as_npz() {
    let dir = common::scratch("coherence-npz");
    let fox = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/Fox.glb");
    let scene = dir.join("fox.toml");
    std::fs::write(
        &scene,
        format!(
            "[input]\ngltf = {:?}\nclip = \"Walk\"\nweld = true\n[frames]\nend = 4\n\
             [[camera]]\ndirection = [1.0, 0.4, 0.2]\n[effects]\nridges = {{}}\n\
             [output]\nsize = [320, 240]\nformats = [\"svg\", \"npz\"]\ndir = {:?}\n",
            fox.display().to_string(),
            dir.join("out").display().to_string()
        ),
    )
    .unwrap();
    let (_, stdout) = common::succeeded(common::cli().args(["render", scene.to_str().unwrap()]));
    for f in 0..4 {
        for ext in ["npz", "svg"] {
            let p = dir.join(format!("out/fox_f{f:04}_v00.{ext}"));
            let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            if ext == "npz" {
                assert_eq!(&bytes[..4], b"PK\x03\x04", "a zip");
            }
        }
    }
    let report = std::fs::read_to_string(dir.join("out/fox_report.json")).unwrap();
    assert!(report.contains("\"npz\""), "the npz pass is in the report");
    assert!(stdout.contains("wrote"), "{stdout}");
    // Held over the frames (the default for an animation): the notes say
    // so and each NPZ holds the chains' ids across frames.
    let has = |hay: &[u8], needle: &[u8]| hay.windows(needle.len()).any(|w| w == needle);
    let npz = || std::fs::read(dir.join("out/fox_f0002_v00.npz")).unwrap();
    assert!(report.contains("lines held over the frames"), "{report}");
    assert!(has(&npz(), b"chain_id.npy"));
    // --coherence off: each frame's lines on their own, no chain ids.
    common::succeeded(common::cli().args([
        "render",
        scene.to_str().unwrap(),
        "--force",
        "--coherence",
        "off",
    ]));
    let report = std::fs::read_to_string(dir.join("out/fox_report.json")).unwrap();
    assert!(!report.contains("lines held over the frames"), "{report}");
    assert!(!has(&npz(), b"chain_id.npy"));
}
