//! The viewer's camera: the scene's own first view until the user moves it,
//! then an orbit (eye around a target, about the view's up axis), pan and
//! zoom, handed to the executor as an explicit eye and target (world
//! coordinates).

use glam::Vec3;
use shapecue::render::{Camera, Placement, framed};
use shapecue::scene::file::{CameraKind, ViewSpec};

/// An orbiting camera over a scene's first view.
#[derive(Clone, Debug)]
pub struct Orbit {
    /// The scene's view, used as is until the camera moves (so that an
    /// unmoved view draws exactly what `shapecue render` draws).
    initial: ViewSpec,
    /// The world camera the initial view resolves to.
    home: Camera,
    /// Current eye, target and up (world).
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Moved since the last reset.
    pub moved: bool,
}

impl Orbit {
    /// The orbit of `view` over world `bounds` at image aspect `aspect`.
    pub fn new(
        view: ViewSpec,
        bounds: ([f64; 3], [f64; 3]),
        aspect: f32,
    ) -> shapecue::Result<Orbit> {
        let (placement, target) = match &view.kind {
            CameraKind::LookAt { eye, target } => {
                (Placement::At(Vec3::from(*eye)), target.map(Vec3::from))
            }
            CameraKind::Fit(d) => (Placement::Fit(Vec3::from(*d)), None),
        };
        let up = view.up.map(Vec3::from);
        let home = framed(placement, target, up, view.fov, view.ortho, bounds, aspect)?;
        Ok(Orbit {
            initial: view,
            eye: home.eye,
            target: home.target,
            up: home.up.normalize_or(Vec3::Y),
            home,
            moved: false,
        })
    }

    /// Back to the scene's view.
    pub fn reset(&mut self) {
        self.eye = self.home.eye;
        self.target = self.home.target;
        self.up = self.home.up.normalize_or(Vec3::Y);
        self.moved = false;
    }

    /// The view to hand to the executor.
    pub fn view(&self) -> ViewSpec {
        if !self.moved {
            return self.initial.clone();
        }
        ViewSpec {
            kind: CameraKind::LookAt {
                eye: self.eye.into(),
                target: Some(self.target.into()),
            },
            up: Some(self.up.into()),
            ..self.initial.clone()
        }
    }

    /// Turns the eye about the target: `yaw` degrees about the up axis,
    /// `pitch` degrees towards it (stopping 1° short of the poles).
    pub fn orbit(&mut self, yaw: f32, pitch: f32) {
        let off = self.eye - self.target;
        let dist = off.length();
        if dist <= 0.0 || !dist.is_finite() {
            return;
        }
        let d = glam::Quat::from_axis_angle(self.up, -yaw.to_radians()) * (off / dist);
        // Angle from the up axis, kept in [1°, 179°].
        let polar = d.dot(self.up).clamp(-1.0, 1.0).acos();
        let new_polar = (polar - pitch.to_radians()).clamp(1f32.to_radians(), 179f32.to_radians());
        let right = self.up.cross(d).normalize_or(Vec3::X);
        let d = glam::Quat::from_axis_angle(right, polar - new_polar) * d;
        self.eye = self.target + d.normalize() * dist;
        self.moved = true;
    }

    /// Moves eye and target across the view: `dx`, `dy` in fractions of the
    /// view's height at the target (right and up positive).
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let off = self.eye - self.target;
        let dist = off.length();
        let fwd = -off / dist.max(f32::MIN_POSITIVE);
        let right = fwd.cross(self.up).normalize_or(Vec3::X);
        let up = right.cross(fwd);
        let height = 2.0 * dist * (0.5 * self.initial.fov.to_radians()).tan();
        let shift = (right * dx + up * dy) * height;
        self.eye -= shift;
        self.target -= shift;
        self.moved = true;
    }

    /// Moves the eye towards the target: the distance times `factor` (< 1
    /// closer), kept within 1e-4 and 1e4 times the scene camera's distance
    /// (beyond them the view holds nothing of the model, and the camera's
    /// numbers leave single precision).
    pub fn zoom(&mut self, factor: f32) {
        if !(factor > 0.0 && factor.is_finite()) {
            return;
        }
        let off = self.eye - self.target;
        let home = self
            .home
            .eye
            .distance(self.home.target)
            .max(f32::MIN_POSITIVE);
        let d = off.length();
        if d > 0.0 {
            let want = (d * factor).clamp(1e-4 * home, 1e4 * home);
            self.eye = self.target + off * (want / d);
        }
        self.moved = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zoom_stays_within_four_decades_of_the_scene_distance() {
        let mut o = orbit();
        let home = o.eye.distance(o.target);
        o.zoom(1e30);
        assert!((o.eye.distance(o.target) / home - 1e4).abs() < 1.0);
        assert!(o.eye.is_finite());
        o.zoom(1e-30);
        assert!((o.eye.distance(o.target) / home - 1e-4).abs() < 1e-6);
    }

    fn orbit() -> Orbit {
        let view = ViewSpec {
            kind: CameraKind::Fit([0.0, 0.0, 1.0]),
            up: None,
            fov: 40.0,
            ortho: false,
        };
        Orbit::new(view, ([-1.0; 3], [1.0; 3]), 4.0 / 3.0).unwrap()
    }

    #[test]
    fn orbit_pan_zoom_and_reset() {
        let mut o = orbit();
        let home = o.view();
        let (eye, target) = (o.eye, o.target);
        let dist = eye.distance(target);
        o.orbit(30.0, 20.0);
        assert!((o.eye.distance(o.target) - dist).abs() < 1e-4 * dist);
        assert!(o.eye.distance(eye) > 0.1 * dist);
        o.orbit(0.0, -20.0);
        o.orbit(-30.0, 0.0);
        assert!(o.eye.distance(eye) < 1e-4 * dist, "{} vs {eye}", o.eye);
        // Pitch stops short of the pole.
        o.orbit(0.0, 500.0);
        let d = (o.eye - o.target).normalize();
        assert!(d.dot(o.up) < 1.0 - 1e-5 && d.is_finite());
        o.pan(0.1, 0.0);
        assert!((o.eye - o.target).is_finite());
        o.zoom(0.5);
        assert!((o.eye.distance(o.target) - 0.5 * dist).abs() < 1e-3 * dist);
        assert!(matches!(o.view().kind, CameraKind::LookAt { .. }));
        o.reset();
        assert_eq!(o.view(), home);
        assert_eq!((o.eye, o.target), (eye, target));
    }
}
