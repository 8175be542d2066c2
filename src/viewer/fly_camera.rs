//! A fly camera: yaw and pitch from mouse drags, movement from held keys. Pure state and
//! math, so it is tested without a window.

use bevy_transform::components::Transform;
use glam::{EulerRot, Quat, Vec3};

/// Movement keys currently held.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MoveKeys {
    /// W: forward.
    pub forward: bool,
    /// S: backward.
    pub back: bool,
    /// A: left.
    pub left: bool,
    /// D: right.
    pub right: bool,
    /// E: up.
    pub up: bool,
    /// Q: down.
    pub down: bool,
    /// Shift: move four times faster.
    pub fast: bool,
}

/// Orientation as yaw (about +Y) and pitch (about the camera's right axis), plus position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    /// World position.
    pub position: Vec3,
    /// Radians about +Y; 0 looks along -Z.
    pub yaw: f32,
    /// Radians up (+) or down (-), kept within ±89°.
    pub pitch: f32,
    /// Metres per second.
    pub speed: f32,
    /// Radians per pixel of mouse drag.
    pub sensitivity: f32,
}

const MAX_PITCH: f32 = 89.0 * std::f32::consts::PI / 180.0;

impl FlyCamera {
    /// A camera at `position` looking at `target`.
    pub fn looking_at(position: Vec3, target: Vec3) -> Self {
        let d = (target - position).normalize_or(Vec3::NEG_Z);
        Self {
            position,
            yaw: (-d.x).atan2(-d.z),
            pitch: d.y.clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH),
            speed: 8.0,
            sensitivity: 0.004,
        }
    }

    /// Orientation.
    pub fn rotation(&self) -> Quat {
        Quat::from_euler(EulerRot::YXZ, self.yaw, self.pitch, 0.0)
    }

    /// Turns by a mouse drag of `(dx, dy)` pixels.
    pub fn drag(&mut self, dx: f32, dy: f32) {
        if !(dx.is_finite() && dy.is_finite()) {
            return;
        }
        self.yaw -= dx * self.sensitivity;
        self.pitch = (self.pitch - dy * self.sensitivity).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Changes the speed by `steps` mouse-wheel notches (each ×1.25), within 0.1–500 m/s.
    pub fn scroll_speed(&mut self, steps: f32) {
        if steps.is_finite() {
            self.speed = (self.speed * 1.25_f32.powf(steps)).clamp(0.1, 500.0);
        }
    }

    /// Moves for `dt` seconds with the held keys.
    pub fn advance(&mut self, keys: MoveKeys, dt: f32) {
        let r = self.rotation();
        let axis = |pos: bool, neg: bool| (pos as i32 - neg as i32) as f32;
        let local = Vec3::new(axis(keys.right, keys.left), 0.0, -axis(keys.forward, keys.back));
        let world = r * local + Vec3::Y * axis(keys.up, keys.down);
        let speed = if keys.fast { self.speed * 4.0 } else { self.speed };
        if world.length_squared() > 0.0 && dt.is_finite() {
            self.position += world.normalize() * speed * dt.clamp(0.0, 0.25);
        }
    }

    /// Moves `metres` horizontally the way the camera faces (its yaw; pitch ignored), as a
    /// scripted walk does each frame.
    pub fn walk(&mut self, metres: f32) {
        if metres.is_finite() {
            let (sin, cos) = self.yaw.sin_cos();
            self.position += Vec3::new(-sin, 0.0, -cos) * metres;
        }
    }

    /// The camera's transform.
    pub fn transform(&self) -> Transform {
        Transform {
            translation: self.position,
            rotation: self.rotation(),
            scale: Vec3::ONE,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_walk_moves_level_the_way_the_camera_faces() {
        let mut cam = FlyCamera::looking_at(Vec3::new(0.0, 10.0, 0.0), Vec3::new(3.0, 0.0, -4.0));
        cam.walk(2.5);
        // Facing (3, −4) on the ground (pitched down): 2.5 m along it, height kept.
        assert!(
            cam.position.abs_diff_eq(Vec3::new(1.5, 10.0, -2.0), 1e-5),
            "{}",
            cam.position
        );
        cam.walk(f32::NAN);
        assert!(cam.position.is_finite());
    }

    #[test]
    fn looking_at_faces_the_target() {
        let cam = FlyCamera::looking_at(Vec3::new(0.0, 2.0, 5.0), Vec3::new(3.0, 1.0, -2.0));
        let expected = (Vec3::new(3.0, 1.0, -2.0) - Vec3::new(0.0, 2.0, 5.0)).normalize();
        assert!(cam.transform().forward().abs_diff_eq(expected, 1e-5));
    }

    #[test]
    fn forward_key_moves_along_the_view_and_pitch_is_clamped() {
        let mut cam = FlyCamera::looking_at(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0));
        cam.advance(
            MoveKeys {
                forward: true,
                ..Default::default()
            },
            0.25,
        );
        assert!(
            cam.position.abs_diff_eq(Vec3::new(2.0, 0.0, 0.0), 1e-4),
            "{:?}",
            cam.position
        );
        cam.drag(0.0, -1e6);
        assert!((cam.pitch - MAX_PITCH).abs() < 1e-6);
        cam.drag(f32::NAN, 0.0);
        assert!(cam.yaw.is_finite());
        let before = cam.position;
        cam.advance(
            MoveKeys {
                up: true,
                fast: true,
                ..Default::default()
            },
            0.1,
        );
        assert!((cam.position - before).abs_diff_eq(Vec3::new(0.0, 3.2, 0.0), 1e-4));
    }

    #[test]
    fn the_wheel_scales_speed_within_limits() {
        let mut cam = FlyCamera::looking_at(Vec3::ZERO, Vec3::X);
        let start = cam.speed;
        cam.scroll_speed(1.0);
        assert!((cam.speed - start * 1.25).abs() < 1e-4);
        cam.scroll_speed(1e6);
        assert_eq!(cam.speed, 500.0);
        cam.scroll_speed(f32::NAN);
        assert_eq!(cam.speed, 500.0);
        cam.scroll_speed(-1e6);
        assert_eq!(cam.speed, 0.1);
    }
}
