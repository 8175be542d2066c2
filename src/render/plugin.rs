//! [`RenderPlugin`]: renders every frame, after the shadow systems, with the [`Renderer`]
//! resource the application inserted (headless or windowed).

use bevy_app::{App, Last, Plugin, PostUpdate};
use bevy_ecs::change_detection::Mut;
use bevy_ecs::schedule::IntoScheduleConfigs;
use bevy_ecs::system::Local;
use bevy_ecs::system::{Res, ResMut};
use bevy_ecs::world::World;

use crate::ecs::clipmap_scroll::ScrollResync;
use crate::ecs::components::ViewportSize;
use crate::ecs::light_views::FrameLights;
use crate::ecs::plugin::ShadowSystems;
use crate::ecs::receiver_culling::ShadowCulling;
use crate::ecs::shadow_memory::ShadowMemoryBudget;
use crate::ecs::stats::{ShadowDiagnostics, log_diagnostics};
use crate::ecs::view::SeenByCamera;
use crate::render::frame_inputs::FrameInputs;
use crate::render::options::{RenderOptions, SunDepth};
use crate::render::renderer::Renderer;
use crate::render::shadows::casters::UNORM16_STEPS;
use crate::render::shadows::storage::depth_texel_bytes;

/// Adds the render system. Requires [`ShadowPlugin`](crate::ecs::ShadowPlugin) and a
/// [`Renderer`] resource; frames without a renderer are skipped.
#[derive(Default)]
pub struct RenderPlugin;

impl Plugin for RenderPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<RenderOptions>();
        app.add_systems(PostUpdate, sync_culling.before(ShadowSystems::Cull));
        app.add_systems(PostUpdate, sync_memory_costs.before(ShadowSystems::ComputeCascades));
        app.add_systems(
            PostUpdate,
            warn_coarse_sun_depth
                .after(ShadowSystems::ComputeCascades)
                .before(log_diagnostics),
        );
        app.add_systems(Last, render_frame);
    }
}

/// Hands culling what the renderer can do and was asked ([`ShadowCulling::single_pass`],
/// [`ShadowCulling::multiview_views`], [`ShadowCulling::cached`],
/// [`ShadowCulling::gpu_camera`]) before this frame's lists are made.
pub fn sync_culling(
    options: Option<Res<RenderOptions>>,
    renderer: Option<Res<Renderer>>,
    culling: Option<ResMut<ShadowCulling>>,
) {
    let (Some(renderer), Some(mut culling)) = (renderer, culling) else {
        return;
    };
    let asked = options.as_ref().is_some_and(|o| o.single_pass_cascades);
    let cached = options.as_ref().is_none_or(|o| o.shadow_cache);
    let views = renderer.gpu.multiview_views;
    let options = options.as_deref().copied().unwrap_or_default();
    let gpu_camera = options.gpu_culling && options.multi_draw && renderer.gpu.indirect_first_instance;
    let now = (asked, views, cached, gpu_camera);
    if (
        culling.single_pass,
        culling.multiview_views,
        culling.cached,
        culling.gpu_camera,
    ) != now
        || culling.gpu_shadows != gpu_camera
    {
        culling.single_pass = asked;
        culling.multiview_views = views;
        culling.cached = cached;
        culling.gpu_camera = gpu_camera;
        culling.gpu_shadows = gpu_camera;
    }
}

/// Hands the shadow-memory budget the bytes of a sun's depth texel
/// ([`RenderOptions::sun_depth`]) before this frame's storages are fitted to it.
pub fn sync_memory_costs(options: Option<Res<RenderOptions>>, budget: Option<ResMut<ShadowMemoryBudget>>) {
    let Some(mut budget) = budget else {
        return;
    };
    let bytes = u64::from(depth_texel_bytes(sun_depth(options.as_deref()).format()));
    if budget.costs.sun_depth_texel != bytes {
        budget.costs.sun_depth_texel = bytes;
    }
}

/// The suns' depth format `options` ask for (the default without them).
fn sun_depth(options: Option<&RenderOptions>) -> SunDepth {
    options.map_or_else(SunDepth::default, |o| o.sun_depth)
}

/// Warns about each sun whose 16-bit depth ([`RenderOptions::sun_depth`]) steps more coarsely
/// than its shadow texels in some cascade (a sun near the horizon over casters kilometres
/// apart along its light): contacts may then leak by up to a step, which 32-bit floats avoid.
/// Logged once per sun ([`ShadowDiagnostics`]).
pub fn warn_coarse_sun_depth(
    options: Option<Res<RenderOptions>>,
    lights: Option<Res<FrameLights>>,
    diagnostics: Option<ResMut<ShadowDiagnostics>>,
) {
    let (Some(lights), Some(mut diagnostics)) = (lights, diagnostics) else {
        return;
    };
    if sun_depth(options.as_deref()) != SunDepth::Unorm16 {
        return;
    }
    for sun in lights.suns.iter().filter(|s| s.paged.is_none()) {
        if sun.cascades.depth_step_in_texels(UNORM16_STEPS) > 1.0 {
            let name = sun.entity.to_string();
            diagnostics.warn_about(
                &name,
                format!(
                    "directional light {name}: its cascades span so much depth that a step of 16-bit depth is coarser than a shadow texel, so contacts may leak by up to a step; RenderOptions::sun_depth = SunDepth::Float32 (--sun-depth 32) draws its maps in 32-bit floats"
                ),
            );
        }
    }
}

/// Renders the frame the shadow systems prepared (an exclusive system: it reads the shadow
/// resources through [`FrameInputs::from_world`] while holding the renderer).
pub fn render_frame(world: &mut World, mut frame_index: Local<u32>) {
    if !world.contains_resource::<Renderer>() {
        return;
    }
    world.resource_scope(|world, mut renderer: Mut<Renderer>| {
        let (width, height) = renderer.size();
        if *world.resource::<ViewportSize>() != (ViewportSize { width, height }) {
            world.insert_resource(ViewportSize { width, height });
        }
        renderer.render(&FrameInputs::from_world(world, *frame_index));
        if let Some(mut resync) = world.get_resource_mut::<ScrollResync>() {
            resync.views.extend(renderer.take_scroll_resync());
        }
        publish_seen_depths(world, &renderer);
    });
    *frame_index = frame_index.wrapping_add(1);
}

/// Hands the latest depths the renderer saw to the ECS ([`SeenByCamera`]), for the next
/// frame's depth-bounds cascade fit (unchanged while nothing new came back); returns whether
/// they changed.
pub fn publish_seen_depths(world: &mut World, renderer: &Renderer) -> bool {
    let Some((depths, origin)) = renderer.seen_depths() else {
        return false;
    };
    let seen = SeenByCamera {
        depths: Some(depths),
        origin,
    };
    let changed = world.get_resource::<SeenByCamera>() != Some(&seen);
    if changed {
        world.insert_resource(seen);
    }
    changed
}
