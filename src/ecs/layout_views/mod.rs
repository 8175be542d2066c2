//! The shadow layouts' views: each layout turns its lights (and the camera, through the
//! light views of [`FrameLights`]) into [`ShadowView`]s — matrix, cull volume, storage slot
//! and what its WGSL module reads of the view
//! ([`ViewShading`](crate::ecs::view_list::ViewShading)) — in one module each: [`sun`]
//! (cascades and clipmap levels), [`spot`] and [`point`]. Nothing outside these modules needs
//! to know what a layout's views hold.

pub mod point;
pub mod spot;
pub mod sun;

use crate::ecs::light_views::FrameLights;
use crate::ecs::receiver_culling::ReceiverCache;
use crate::ecs::view_list::ShadowView;
use crate::settings::ShadowSettings;

/// Appends every layout's views of this frame's lights, in the order of the storages:
/// the suns' cascades or clipmap levels (culled against `receivers`), the spot lights', the
/// point lights' faces. A new layout adds its call here.
pub fn push_views(lights: &FrameLights, receivers: &ReceiverCache, sink: &mut ViewSink<'_>) {
    sun::push_sun_views(lights, receivers, sink);
    spot::push_spot_views(lights, sink);
    point::push_point_views(lights, sink);
}

/// Where the layouts append their views: the frame's views, in order, each with the settings
/// of its light at the same position (what the view cache keys on).
pub struct ViewSink<'a> {
    /// The frame's views.
    pub views: &'a mut Vec<ShadowView>,
    /// The settings of each view's light.
    pub settings: &'a mut Vec<ShadowSettings>,
}

impl ViewSink<'_> {
    /// Appends `view`, drawn with its light's `settings`.
    pub fn push(&mut self, view: ShadowView, settings: ShadowSettings) {
        self.views.push(view);
        self.settings.push(settings);
    }
}
