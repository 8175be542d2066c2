//! The hard-case scene: ground, a 2 m box on it, a slab 1.5 m up, a pole, and a 7×5 m roof
//! 3 m up that shades a large part of the view; every shadow setting at its default.

use glam::Vec3;
use penumbra::scene::SceneDesc;

/// Where the camera is and what it sees, and where the sun shines from.
#[derive(Clone, Copy, Debug)]
pub struct Case {
    /// Direction the sunlight travels.
    pub sun: Vec3,
    /// Camera position.
    pub camera: Vec3,
    /// Point the camera looks at.
    pub target: Vec3,
    /// Vertical field of view, degrees.
    pub fov: f32,
    /// Near plane, metres.
    pub near: f32,
    /// Far plane, metres.
    pub far: f32,
    /// More objects (RON, each followed by a comma).
    pub extra: &'static str,
}

/// The usual sun: high, from behind the camera's left.
pub const SUN: Vec3 = Vec3::new(-0.5, -1.0, -0.3);

impl Default for Case {
    fn default() -> Self {
        Self {
            sun: SUN,
            camera: Vec3::new(2.0, 6.0, 12.0),
            target: Vec3::new(0.0, 0.5, -1.0),
            fov: 60.0,
            near: 0.1,
            far: 500.0,
            extra: "",
        }
    }
}

impl Case {
    /// The default view under a sun travelling along `sun`.
    pub fn sun(sun: Vec3) -> Self {
        Self { sun, ..Self::default() }
    }

    /// The scene, parsed.
    pub fn desc(&self) -> SceneDesc {
        let (c, t, s) = (self.camera, self.target, self.sun);
        let text = format!(
            r#"Scene(
    camera: (position: ({}, {}, {}), target: ({}, {}, {}), fov: {}, near: {}, far: {}),
    sun: (direction: ({}, {}, {}), angular_diameter: 1.0),
    ambient: (0.1, 0.1, 0.1),
    materials: {{ "m": (base_color: (0.7, 0.7, 0.7, 1)) }},
    objects: [
        (shape: Plane(size: (200, 200)), material: "m", cast_shadows: false),
        (shape: Cuboid(size: (2, 2, 2)), material: "m", translation: (0, 1, 0)),
        (shape: Cuboid(size: (3, 0.2, 3)), material: "m", translation: (4, 1.5, -2)),
        (shape: Cuboid(size: (0.3, 5, 0.3)), material: "m", translation: (-4, 2.5, -3)),
        (shape: Cuboid(size: (7, 0.3, 5)), material: "m", translation: (-2, 3, 3)),
        {}
    ],
)"#,
            c.x, c.y, c.z, t.x, t.y, t.z, self.fov, self.near, self.far, s.x, s.y, s.z, self.extra
        );
        load(&text)
    }
}

/// Parses a scene, panicking with the located error.
pub fn load(text: &str) -> SceneDesc {
    SceneDesc::from_str(text, "hard_case.ron").unwrap_or_else(|e| panic!("{e}"))
}
