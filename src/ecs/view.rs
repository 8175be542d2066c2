//! Per-frame view state: the active camera, the sun, and the sun's cascades, computed from
//! the ECS each frame by [`update_active_view`].

use std::time::Instant;

use bevy_ecs::resource::Resource;
use bevy_ecs::system::{Query, Res, ResMut};
use bevy_transform::components::GlobalTransform;
use glam::{Quat, Vec3};

use crate::ecs::components::{Camera3d, DirectionalLight, ViewportSize};
use crate::ecs::instances::RenderInstances;
use crate::ecs::origin::RenderOrigin;
use crate::ecs::placement::{world_forward, world_pose};
use crate::ecs::stats::{ShadowDiagnostics, ShadowStats};
use crate::math::cascades::{CascadeInput, CascadeSet, compute_cascades};
use crate::math::frustum::CameraView;
use crate::settings::ShadowSettings;

/// The sun as the renderer sees it this frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunView {
    /// Unit direction the light travels.
    pub direction: Vec3,
    /// The light's parameters.
    pub light: DirectionalLight,
    /// Sanitized shadow settings.
    pub settings: ShadowSettings,
    /// Cascades; `count == 0` when the light casts no shadows.
    pub cascades: CascadeSet,
}

/// The camera and sun of this frame. Positions (the camera, the cascade matrices) are relative
/// to the [`RenderOrigin`].
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct ActiveView {
    /// The first entity with [`Camera3d`] and a valid [`GlobalTransform`], if any.
    pub camera: Option<(CameraView, Camera3d)>,
    /// The first entity with [`DirectionalLight`] and a valid [`GlobalTransform`], if any.
    pub sun: Option<SunView>,
}

/// Builds the camera's view description from its world pose and the viewport's aspect, in
/// coordinates relative to the render origin.
fn camera_view(camera: &Camera3d, pose: (Quat, Vec3), viewport: &ViewportSize, origin: Vec3) -> CameraView {
    let (rotation, translation) = pose;
    let world_from_view = glam::Mat4::from_rotation_translation(rotation, translation - origin);
    CameraView {
        world_from_view,
        fov_y: camera.fov_y,
        aspect: viewport.aspect(),
        near: camera.near,
        far: camera.far,
    }
}

/// Sane camera parameters: a user camera with a zero near plane or a NaN field of view is
/// repaired (with a warning) instead of producing NaN matrices.
fn sanitize_camera(mut camera: Camera3d, diagnostics: &mut ShadowDiagnostics) -> Camera3d {
    let fov_ok = camera.fov_y.is_finite() && camera.fov_y > 1e-4 && camera.fov_y < std::f32::consts::PI - 1e-4;
    let near_ok = camera.near.is_finite() && camera.near > 0.0;
    let far_ok = camera.far.is_finite() && camera.far > camera.near;
    if !(fov_ok && near_ok && far_ok) {
        let d = Camera3d::default();
        diagnostics.warn(format!(
            "camera has fov_y {}, near {}, far {}: expected 0 < fov_y < π and 0 < near < far; using defaults for the bad values",
            camera.fov_y, camera.near, camera.far
        ));
        if !fov_ok {
            camera.fov_y = d.fov_y;
        }
        if !near_ok {
            camera.near = d.near;
        }
        if !(camera.far.is_finite() && camera.far > camera.near) {
            camera.far = camera.near * 1e4;
        }
    }
    camera
}

/// Finds the camera and sun and computes the sun's cascades for this frame.
#[allow(clippy::too_many_arguments)]
pub fn update_active_view(
    cameras: Query<(&Camera3d, &GlobalTransform)>,
    lights: Query<(&DirectionalLight, &GlobalTransform, Option<&ShadowSettings>)>,
    viewport: Res<ViewportSize>,
    origin: Res<RenderOrigin>,
    instances: Res<RenderInstances>,
    mut view: ResMut<ActiveView>,
    mut stats: ResMut<ShadowStats>,
    mut diagnostics: ResMut<ShadowDiagnostics>,
) {
    let start = Instant::now();
    diagnostics.begin_frame();
    view.camera = cameras
        .iter()
        .find_map(|(c, t)| Some((c, world_pose(t)?)))
        .map(|(c, pose)| {
            let c = sanitize_camera(*c, &mut diagnostics);
            (camera_view(&c, pose, &viewport, origin.0), c)
        });
    view.sun = None;
    for (light, transform, settings) in &lights {
        let Some(direction) = world_forward(transform) else {
            diagnostics.warn(format!(
                "directional light has a non-finite or degenerate transform {:?}; it is ignored",
                transform.affine()
            ));
            continue;
        };
        let (settings, problems) = settings.copied().unwrap_or_default().sanitized();
        for p in problems {
            diagnostics.warn(format!("shadow settings: {p}; clamped"));
        }
        let mut angular_diameter = light.angular_diameter;
        if !(angular_diameter.is_finite() && (0.0..=0.6).contains(&angular_diameter)) {
            diagnostics.warn(format!(
                "light angular_diameter {angular_diameter} rad is outside 0..0.6; using 0.53°"
            ));
            angular_diameter = DirectionalLight::default().angular_diameter;
        }
        let count = if light.shadows_enabled {
            settings.cascade_count as usize
        } else {
            0
        };
        let cascades = match (&view.camera, count) {
            (Some((camera, _)), 1..) => compute_cascades(&CascadeInput {
                camera: *camera,
                light_direction: direction,
                scene_bounds: instances.caster_bounds,
                count,
                split_lambda: settings.split_lambda,
                max_distance: settings.max_distance,
                resolution: settings.resolution,
                fit: settings.fit,
                angular_diameter,
                blend_width: settings.blend_width,
            }),
            _ => CascadeSet {
                count: 0,
                ..CascadeSet::default()
            },
        };
        view.sun = Some(SunView {
            direction,
            light: DirectionalLight {
                angular_diameter,
                ..*light
            },
            settings,
            cascades,
        });
        break;
    }
    if instances.skipped > 0 {
        diagnostics.warn(format!(
            "{} mesh entities are not drawn: non-finite or zero-scale transform, or a missing mesh or material",
            instances.skipped
        ));
    }
    stats.cascades_cpu = start.elapsed();
    if view.camera.is_none() && !cameras.is_empty() {
        diagnostics.warn("every camera has a non-finite or zero-scale transform; nothing is drawn".to_string());
    }
    stats.frames += 1;
}
