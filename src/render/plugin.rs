//! [`RenderPlugin`]: renders every frame, after the shadow systems, with the [`Renderer`]
//! resource the application inserted (headless or windowed).

use bevy_app::{App, Last, Plugin};
use bevy_ecs::system::{Local, Res, ResMut};

use crate::ecs::assets::{Images, Materials, Meshes};
use crate::ecs::components::{AmbientLight, ViewportSize};
use crate::ecs::draw_groups::{ShadowDrawGroups, ViewDrawGroups};
use crate::ecs::instances::RenderInstances;
use crate::ecs::view::ActiveView;
use crate::render::frame::FrameInputs;
use crate::render::renderer::Renderer;

/// Adds the render system. Requires [`ShadowPlugin`](crate::ecs::ShadowPlugin) and a
/// [`Renderer`] resource; frames without a renderer are skipped.
#[derive(Default)]
pub struct RenderPlugin;

impl Plugin for RenderPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(Last, render_frame);
    }
}

/// Renders the frame the shadow systems prepared.
#[allow(clippy::too_many_arguments)]
pub fn render_frame(
    renderer: Option<ResMut<Renderer>>,
    meshes: Res<Meshes>,
    materials: Res<Materials>,
    images: Res<Images>,
    instances: Res<RenderInstances>,
    shadow_groups: Res<ShadowDrawGroups>,
    view_groups: Res<ViewDrawGroups>,
    view: Res<ActiveView>,
    ambient: Res<AmbientLight>,
    mut viewport: ResMut<ViewportSize>,
    mut frame_index: Local<u32>,
) {
    let Some(mut renderer) = renderer else { return };
    let (width, height) = renderer.size();
    if viewport.width != width || viewport.height != height {
        *viewport = ViewportSize { width, height };
    }
    renderer.render(&FrameInputs {
        meshes: &meshes,
        materials: &materials,
        images: &images,
        instances: &instances,
        shadow_groups: &shadow_groups,
        view_groups: &view_groups,
        view: &view,
        ambient: &ambient,
        frame_index: *frame_index,
    });
    *frame_index = frame_index.wrapping_add(1);
}
