//! Per-frame view state: the active camera, found in the ECS each frame by
//! [`update_active_view`].

use bevy_ecs::resource::Resource;
use bevy_ecs::system::{Query, Res, ResMut};
use bevy_transform::components::GlobalTransform;
use glam::{Quat, Vec3};

use crate::ecs::components::{Camera3d, ViewportSize};
use crate::ecs::instances::RenderInstances;
use crate::ecs::origin::RenderOrigin;
use crate::ecs::placement::world_pose;
use crate::ecs::stats::{ShadowDiagnostics, ShadowStats};
use crate::math::frustum::CameraView;
use crate::math::seen_depths::SeenDepths;

/// The camera of this frame; its position is relative to the [`RenderOrigin`]. The lights
/// are in [`FrameLights`](crate::ecs::light_views::FrameLights).
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct ActiveView {
    /// The first entity with [`Camera3d`] and a valid [`GlobalTransform`], if any.
    pub camera: Option<(CameraView, Camera3d)>,
}

/// What the camera saw in an earlier frame, for suns that fit their cascades with
/// [`CascadeFit::DepthBounds`](crate::settings::CascadeFit): written by the
/// [`RenderPlugin`](crate::render::RenderPlugin) when a depth reduction comes back from the
/// GPU (or by an application that measures it itself), read when the cascades are computed.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct SeenByCamera {
    /// The depths seen, if any came back.
    pub depths: Option<SeenDepths>,
    /// The render origin the depths' world boxes are relative to.
    pub origin: Vec3,
}

impl SeenByCamera {
    /// The depths seen, with their world boxes made relative to the render origin `origin`.
    pub fn relative_to(&self, origin: Vec3) -> Option<SeenDepths> {
        self.depths.map(|d| d.shifted(origin - self.origin))
    }
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

/// Finds the camera for this frame and starts the frame's diagnostics.
pub fn update_active_view(
    cameras: Query<(&Camera3d, &GlobalTransform)>,
    viewport: Res<ViewportSize>,
    origin: Res<RenderOrigin>,
    instances: Res<RenderInstances>,
    mut view: ResMut<ActiveView>,
    mut stats: ResMut<ShadowStats>,
    mut diagnostics: ResMut<ShadowDiagnostics>,
) {
    diagnostics.begin_frame();
    view.camera = cameras
        .iter()
        .find_map(|(c, t)| Some((c, world_pose(t)?)))
        .map(|(c, pose)| {
            let c = sanitize_camera(*c, &mut diagnostics);
            (camera_view(&c, pose, &viewport, origin.0), c)
        });
    if instances.skipped > 0 {
        diagnostics.warn(format!(
            "{} mesh entities are not drawn: non-finite or zero-scale transform, or a missing mesh or material",
            instances.skipped
        ));
    }
    if view.camera.is_none() && !cameras.is_empty() {
        diagnostics.warn("every camera has a non-finite or zero-scale transform; nothing is drawn".to_string());
    }
    stats.frames += 1;
}
