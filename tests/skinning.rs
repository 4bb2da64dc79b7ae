//! Skinning: glTF skins and clips load, the bind pose reproduces the rest
//! mesh, the device matches the CPU twin on several frames of every model,
//! and bad requests are clear errors.

mod common;

use common::{gpu, max_abs_diff as max_dev, model_path, to_f32};

use shapecue::cpu::skinning::skin_lbs;
use shapecue::mesh::skinned::{SkinnedMesh, load_gltf};
use shapecue::stages::skinning::Skinner;

/// The shared glTF model `name`, loaded, or `None` (after saying so) when
/// absent.
fn model(name: &str) -> Option<SkinnedMesh> {
    let p = model_path(name)?;
    Some(load_gltf(&p).unwrap_or_else(|e| panic!("{name}: {e}")))
}

const MODELS: [&str; 5] = [
    "SimpleSkin.gltf",
    "RiggedSimple.glb",
    "CesiumMan.glb",
    "Fox.glb",
    "BrainStem.glb",
];

fn extent(m: &SkinnedMesh) -> f32 {
    let (lo, hi) = m.rest.bounds();
    (0..3).map(|k| (hi[k] - lo[k]) as f32).fold(0.0, f32::max)
}

#[test]
fn models_load_with_skins_and_clips() {
    for name in MODELS {
        let Some(m) = model(name) else { return };
        assert!(
            !m.rest.faces.is_empty() && !m.joint_nodes.is_empty(),
            "{name}"
        );
        assert!(!m.clips.is_empty(), "{name}: no clips");
        assert!(m.weights.iter().all(|w| {
            let s: f32 = w.iter().sum();
            s == 0.0 || (s - 1.0).abs() < 1e-5
        }));
        m.rest.validate(name).unwrap();
    }
    if let Some(b) = model("BrainStem.glb") {
        assert_eq!(b.rest.positions.len(), 34_159);
        assert_eq!(b.joint_nodes.len(), 18);
    }
}

#[test]
fn bind_pose_reproduces_the_rest_mesh() {
    // The bind pose: every joint at the inverse of its inverse bind matrix,
    // through the device. Translation-only and rotated matrices check the
    // column-major layout.
    if let Some(m) = model("RiggedSimple.glb") {
        let rest = to_f32(&m.rest.positions);
        let mut sk = Skinner::new(gpu(), &m).unwrap();
        let ident = SkinnedMesh::flatten(&vec![glam::Mat4::IDENTITY; m.joint_nodes.len()]);
        sk.pose(&ident).unwrap();
        assert!(max_dev(&sk.read().unwrap(), &rest) < 1e-6);
        let shift = glam::Mat4::from_translation(glam::Vec3::new(1.0, -2.0, 3.0));
        sk.pose(&SkinnedMesh::flatten(&vec![shift; m.joint_nodes.len()]))
            .unwrap();
        let moved = sk.read().unwrap();
        for (p, q) in moved.iter().zip(&rest) {
            assert!((p[0] - q[0] - 1.0).abs() < 1e-5 && (p[1] - q[1] + 2.0).abs() < 1e-5);
        }
    }
    // The nodes' rest transforms are the bind pose in these files (not in
    // SimpleSkin, whose root joint rests 0.5 away from its bind position).
    for name in ["RiggedSimple.glb", "CesiumMan.glb", "BrainStem.glb"] {
        let Some(m) = model(name) else { return };
        let mats = SkinnedMesh::flatten(&m.joint_matrices(None, 0.0).unwrap());
        let rest = to_f32(&m.rest.positions);
        let cpu = skin_lbs(&rest, &m.joints, &m.weights, &mats);
        let d = max_dev(&cpu, &rest) / extent(&m);
        eprintln!("{name}: bind pose max deviation {d:.2e} of the extent");
        assert!(d < 1e-4, "{name}: {d}");
    }
}

#[test]
fn device_matches_cpu_twin_on_animation_frames() {
    for name in MODELS {
        let Some(m) = model(name) else { return };
        let rest = to_f32(&m.rest.positions);
        let mut sk = Skinner::new(gpu(), &m).unwrap();
        let clip = &m.clips[0];
        let mut moved = 0.0f32;
        for f in 0..5 {
            let t = clip.duration * f as f32 / 4.0;
            let mats = SkinnedMesh::flatten(&m.joint_matrices(Some(0), t).unwrap());
            sk.pose(&mats).unwrap();
            let dev = sk.read().unwrap();
            let cpu = skin_lbs(&rest, &m.joints, &m.weights, &mats);
            let d = max_dev(&dev, &cpu) / extent(&m);
            assert!(d < 1e-5, "{name} t={t}: device vs CPU {d}");
            assert!(dev.iter().flatten().all(|c| c.is_finite()));
            moved = moved.max(max_dev(&dev, &rest) / extent(&m));
        }
        assert!(
            moved > 1e-3,
            "{name}: the clip does not move the mesh ({moved})"
        );
    }
}

#[test]
fn bad_requests_are_errors() {
    let Some(m) = model("SimpleSkin.gltf") else {
        return;
    };
    assert!(m.joint_matrices(Some(99), 0.0).is_err());
    let mut sk = Skinner::new(gpu(), &m).unwrap();
    assert!(sk.pose(&[0.0; 5]).is_err());
    let mut mats = SkinnedMesh::flatten(&m.joint_matrices(None, 0.0).unwrap());
    mats[0] = f32::NAN;
    assert!(sk.pose(&mats).is_err());
    let missing = std::env::temp_dir().join("shapecue-missing.glb");
    let e = load_gltf(&missing).unwrap_err().to_string();
    assert!(e.contains("shapecue-missing.glb"), "{e}");
    let junk = std::env::temp_dir().join(format!("shapecue-junk-{}.gltf", std::process::id()));
    std::fs::write(&junk, b"{ not json").unwrap();
    let e = load_gltf(&junk).unwrap_err().to_string();
    assert!(e.contains("shapecue-junk"), "{e}");
    let _ = std::fs::remove_file(&junk);
}

#[test]
fn welding_a_gltf_skin_joins_its_seams() {
    // Fox.glb splits its vertices along UV seams: unwelded, most of its
    // edges are boundaries (a wireframe in an edges picture).
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/Fox.glb");
    let m = shapecue::mesh::skinned::load_gltf(&path).unwrap();
    let boundary = |faces: &[[u32; 3]]| -> f64 {
        let mask = shapecue::cpu::feature_lines_curves::boundary_mask(faces);
        let edges: u32 = mask.iter().map(|b| b.count_ones()).sum();
        f64::from(edges) / (3 * faces.len()) as f64
    };
    let (w, differ) = m.welded();
    assert!(w.rest.n_vertices() < m.rest.n_vertices() / 2);
    assert_eq!(w.rest.n_faces(), m.rest.n_faces());
    assert_eq!(
        (w.joints.len(), w.weights.len()),
        (w.rest.n_vertices(), w.rest.n_vertices())
    );
    let (before, after) = (boundary(&m.rest.faces), boundary(&w.rest.faces));
    assert!(
        before > 0.5 && after < 0.05,
        "boundary edges {before} -> {after}"
    );
    // Seams split one skinned vertex: the merged copies carry its weights.
    assert_eq!(differ, 0);
}

#[test]
fn a_gltf_file_too_short_for_either_form_is_named() {
    let dir = std::env::temp_dir().join(format!("shapecue-gltf-short-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in [("empty.gltf", &b"{}"[..]), ("nothing.glb", &b""[..])] {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        let e = load_gltf(&p).unwrap_err().to_string();
        assert!(e.contains(name) && e.contains("too short for glTF"), "{e}");
        assert!(!e.contains("fill whole buffer"), "{e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
