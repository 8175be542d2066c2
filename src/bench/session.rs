//! A scene loaded into an ECS world with the shadow systems, plus the handles the benchmark
//! turns: the sun's settings and the camera's transform.

use bevy_app::App;
use bevy_transform::components::Transform;
use glam::{Quat, Vec3};

use crate::app::{SpawnError, spawn_scene};
use crate::ecs::assets::{AlphaMode, Images, Materials, Meshes};
use crate::ecs::components::{Camera3d, DirectionalLight, ViewportSize};
use crate::ecs::frame_lights::FrameLights;
use crate::ecs::instances::RenderInstances;
use crate::ecs::plugin::ShadowPlugin;
use crate::ecs::stats::ShadowStats;
use crate::ecs::view::ActiveView;
use crate::reference::{AlphaMask, Caster, ReferenceScene, SunDisc};
use crate::scene::SceneDesc;
use crate::settings::ShadowSettings;

/// A running scene.
pub struct SceneSession {
    /// The app (ShadowPlugin only; rendering is driven by the caller).
    pub app: App,
    base: ShadowSettings,
    camera: Transform,
}

impl SceneSession {
    /// Spawns `desc` for a `width`×`height` view.
    pub fn new(desc: &SceneDesc, width: u32, height: u32) -> Result<Self, SpawnError> {
        let mut app = App::new();
        app.add_plugins(ShadowPlugin);
        app.world_mut().insert_resource(ViewportSize { width, height });
        spawn_scene(app.world_mut(), desc)?;
        let mut session = Self {
            app,
            base: desc.shadows,
            camera: Transform::default(),
        };
        session.camera = session.camera_transform();
        session.app.update();
        Ok(session)
    }

    /// Changes the viewport size (the cascades follow the aspect ratio).
    pub fn set_viewport(&mut self, width: u32, height: u32) {
        self.app.world_mut().insert_resource(ViewportSize { width, height });
    }

    fn camera_transform(&mut self) -> Transform {
        let world = self.app.world_mut();
        let mut q = world.query::<(&Camera3d, &Transform)>();
        q.iter(world).next().map(|(_, t)| *t).unwrap_or_default()
    }

    /// Sets the sun's settings to the scene's own, changed by `apply`.
    pub fn apply_settings(&mut self, apply: fn(&mut ShadowSettings)) {
        let mut settings = self.base;
        apply(&mut settings);
        let world = self.app.world_mut();
        let mut q = world.query::<(&DirectionalLight, &mut ShadowSettings)>();
        for (_, mut s) in q.iter_mut(world) {
            *s = settings;
        }
    }

    /// Puts the camera back where the scene file had it, then moves it by `offset` (world)
    /// and turns it by `yaw` radians about world +Y.
    pub fn move_camera(&mut self, offset: Vec3, yaw: f32) {
        let start = self.camera;
        let world = self.app.world_mut();
        let mut q = world.query::<(&Camera3d, &mut Transform)>();
        for (_, mut t) in q.iter_mut(world) {
            t.translation = start.translation + offset;
            t.rotation = Quat::from_rotation_y(yaw) * start.rotation;
        }
    }

    /// The camera transform the scene file defines.
    pub fn start_camera(&self) -> Transform {
        self.camera
    }

    /// Runs the shadow systems for one frame.
    pub fn update(&mut self) {
        self.app.update();
    }

    /// This frame's statistics.
    pub fn stats(&self) -> &ShadowStats {
        self.app.world().resource::<ShadowStats>()
    }

    /// This frame's camera.
    pub fn view(&self) -> &ActiveView {
        self.app.world().resource::<ActiveView>()
    }

    /// This frame's lights.
    pub fn lights(&self) -> &FrameLights {
        self.app.world().resource::<FrameLights>()
    }

    /// The sun disc of the scene's first directional light, if it has one.
    pub fn sun_disc(&self) -> Option<SunDisc> {
        let sun = self.lights().sun()?;
        Some(SunDisc {
            direction: sun.direction,
            angular_diameter: sun.light.angular_diameter,
        })
    }

    /// Every shadow caster's triangles (with alpha masks) for the ray-traced reference.
    pub fn reference_scene(&self) -> ReferenceScene {
        let world = self.app.world();
        let instances = world.resource::<RenderInstances>();
        let meshes = world.resource::<Meshes>();
        let materials = world.resource::<Materials>();
        let images = world.resource::<Images>();
        let masks: Vec<Option<std::sync::Arc<AlphaMask>>> = materials
            .as_slice()
            .iter()
            .map(
                |m| match (m.alpha_mode, m.base_color_texture.and_then(|h| images.get(h))) {
                    (AlphaMode::Mask(cutoff), Some(image)) => Some(std::sync::Arc::new(AlphaMask {
                        width: image.width,
                        height: image.height,
                        alpha: image.rgba.chunks_exact(4).map(|p| p[3]).collect(),
                        factor: m.base_color.w,
                        cutoff,
                    })),
                    (AlphaMode::Mask(cutoff), None) => Some(std::sync::Arc::new(AlphaMask {
                        width: 1,
                        height: 1,
                        alpha: vec![255],
                        factor: m.base_color.w,
                        cutoff,
                    })),
                    (AlphaMode::Opaque, _) => None,
                },
            )
            .collect();
        let casters = instances.casters.iter().filter_map(|&i| {
            let key = instances.keys[i as usize];
            Some(Caster {
                mesh: meshes.get(key.mesh)?,
                world_from_local: instances.gpu[i as usize].world_from_local,
                mask: masks.get(key.material.0 as usize).cloned().flatten(),
            })
        });
        ReferenceScene::build(casters)
    }
}
