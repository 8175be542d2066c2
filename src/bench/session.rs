//! A scene loaded into an ECS world with the shadow systems, plus the handles the benchmark
//! turns: the scored light's settings (see [`focus`](crate::bench::focus)) and the camera's
//! transform.

use bevy_app::App;
use bevy_transform::components::Transform;
use glam::{Quat, Vec3};

use crate::app::{SpawnError, spawn_scene};
use crate::bench::config::PagesOverride;
use crate::bench::focus::{Focus, FocusKind, choose_focus};
use crate::ecs::assets::{AlphaMode, Images, Materials, Meshes};
use crate::ecs::components::{Camera3d, DirectionalLight, ViewportSize};
use crate::ecs::instances::RenderInstances;
use crate::ecs::light_views::FrameLights;
use crate::ecs::origin::RenderOrigin;
use crate::ecs::plugin::ShadowPlugin;
use crate::ecs::stats::ShadowStats;
use crate::ecs::view::ActiveView;
use crate::ecs::view_list::ShadowLightBudget;
use crate::reference::{AlphaMask, Caster, ReferenceScene, SunDisc};
use crate::render::plugin::publish_seen_depths;
use crate::render::renderer::Renderer;
use crate::scene::SceneDesc;
use crate::settings::{ShadowSettings, SunLayout};

/// A running scene.
pub struct SceneSession {
    /// The app (ShadowPlugin only; rendering is driven by the caller).
    pub app: App,
    base: ShadowSettings,
    camera: Transform,
    target: Vec3,
    focus: Option<Focus>,
    /// Given to every preset whose sun is paged ([`BenchConfig::pages`]).
    ///
    /// [`BenchConfig::pages`]: crate::bench::BenchConfig::pages
    pub pages: Option<PagesOverride>,
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
            target: desc.camera.target,
            focus: None,
            pages: None,
        };
        session.camera = session.camera_transform();
        session.app.update();
        session.focus = choose_focus(session.lights());
        if let Some(focus) = session.focus.filter(|f| f.kind != FocusKind::Sun) {
            // NOTE: a spot or point light's presets start from its own settings. One without
            // a settings component gets the settings it is drawn with (the defaults at the
            // budget's resolution for its kind) now, so that the presets change a component in
            // place and never move the light to another archetype (which could reorder the
            // lights).
            let world = session.app.world_mut();
            let own = world.get::<ShadowSettings>(focus.entity).copied();
            let budget = world.get_resource::<ShadowLightBudget>().copied().unwrap_or_default();
            let base = own.unwrap_or_else(|| {
                ShadowSettings::with_resolution(match focus.kind {
                    FocusKind::Point => budget.point_resolution,
                    _ => budget.spot_resolution,
                })
            });
            if own.is_none() {
                world.entity_mut(focus.entity).insert(base);
                session.app.update();
            }
            session.base = base;
        }
        Ok(session)
    }

    /// The light the benchmark scores on this scene (see [`choose_focus`]), chosen when the
    /// session started; None when the scene has neither a directional light nor a shadowed
    /// spot or point light.
    pub fn focus(&self) -> Option<Focus> {
        self.focus
    }

    /// The focus light's index in the renderer's light list this frame, for
    /// [`Renderer::set_focus_light`](crate::render::Renderer::set_focus_light) (0 without a
    /// focus light).
    pub fn focus_light_index(&self) -> usize {
        self.focus.and_then(|f| f.light_index(self.lights())).unwrap_or(0)
    }

    /// The camera's target in the scene file, relative to the render origin (as every
    /// position the renderer and the reference see).
    pub fn camera_target(&self) -> Vec3 {
        self.target
            - self
                .app
                .world()
                .get_resource::<RenderOrigin>()
                .map_or(Vec3::ZERO, |o| o.0)
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

    /// Sets the scored light's settings to its own from the scene, changed by `apply`: for a
    /// spot or point light in focus, that light's settings; otherwise every directional
    /// light's (the scene's `shadows`, changed).
    pub fn apply_settings(&mut self, apply: fn(&mut ShadowSettings)) {
        let mut settings = self.base;
        apply(&mut settings);
        if let (
            Some(o),
            SunLayout::VirtualClipmap {
                virtual_resolution,
                pool_pages,
                ..
            },
        ) = (self.pages, &mut settings.map.layout)
        {
            *virtual_resolution = o.virtual_resolution.unwrap_or(*virtual_resolution);
            *pool_pages = o.pool_pages.unwrap_or(*pool_pages);
        }
        let world = self.app.world_mut();
        if let Some(focus) = self.focus.filter(|f| f.kind != FocusKind::Sun) {
            if let Some(mut s) = world.get_mut::<ShadowSettings>(focus.entity) {
                *s = settings;
            }
            return;
        }
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

    /// Waits for the depths `renderer`'s frames saw and hands them to the shadow systems, so
    /// the next frame's depth-bounds fit follows the last frame rendered; returns whether
    /// they changed.
    pub fn take_seen_depths(&mut self, renderer: &mut Renderer) -> bool {
        renderer.wait_for_seen_depths();
        publish_seen_depths(self.app.world_mut(), renderer)
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
                world_from_local: instances.gpu[i as usize].world_from_local(),
                mask: masks.get(key.material.0 as usize).cloned().flatten(),
            })
        });
        ReferenceScene::build(casters)
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::settings::{PcssQuality, ShadowMode};

    fn shipped(name: &str) -> SceneDesc {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes").join(name);
        SceneDesc::load(&path).unwrap_or_else(|e| panic!("{e}"))
    }

    fn pcf3(s: &mut ShadowSettings) {
        s.filter.mode = ShadowMode::Pcf;
        s.filter.pcf_radius = 3;
    }

    #[test]
    fn the_spot_scene_scores_its_spot_light_and_presets_change_only_it() {
        let mut session = SceneSession::new(&shipped("spot.ron"), 64, 36).unwrap_or_else(|e| panic!("{e}"));
        let focus = session.focus().expect("a focus light");
        assert_eq!(focus.kind, FocusKind::Spot);
        assert!(session.lights().suns.is_empty());
        assert_eq!(session.focus_light_index(), 0);
        session.apply_settings(pcf3);
        session.update();
        let spot = session.lights().spots[0];
        assert_eq!(
            (spot.settings.filter.mode, spot.settings.filter.pcf_radius),
            (ShadowMode::Pcf, 3)
        );
        // The rest is the spot light's own settings, not the scene's `shadows`.
        assert_eq!(spot.settings.map.resolution, 2048);
        assert_eq!(spot.settings.filter.pcss_quality, PcssQuality::High);
        assert_eq!(spot.light.radius, 0.25);
    }

    #[test]
    fn scenes_with_a_sun_score_it_and_spot_lights_keep_their_settings() {
        let mut session = SceneSession::new(&shipped("lights.ron"), 64, 36).unwrap_or_else(|e| panic!("{e}"));
        let focus = session.focus().expect("a focus light");
        assert_eq!(focus.kind, FocusKind::Sun);
        assert_eq!(session.focus_light_index(), 0);
        let before: Vec<ShadowSettings> = session.lights().spots.iter().map(|s| s.settings).collect();
        session.apply_settings(pcf3);
        session.update();
        let lights = session.lights();
        assert!(lights.suns.iter().all(|s| s.settings.filter.pcf_radius == 3));
        let after: Vec<ShadowSettings> = lights.spots.iter().map(|s| s.settings).collect();
        assert_eq!(before, after);
    }

    #[test]
    fn a_spot_light_without_settings_keeps_its_map_size_under_presets() {
        let desc = SceneDesc::from_str(
            r#"Scene(
            camera: (position: (0, 8, 8), target: (0, 0, 0), fov: 50, near: 0.1, far: 100),
            lights: [
                Spot(position: (3, 5, 0), direction: (0, -1, 0), shadows_enabled: false),
                Spot(position: (0, 5, 0), direction: (0, -1, 0), radius: 0.1),
            ],
            objects: [(shape: Cuboid(size: (1, 1, 1)), material: "m", translation: (0, 0.5, 0))],
            materials: { "m": () },
        )"#,
            "test.ron",
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let mut session = SceneSession::new(&desc, 64, 36).unwrap_or_else(|e| panic!("{e}"));
        let focus = session.focus().expect("the shadowed spot light");
        let index = session.focus_light_index();
        assert_eq!(
            session.lights().spot_at(index as u32).map(|s| s.light.radius),
            Some(0.1)
        );
        session.apply_settings(pcf3);
        session.update();
        assert_eq!(session.focus_light_index(), index, "the light list keeps its order");
        let spot = session.lights().spot_at(index as u32).expect("the focus light");
        assert_eq!(spot.entity, focus.entity);
        assert_eq!(
            (spot.settings.filter.pcf_radius, spot.settings.map.resolution),
            (3, 1024)
        );
    }
}
