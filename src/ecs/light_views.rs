//! This frame's lights as the renderer sees them ([`FrameLights`]): each sun, spot and point
//! light with its repaired parameters, its shadow settings and, when it casts, its views.
//! [`update_frame_lights`](crate::ecs::frame_lights::update_frame_lights) fills it each frame.

use bevy_ecs::entity::Entity;
use bevy_ecs::resource::Resource;
use glam::Vec3;

use crate::ecs::components::DirectionalLight;
use crate::ecs::lights::{PointLight, SpotLight};
use crate::ecs::view_list::{SPOT_NEAR, ShadowView};
use crate::math::cascades::CascadeSet;
use crate::math::clipmap::ClipmapSet;
use crate::math::light_budget::LightKind;
use crate::math::pages::PageLayout;
use crate::math::point::PointView;
use crate::math::spot::{SpotInput, SpotView};
use crate::settings::ShadowSettings;

/// A directional light this frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunView {
    /// The light's entity.
    pub entity: Entity,
    /// Unit direction the light travels.
    pub direction: Vec3,
    /// The light's parameters (repaired where out of range).
    pub light: DirectionalLight,
    /// Sanitized shadow settings (the entity's [`ShadowSettings`], else the defaults).
    pub settings: ShadowSettings,
    /// Side of its maps this frame, texels: what it asks for (its settings' resolution, or
    /// for a positional light without settings the budget's), lowered by the shadow-memory
    /// budget; point lights share the largest cube face any shadowed one gets.
    pub resolution: u32,
    /// Cascades; `count == 0` when the light casts no shadows this frame.
    pub cascades: CascadeSet,
    /// Its clipmap's levels this frame (no level with the cascade layout).
    pub clipmap: ClipmapSet,
    /// How its clipmap's levels are paged: the frame's first sun with a virtual clipmap
    /// (its levels then render into the page pool); None for every other sun.
    pub paged: Option<PageLayout>,
}

/// A spot light this frame. Positions are relative to the [`RenderOrigin`](crate::ecs::origin::RenderOrigin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLightView {
    /// The light's entity.
    pub entity: Entity,
    /// Position of the light.
    pub position: Vec3,
    /// Unit direction the light shines along.
    pub direction: Vec3,
    /// The light's parameters (repaired where out of range).
    pub light: SpotLight,
    /// Sanitized shadow settings (filter, bias, normal offset, and `resolution`: the side of
    /// its map; the cascade fields are unused).
    pub settings: ShadowSettings,
    /// Side of its maps this frame, texels: what it asks for (its settings' resolution, or
    /// for a positional light without settings the budget's), lowered by the shadow-memory
    /// budget; point lights share the largest cube face any shadowed one gets.
    pub resolution: u32,
    /// The shadow view, relative to the render origin, when the light casts a shadow this
    /// frame.
    pub shadow: Option<SpotView>,
}

impl SpotLightView {
    /// What its shadow view is made from: its placement, cone, range, the near plane
    /// [`SPOT_NEAR`] and its map's side (also what a standalone pass takes,
    /// [`StandaloneShadows::render_spot`](crate::render::shadows::standalone::StandaloneShadows::render_spot)).
    pub fn shadow_input(&self) -> SpotInput {
        SpotInput {
            position: self.position,
            direction: self.direction,
            outer_angle: self.light.outer_angle,
            range: self.light.range,
            near: SPOT_NEAR,
            resolution: self.resolution,
        }
    }
}

/// A point light this frame. Its position is relative to the [`RenderOrigin`](crate::ecs::origin::RenderOrigin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLightView {
    /// The light's entity.
    pub entity: Entity,
    /// Position of the light.
    pub position: Vec3,
    /// The light's parameters (repaired where out of range).
    pub light: PointLight,
    /// Sanitized shadow settings (filter, bias, normal offset, and `resolution`: the side of
    /// each cube face — shared by every shadowed point light, the largest any asks for; the
    /// cascade fields are unused).
    pub settings: ShadowSettings,
    /// Side of its maps this frame, texels: what it asks for (its settings' resolution, or
    /// for a positional light without settings the budget's), lowered by the shadow-memory
    /// budget; point lights share the largest cube face any shadowed one gets.
    pub resolution: u32,
    /// The six face views, relative to the render origin, when the light casts a shadow this
    /// frame.
    pub shadow: Option<PointView>,
}

/// Every light of this frame, per kind, in the order the ECS query returned them.
#[derive(Resource, Clone, Debug, Default)]
pub struct FrameLights {
    /// Directional lights.
    pub suns: Vec<SunView>,
    /// Spot lights.
    pub spots: Vec<SpotLightView>,
    /// Point lights.
    pub points: Vec<PointLightView>,
}

impl FrameLights {
    /// The first directional light, if any (the one the bench scores and the inspector edits
    /// first).
    pub fn sun(&self) -> Option<&SunView> {
        self.suns.first()
    }

    /// Number of lights of every kind.
    pub fn len(&self) -> usize {
        self.suns.len() + self.spots.len() + self.points.len()
    }

    /// True when there is no light at all.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Index of light `index` of `kind` in the renderer's light list (suns, then spots, then
    /// points), which is the `i` a material passes to `get_light(i)`.
    pub fn light_index(&self, kind: LightKind, index: usize) -> usize {
        match kind {
            LightKind::Directional => index,
            LightKind::Spot => self.suns.len() + index,
            LightKind::Point => self.suns.len() + self.spots.len() + index,
        }
    }

    /// The frame's paged sun, if one casts shadows (its levels are virtual).
    pub fn paged_sun(&self) -> Option<&SunView> {
        self.suns.iter().find(|s| s.paged.is_some() && s.cascades.count > 0)
    }

    /// The sun at `light` in the renderer's light list, if that light is a sun.
    pub fn sun_at(&self, light: u32) -> Option<&SunView> {
        self.suns.get(light as usize)
    }

    /// The spot light at `light` in the renderer's light list, if that light is a spot light.
    pub fn spot_at(&self, light: u32) -> Option<&SpotLightView> {
        let index = (light as usize).checked_sub(self.suns.len())?;
        self.spots.get(index)
    }

    /// The settings of the light `view` belongs to.
    pub fn view_settings(&self, view: &ShadowView) -> Option<&ShadowSettings> {
        match view.light_kind {
            LightKind::Directional => self.sun_at(view.light).map(|s| &s.settings),
            LightKind::Spot => self.spot_at(view.light).map(|s| &s.settings),
            LightKind::Point => self.point_at(view.light).map(|p| &p.settings),
        }
    }

    /// The point light at `light` in the renderer's light list, if that light is a point light.
    pub fn point_at(&self, light: u32) -> Option<&PointLightView> {
        let index = (light as usize).checked_sub(self.suns.len() + self.spots.len())?;
        self.points.get(index)
    }

    /// The settings of the light at `light` in the renderer's light list.
    pub fn settings_at(&self, light: u32) -> Option<&ShadowSettings> {
        let sun = self.sun_at(light).map(|s| &s.settings);
        sun.or_else(|| self.spot_at(light).map(|s| &s.settings))
            .or_else(|| self.point_at(light).map(|p| &p.settings))
    }

    /// The settings of every light, in the renderer's order (suns, spots, points).
    pub fn all_settings(&self) -> impl Iterator<Item = &ShadowSettings> {
        let suns = self.suns.iter().map(|s| &s.settings);
        suns.chain(self.spots.iter().map(|s| &s.settings))
            .chain(self.points.iter().map(|p| &p.settings))
    }

    /// True when a light asks for contact shadows (they need the depth prepass).
    pub fn any_contact_shadows(&self) -> bool {
        self.all_settings().any(|s| s.filter.contact.enabled())
    }
}
