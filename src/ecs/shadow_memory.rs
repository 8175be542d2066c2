//! The shadow-memory budget: [`ShadowMemoryBudget`] says how many bytes the shadow storages
//! (depth arrays, moments with their mips, the blur's scratch) may take and what the device
//! stores moments in; [`ShadowMemory`] is this frame's account — per shadowed light what it
//! asked for, what it got and its bytes, per array and in total — computed by
//! [`apply_memory_budget`] from the shadowed lights before their views are made, so the
//! renderer never allocates past the budget.
//!
//! A paged sun's page pool is fixed by its settings
//! ([`SunLayout::pool_bytes`](crate::settings::SunLayout::pool_bytes)): it is taken from the
//! budget first, and the other maps share the rest.
//!
//! Over budget, the lights smallest on screen have their maps halved first (suns last), never
//! below 256² ([`fit_budget`](crate::math::shadow_memory::fit_budget)), with one warning naming
//! them. A light that still does not fit gets no shadow, and [`ShadowMemory::error`] names it
//! with the bytes it needs at 256²: a headless render fails with that message.

use bevy_ecs::entity::Entity;
use bevy_ecs::resource::Resource;

use crate::ecs::light_views::FrameLights;
use crate::math::evsm::MomentPrecision;
use crate::math::light_budget::{LightKind, RankingView, screen_coverage};
use crate::math::shadow_memory::{
    BudgetFit, DEFAULT_SUN_DEPTH_TEXEL_BYTES, LightRequest, MIN_BUDGET_RESOLUTION, MOMENT_MIPS, MemoryCosts,
    MomentSupport, MomentUse, StorageBytes, alone_bytes, cascade_moment_format, fit_budget_into, storage_index,
};
use crate::settings::{ShadowMode, ShadowSettings};
use crate::text::format_bytes;

/// Bytes in a mebibyte.
pub const MIB: u64 = 1 << 20;

/// The default budget on a GPU with memory of its own, bytes (2 GiB). wgpu reports no memory
/// size, so the default follows the kind of adapter.
pub const GPU_BUDGET: u64 = 2048 * MIB;
/// The default budget on an integrated or unknown GPU, bytes (1 GiB).
pub const SHARED_BUDGET: u64 = 1024 * MIB;
/// The default budget on software Vulkan (a CPU adapter, whose memory is the process's own),
/// bytes (512 MiB).
pub const SOFTWARE_BUDGET: u64 = 512 * MIB;

/// How much memory the shadow storages may take. The default is [`GPU_BUDGET`] with 32-bit
/// moments (what a desktop GPU has); the renderer's
/// [`shadow_memory_budget`](crate::render::GpuContext::shadow_memory_budget) sizes it to its
/// device, and an application may set `bytes`.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowMemoryBudget {
    /// Most bytes of shadow maps, moments and scratch together.
    pub bytes: u64,
    /// The device's moment formats.
    pub costs: MemoryCosts,
}

impl Default for ShadowMemoryBudget {
    fn default() -> Self {
        Self {
            bytes: GPU_BUDGET,
            costs: MemoryCosts {
                vsm_texel: 16,
                sun_depth_texel: DEFAULT_SUN_DEPTH_TEXEL_BYTES,
                support: MomentSupport {
                    fp32_filterable: true,
                    unorm16: true,
                },
            },
        }
    }
}

/// One shadowed light's share.
#[derive(Clone, Debug, PartialEq)]
pub struct LightMemory {
    /// The light.
    pub entity: Entity,
    /// How messages name it: its kind, then its [`Name`](bevy_ecs::name::Name) (else its
    /// entity).
    pub name: String,
    /// Its kind.
    pub kind: LightKind,
    /// Texels per side it asked for.
    pub asked: u32,
    /// Texels per side it got (0: no shadow, the budget could not hold it).
    pub granted: u32,
    /// Layers (cascades, 1, or a cube's 6).
    pub views: u32,
    /// Bytes of its layers: depth and moments at its array's side (the array's scratch is
    /// not in it).
    pub bytes: u64,
}

/// This frame's shadow memory, before anything is allocated.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct ShadowMemory {
    /// The budget it was fitted to, bytes.
    pub budget: u64,
    /// The shadowed lights (suns, then spot lights, then point lights).
    pub lights: Vec<LightMemory>,
    /// The arrays: cascades, spot lights, point lights.
    pub storages: [StorageBytes; 3],
    /// Bytes of the paged sun's page pool (0 without one).
    pub pages: u64,
    /// Lights lowered to fit, as one warning (None when nothing was lowered).
    pub warning: Option<String>,
    /// Lights the budget cannot hold at all, with their bytes.
    pub error: Option<String>,
}

impl ShadowMemory {
    /// Bytes of the three arrays and the page pool together.
    pub fn total(&self) -> u64 {
        self.storages.iter().map(StorageBytes::total).sum::<u64>() + self.pages
    }

    /// The account as text: a line with the total, the budget and what it is made of, then
    /// one line per shadowed light (what the command line and the inspector show).
    pub fn lines(&self) -> Vec<String> {
        let sum = |f: fn(&StorageBytes) -> u64| format_bytes(self.storages.iter().map(f).sum());
        let shift: u64 = self.storages.iter().map(|s| s.shift).sum();
        let mut shift = if shift > 0 {
            format!(", clipmap shift {}", format_bytes(shift))
        } else {
            String::new()
        };
        if self.pages > 0 {
            shift += &format!(", page pool {}", format_bytes(self.pages));
        }
        let mut lines = vec![format!(
            "{} of a {} budget (depth {}, moments {}, blur scratch {}{shift})",
            format_bytes(self.total()),
            format_bytes(self.budget),
            sum(|s| s.depth),
            sum(|s| s.moments),
            sum(|s| s.scratch)
        )];
        lines.extend(self.lines_of_lights());
        lines
    }

    /// One line per shadowed light: its name, views and side, bytes.
    fn lines_of_lights(&self) -> Vec<String> {
        self.lights
            .iter()
            .map(|l| {
                let side = self.storages[storage_index(l.kind)].side;
                let mut size = match l.granted {
                    0 => "no shadow (over budget)".to_owned(),
                    g if g < l.asked => format!("{} × {g}² (asked {}²)", l.views, l.asked),
                    g => format!("{} × {g}²", l.views),
                };
                if l.granted > 0 && l.granted < side {
                    size += &format!(" in layers of {side}²");
                }
                format!("{}: {size}, {}", l.name, format_bytes(l.bytes))
            })
            .collect()
    }
}

/// Reused buffers of [`apply_memory_budget`], and what it fitted last (an unchanged frame
/// reuses the fit and allocates nothing).
#[derive(Default)]
pub struct MemoryScratch {
    requests: Vec<LightRequest>,
    entities: Vec<Entity>,
    /// Bytes of the page pool, and the index of its sun among the requests.
    pool: Option<(u64, usize)>,
    last: Option<(Vec<LightRequest>, Vec<Entity>, ShadowMemoryBudget, BudgetFit)>,
    fit: BudgetFit,
}

/// What a light's settings make its moments.
fn moment_use(kind: LightKind, s: &ShadowSettings, fp32_filterable: bool) -> MomentUse {
    match (kind, s.filter.mode) {
        (LightKind::Directional, ShadowMode::Evsm | ShadowMode::Evsm4 | ShadowMode::Msm) => MomentUse::Sun {
            msm: s.filter.mode == ShadowMode::Msm,
            fp32: s.filter.moments.precision.resolve(fp32_filterable) == MomentPrecision::Fp32,
            blur: !s.filter.moments.contact_hardening && s.filter.moments.blur > 0.0,
            hardening: s.filter.moments.contact_hardening,
        },
        (LightKind::Spot | LightKind::Point, ShadowMode::Vsm) => MomentUse::Vsm {
            blur: s.filter.vsm.blur > 0,
        },
        _ => MomentUse::None,
    }
}

/// Bytes of a paged sun's pool with `settings` on a device with `support`: the atlas of depth
/// and, for a moment filter, its moments laid out the same (with [`MOMENT_MIPS`] levels for
/// contact hardening; 0 for another layout).
fn page_bytes(settings: &ShadowSettings, support: MomentSupport) -> u64 {
    let side = u64::from(settings.map.layout.pool_side());
    if side == 0 {
        return 0;
    }
    let (texel, mips) = match moment_use(LightKind::Directional, settings, support.fp32_filterable) {
        MomentUse::Sun {
            msm, fp32, hardening, ..
        } => {
            let format = cascade_moment_format([(msm, fp32)], support);
            (
                format.map_or(0, |f| f.texel_bytes()),
                if hardening { MOMENT_MIPS } else { 1 },
            )
        }
        _ => (0, 1),
    };
    let texels: u64 = (0..mips).map(|k| (side >> k).max(1).pow(2)).sum();
    side * side * 4 + texels * texel
}

/// The request of shadowed light `id` (the renderer's light order) and its entity; `paged`
/// says it is the sun whose levels are paged (its memory is its pool: it asks for no view).
fn request(
    lights: &FrameLights,
    (id, paged): (usize, bool),
    ranking: &RankingView,
    fp32: bool,
) -> (LightRequest, Entity) {
    let spots_end = lights.suns.len() + lights.spots.len();
    let (kind, settings, resolution, views, bounds, entity) = if let Some(sun) = lights.suns.get(id) {
        let views = if paged { 0 } else { sun.settings.map.sun_views() };
        (
            LightKind::Directional,
            &sun.settings,
            sun.resolution,
            views,
            None,
            sun.entity,
        )
    } else if id < spots_end {
        let spot = &lights.spots[id - lights.suns.len()];
        let bounds = Some((spot.position, spot.light.range));
        (LightKind::Spot, &spot.settings, spot.resolution, 1, bounds, spot.entity)
    } else {
        let point = &lights.points[id - spots_end];
        let bounds = Some((point.position, point.light.range));
        (
            LightKind::Point,
            &point.settings,
            point.resolution,
            6,
            bounds,
            point.entity,
        )
    };
    let coverage = bounds.map_or(f32::INFINITY, |(centre, range)| screen_coverage(ranking, centre, range));
    let request = LightRequest {
        kind,
        resolution,
        views,
        // NOTE: a paged sun's moments are in its pool's bytes.
        moments: if paged {
            MomentUse::None
        } else {
            moment_use(kind, settings, fp32)
        },
        coverage,
        scrolls: kind == LightKind::Directional && !paged && settings.map.layout.clipmap_levels().is_some(),
        // NOTE: as `ecs::clipmap_scroll` decides: moments are blurred up to a layer's edges.
        wraps: !settings.filter.mode.effective(true).is_sun_moments(),
    };
    (request, entity)
}

/// Fits the shadowed lights (`shadowed`: ids in the renderer's light order, with sanitized
/// settings whose `mode` is the one each light is filtered with) to `budget`: lowers their
/// `settings.resolution`, and removes from `shadowed` those that cannot fit. Returns the new
/// account when it differs from last frame's (`name_of` names a light for it).
pub fn apply_memory_budget(
    lights: &mut FrameLights,
    shadowed: &mut Vec<usize>,
    ranking: &RankingView,
    budget: &ShadowMemoryBudget,
    name_of: impl Fn(Entity) -> Option<String>,
    scratch: &mut MemoryScratch,
) -> Option<ShadowMemory> {
    scratch.requests.clear();
    scratch.entities.clear();
    scratch.pool = None;
    let fp32 = budget.costs.support.fp32_filterable;
    for (k, &id) in shadowed.iter().enumerate() {
        // NOTE: the first shadowed sun with a virtual clipmap is paged (as `frame_lights`
        // chooses); another is a plain clipmap.
        let pool = lights
            .suns
            .get(id)
            .map_or(0, |s| page_bytes(&s.settings, budget.costs.support));
        let paged = pool > 0 && scratch.pool.is_none();
        if paged {
            scratch.pool = Some((pool, k));
        }
        let (request, entity) = request(lights, (id, paged), ranking, fp32);
        scratch.requests.push(request);
        scratch.entities.push(entity);
    }
    let pool = scratch.pool.map_or(0, |(bytes, _)| bytes);
    fit_budget_into(
        &scratch.requests,
        &budget.costs,
        budget.bytes.saturating_sub(pool),
        &mut scratch.fit,
    );
    // NOTE: a moving light changes its screen coverage every frame; the account only changes
    // when what was asked or given does, so a moving frame allocates nothing either.
    let same = scratch.last.as_ref().is_some_and(|(r, e, b, fit)| {
        let asked = |a: &LightRequest, b: &LightRequest| {
            LightRequest { coverage: 0.0, ..*a } == LightRequest { coverage: 0.0, ..*b }
        };
        r.len() == scratch.requests.len()
            && r.iter().zip(&scratch.requests).all(|(a, b)| asked(a, b))
            && *e == scratch.entities
            && b == budget
            && *fit == scratch.fit
    });
    let account = (!same).then(|| {
        let last = (
            scratch.requests.clone(),
            scratch.entities.clone(),
            *budget,
            scratch.fit.clone(),
        );
        scratch.last = Some(last);
        let requests = (&scratch.requests[..], &scratch.entities[..], scratch.pool);
        account(requests, budget, &scratch.fit, name_of)
    });
    let spots_end = lights.suns.len() + lights.spots.len();
    for (&id, &granted) in shadowed.iter().zip(&scratch.fit.resolutions) {
        let resolution = if let Some(sun) = lights.suns.get_mut(id) {
            &mut sun.resolution
        } else if id < spots_end {
            &mut lights.spots[id - lights.suns.len()].resolution
        } else {
            &mut lights.points[id - spots_end].resolution
        };
        *resolution = granted.max(1);
    }
    if !scratch.fit.dropped.is_empty() {
        let mut k = 0;
        let fit = &scratch.fit;
        shadowed.retain(|_| {
            k += 1;
            fit.resolutions[k - 1] > 0
        });
    }
    account
}

/// The account of a fit of `requests` (with their entities, and the page pool's bytes and
/// sun), with its warning and error.
fn account(
    (requests, entities, pool): (&[LightRequest], &[Entity], Option<(u64, usize)>),
    budget: &ShadowMemoryBudget,
    fit: &BudgetFit,
    name_of: impl Fn(Entity) -> Option<String>,
) -> ShadowMemory {
    let rows: Vec<LightMemory> = requests
        .iter()
        .zip(entities)
        .zip(&fit.resolutions)
        .enumerate()
        .map(|(i, ((r, &entity), &granted))| {
            let named = name_of(entity).unwrap_or_else(|| entity.to_string());
            let name = format!("{} light {named}", r.kind.word());
            let per_layer = fit.storages[storage_index(r.kind)].per_layer();
            let pages = pool.filter(|&(_, k)| k == i).map_or(0, |(bytes, _)| bytes);
            LightMemory {
                entity,
                name,
                kind: r.kind,
                asked: r.resolution,
                granted,
                views: r.views,
                bytes: if granted > 0 {
                    per_layer * u64::from(r.views) + pages
                } else {
                    0
                },
            }
        })
        .collect();
    let pool_bytes = pool.map_or(0, |(bytes, _)| bytes);
    let lowered = (!fit.lowered.is_empty()).then(|| {
        let asked: Vec<u32> = requests.iter().map(|r| r.resolution).collect();
        let wanted = crate::math::shadow_memory::storage_bytes(requests, &asked, &budget.costs);
        let wanted: u64 = wanted.iter().map(StorageBytes::total).sum::<u64>() + pool_bytes;
        let names: Vec<String> = fit
            .lowered
            .iter()
            .map(|&i| format!("{} {}² to {}²", rows[i].name, rows[i].asked, rows[i].granted))
            .collect();
        format!(
            "the shadow maps would take {} but the shadow-memory budget is {}: lowered {} (the lights smallest on screen first); raise the budget (ShadowMemoryBudget, --shadow-budget) to keep them",
            format_bytes(wanted),
            format_bytes(budget.bytes),
            names.join(", ")
        )
    });
    // NOTE: the pool is fixed by its settings: over the budget alone, it is kept and said.
    let over = pool.filter(|&(bytes, _)| bytes > budget.bytes).map(|(bytes, k)| {
        format!(
            "the page pool of {} ({}) is over the shadow-memory budget of {} by itself; lower its pool_pages or raise the budget (ShadowMemoryBudget, --shadow-budget)",
            rows[k].name,
            format_bytes(bytes),
            format_bytes(budget.bytes)
        )
    });
    let warning = match (over, lowered) {
        (Some(a), Some(b)) => Some(format!("{a}; {b}")),
        (a, b) => a.or(b),
    };
    let error = (!fit.dropped.is_empty()).then(|| {
        let names: Vec<String> = fit
            .dropped
            .iter()
            .map(|&i| {
                let smallest = requests[i].resolution.min(MIN_BUDGET_RESOLUTION);
                let bytes = alone_bytes(&requests[i], smallest, &budget.costs);
                format!("{} ({} at {smallest}²)", rows[i].name, format_bytes(bytes))
            })
            .collect();
        let kept = fit.total() + pool_bytes;
        format!(
            "the shadow-memory budget of {} cannot hold the shadows of {}: they cast none ({} is taken by the other lights at their smallest); raise the budget (ShadowMemoryBudget, --shadow-budget) or shadow fewer lights (ShadowLightBudget)",
            format_bytes(budget.bytes),
            names.join(", "),
            format_bytes(kept)
        )
    });
    ShadowMemory {
        budget: budget.bytes,
        lights: rows,
        storages: fit.storages,
        pages: pool_bytes,
        warning,
        error,
    }
}
