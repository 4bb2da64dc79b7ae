//! Scenes of geometry the caller holds: the front door's pictures (the
//! lines picture, the edges picture, the strokes picture) are one-view
//! scenes over a mesh or a volume in memory, run by the scene executor like
//! any scene file.

use super::{CameraKind, Scene, Source, ViewSpec};
use crate::mesh::Mesh;
use crate::volume::Volume;
use std::path::Path;
use std::sync::Arc;

/// A mesh the caller holds. Two are equal when they are the same mesh (the
/// same allocation), as two scene files are equal when they name one file.
#[derive(Clone)]
pub struct HeldMesh(pub Arc<Mesh>);

/// A volume the caller holds; equal when it is the same volume.
#[derive(Clone)]
pub struct HeldVolume(pub Arc<Volume>);

impl PartialEq for HeldMesh {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl PartialEq for HeldVolume {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl std::fmt::Debug for HeldMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a mesh in memory ({} vertices, {} faces)",
            self.0.n_vertices(),
            self.0.n_faces()
        )
    }
}

impl std::fmt::Debug for HeldVolume {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [x, y, z] = self.0.dims;
        write!(f, "a volume in memory ({x} × {y} × {z})")
    }
}

/// Where a picture is taken from and its size: the camera fields every
/// picture shares (the lines, edges and strokes pictures, a scene's view).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shot {
    /// Eye position (world space); `None`: fitted to the bounds from
    /// `fit_direction`, the bounding sphere filling the view with a 5 %
    /// margin.
    pub eye: Option<glam::Vec3>,
    /// Point looked at from `eye`; `None`: the centre of the bounding box
    /// (a fitted camera always looks at the centre).
    pub target: Option<glam::Vec3>,
    /// Up direction; `None`: +Y, or +Z when looking along Y.
    pub up: Option<glam::Vec3>,
    /// Vertical field of view in degrees.
    pub fov_deg: f32,
    /// Orthographic projection (showing the height the perspective view
    /// shows at the target).
    pub ortho: bool,
    /// Image width and height in pixels.
    pub size: [u32; 2],
    /// Direction (centre → eye) of the fitted camera when `eye` is `None`.
    pub fit_direction: glam::Vec3,
}

impl Default for Shot {
    fn default() -> Self {
        Shot {
            eye: None,
            target: None,
            up: None,
            fov_deg: 40.0,
            ortho: false,
            size: [800, 600],
            fit_direction: glam::Vec3::ONE,
        }
    }
}

impl Shot {
    /// The scene's view of this shot.
    pub fn view(&self) -> ViewSpec {
        let kind = match self.eye {
            Some(e) => CameraKind::LookAt {
                eye: e.to_array(),
                target: self.target.map(|t| t.to_array()),
            },
            None => CameraKind::Fit(self.fit_direction.to_array()),
        };
        ViewSpec {
            kind,
            up: self.up.map(|u| u.to_array()),
            fov: self.fov_deg,
            ortho: self.ortho,
        }
    }
}

impl Scene {
    /// A one-view scene of held geometry with every default of a scene file
    /// (no cue yet, PNG and SVG off): the front door sets the cues and their
    /// styles, and runs it through the executor.
    pub fn held(source: Source, shot: &Shot) -> Scene {
        let text = "[input]\ngenerate = \"sphere\"\n[effects]\nshading = {}\n";
        let mut s = Scene::from_str(Path::new("picture"), text).expect("the minimal scene parses");
        s.name = "picture".into();
        s.source = source;
        s.views = vec![shot.view()];
        s.effects.cues.clear();
        s.size = shot.size;
        s.png = false;
        s.svg = false;
        s.npz = false;
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_scene_has_the_defaults_of_a_scene_file_and_no_cue() {
        let mesh = Arc::new(crate::mesh::Generated::Torus.mesh(200).1);
        let s = Scene::held(Source::Held(HeldMesh(mesh.clone())), &Shot::default());
        assert!(s.effects.cues.is_empty());
        assert_eq!(s.views, vec![Shot::default().view()]);
        assert_eq!((s.size, s.png, s.svg), ([800, 600], false, false));
        // Equal only to a scene of the same mesh.
        let again = Scene::held(Source::Held(HeldMesh(mesh)), &Shot::default());
        assert_eq!(s, again);
        let other = Arc::new(crate::mesh::Generated::Torus.mesh(200).1);
        assert_ne!(
            s,
            Scene::held(Source::Held(HeldMesh(other)), &Shot::default())
        );
    }
}
