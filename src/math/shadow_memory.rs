//! Shadow-memory arithmetic: the bytes a frame's shadow storages take, from the shadowed
//! lights' requests, and the fit of those requests to a budget.
//!
//! The renderer keeps one depth array per kind of light (cascades, spot lights, point-light
//! cubes). Each array's layers are as large as the largest view of its kind, so a layer costs
//! the same whichever light owns it. Moments are kept per array too: VSM moments cover every
//! spot (or point) layer once any spot (or point) light filters VSM; a sun's EVSM or MSM
//! moments cover every cascade layer, with a mip chain under contact hardening. An array
//! whose lights pre-blur their moments also has a scratch for the blur's first axis: one
//! layer, or one cube. [`storage_bytes`] counts all of it the way the renderer allocates it.
//!
//! [`fit_budget`] lowers resolutions until the storages fit a budget. Each step halves the
//! largest layers of one array, the array whose lights at that size are smallest on screen;
//! suns cover the whole screen, so their cascades are lowered last. No resolution goes below
//! [`MIN_BUDGET_RESOLUTION`] by this. If the storages still do not fit at that size, the
//! lights smallest on screen are dropped until they do; the caller reports those.

use crate::math::light_budget::LightKind;

/// Bytes of one depth texel of a spot or point light (`Depth32Float`); a sun's are
/// [`MemoryCosts::sun_depth_texel`].
pub const DEPTH_TEXEL_BYTES: u64 = 4;

/// Bytes of a sun's depth texel in the renderer's default format (`Depth16Unorm`, see
/// [`RenderOptions::sun_depth`](crate::render::RenderOptions::sun_depth)): what a budget
/// accounts until a renderer hands it the format in use.
pub const DEFAULT_SUN_DEPTH_TEXEL_BYTES: u64 = 2;

/// Mip levels of a sun's moments under contact hardening: the last averages 64² texels, the
/// widest penumbra filter (`MAX_PENUMBRA_TEXELS` = 32 texels of radius in the shaders).
pub const MOMENT_MIPS: u32 = 7;

/// The smallest side the budget lowers a light to (also the smallest resolution a scene may
/// ask for, `settings::MIN_RESOLUTION`); a light that asks for less keeps what it asks for.
pub const MIN_BUDGET_RESOLUTION: u32 = 256;

/// What the device can store moments in: 32-bit floats it filters (`FLOAT32_FILTERABLE`),
/// and 16-bit unorm (`TEXTURE_FORMAT_16BIT_NORM`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MomentSupport {
    /// 32-bit floats can be filtered.
    pub fp32_filterable: bool,
    /// `Rgba16Unorm` can be sampled and written.
    pub unorm16: bool,
}

/// The texel format of the suns' cascade moments (four channels each).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CascadeMomentFormat {
    /// 32-bit floats.
    Rgba32Float,
    /// 16-bit unsigned normalised (MSM's quantised moments).
    Rgba16Unorm,
    /// 16-bit floats.
    Rgba16Float,
}

impl CascadeMomentFormat {
    /// Bytes per texel.
    pub fn texel_bytes(self) -> u64 {
        match self {
            CascadeMomentFormat::Rgba32Float => 16,
            CascadeMomentFormat::Rgba16Unorm | CascadeMomentFormat::Rgba16Float => 8,
        }
    }
}

/// The format of the cascades' moments for suns that each filter moments with `(msm, fp32)`
/// (MSM rather than EVSM; 32-bit precision asked and filterable), None for no such sun: 32-bit
/// floats when a sun resolves to 32 bits, else 16 bits — `Rgba16Unorm` when every sun uses
/// MSM and the device has it; 32-bit floats for 16-bit MSM without unorm where they filter
/// (half floats are too coarse for MSM's quantised moments); else `Rgba16Float`.
pub fn cascade_moment_format(
    suns: impl IntoIterator<Item = (bool, bool)>,
    support: MomentSupport,
) -> Option<CascadeMomentFormat> {
    let mut any = false;
    let mut fp32 = false;
    let mut all_msm = true;
    for (msm, wide) in suns {
        any = true;
        all_msm &= msm;
        fp32 |= wide;
    }
    any.then_some(match fp32 {
        true => CascadeMomentFormat::Rgba32Float,
        false if all_msm && support.unorm16 => CascadeMomentFormat::Rgba16Unorm,
        false if all_msm && support.fp32_filterable => CascadeMomentFormat::Rgba32Float,
        false => CascadeMomentFormat::Rgba16Float,
    })
}

/// Whether and how a light filters moments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MomentUse {
    /// Depth comparisons only (PCF, PCSS).
    None,
    /// A spot or point light's VSM moments; `blur` when it pre-blurs them.
    Vsm {
        /// Pre-blurred (`vsm_blur > 0`).
        blur: bool,
    },
    /// A sun's EVSM or MSM moments.
    Sun {
        /// MSM rather than EVSM.
        msm: bool,
        /// Stored in 32-bit floats (asked for and filterable).
        fp32: bool,
        /// Pre-blurred (no contact hardening, `moment_blur > 0`).
        blur: bool,
        /// Contact hardening: the moments carry a mip chain.
        hardening: bool,
    },
}

/// One shadowed light's request.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightRequest {
    /// Which array it renders into.
    pub kind: LightKind,
    /// Texels per side it asks for.
    pub resolution: u32,
    /// Layers: its cascades, 1 for a spot light, 6 for a point light.
    pub views: u32,
    /// Its moments.
    pub moments: MomentUse,
    /// Its share of the screen ([`screen_coverage`](crate::math::light_budget::screen_coverage);
    /// infinite for a sun): lights smallest on screen are lowered first.
    pub coverage: f32,
    /// Its layers scroll (a sun's clipmap): unless they wrap, the array then also holds one
    /// depth layer of its side to move a layer through.
    pub scrolls: bool,
    /// Its scrolling layers wrap instead of moving (a sun filtered by depth comparisons) where
    /// they fill the array's layers: they need no layer to move through.
    pub wraps: bool,
}

/// The device's moment formats, which set the bytes of a moment texel, and the suns' depth
/// format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryCosts {
    /// Bytes of a spot or point light's VSM moment texel (16 in 32-bit floats, 8 in 16-bit).
    pub vsm_texel: u64,
    /// Bytes of a sun's depth texel: 4 (`Depth32Float`) or 2 (`Depth16Unorm`, see
    /// [`RenderOptions::sun_depth`](crate::render::RenderOptions::sun_depth)).
    pub sun_depth_texel: u64,
    /// What the suns' moments can be stored in.
    pub support: MomentSupport,
}

/// The bytes of one array and what it holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StorageBytes {
    /// Texels per side of a layer (0 with no layer).
    pub side: u32,
    /// Layers.
    pub layers: u32,
    /// Depth texels.
    pub depth: u64,
    /// Moments, with their mip levels.
    pub moments: u64,
    /// The blur's scratch (a 1×1 stand-in while no light of the array blurs its moments).
    pub scratch: u64,
    /// The depth layer scrolling layers move through (0 while none scrolls).
    pub shift: u64,
}

impl StorageBytes {
    /// All of it.
    pub fn total(&self) -> u64 {
        self.depth + self.moments + self.scratch + self.shift
    }

    /// Bytes of one layer (depth and moments; the scratch is the array's).
    pub fn per_layer(&self) -> u64 {
        match self.layers {
            0 => 0,
            n => (self.depth + self.moments) / u64::from(n),
        }
    }
}

/// Index of `kind`'s array in [`storage_bytes`]'s result.
pub fn storage_index(kind: LightKind) -> usize {
    match kind {
        LightKind::Directional => 0,
        LightKind::Spot => 1,
        LightKind::Point => 2,
    }
}

/// Texels of a `side`² layer over `mips` mip levels.
fn mip_texels(side: u32, mips: u32) -> u64 {
    (0..mips).map(|l| u64::from((side >> l).max(1)).pow(2)).sum()
}

/// Mip levels of the cascade moments in `side`² layers with contact hardening.
pub fn hardening_mips(side: u32) -> u32 {
    MOMENT_MIPS.min(32 - side.max(1).leading_zeros())
}

/// The three arrays (cascades, spot lights, point lights) for `requests` at `resolutions`
/// (one per request; a request left out has resolution 0).
pub fn storage_bytes(requests: &[LightRequest], resolutions: &[u32], costs: &MemoryCosts) -> [StorageBytes; 3] {
    let mut out = [StorageBytes::default(); 3];
    let mut moments = [None::<(u64, u32)>; 3];
    let mut blur = [false; 3];
    let mut scrolls = [false; 3];
    let mut hardening = false;
    let granted = || requests.iter().zip(resolutions).filter(|(_, res)| **res > 0);
    for (r, &res) in granted() {
        let i = storage_index(r.kind);
        out[i].side = out[i].side.max(res);
        out[i].layers += r.views;
        match r.moments {
            MomentUse::None => {}
            MomentUse::Vsm { blur: b } => {
                moments[i] = Some((costs.vsm_texel, 1));
                blur[i] |= b;
            }
            MomentUse::Sun {
                blur: b, hardening: h, ..
            } => {
                blur[0] |= b;
                hardening |= h;
            }
        }
    }
    let suns = granted().filter_map(|(r, _)| match r.moments {
        MomentUse::Sun { msm, fp32, .. } => Some((msm, fp32 && costs.support.fp32_filterable)),
        _ => None,
    });
    if let Some(format) = cascade_moment_format(suns, costs.support) {
        let mips = if hardening { hardening_mips(out[0].side) } else { 1 };
        moments[0] = Some((format.texel_bytes(), mips));
    }
    // NOTE: a scrolling light whose layers wrap moves none, unless the array's layers are
    // larger than its own (it then fills a corner of them, which cannot wrap).
    for (r, &res) in granted() {
        let i = storage_index(r.kind);
        scrolls[i] |= r.scrolls && (!r.wraps || res < out[i].side);
    }
    for (i, s) in out.iter_mut().enumerate() {
        let layer = u64::from(s.side).pow(2);
        let texel = if i == 0 {
            costs.sun_depth_texel
        } else {
            DEPTH_TEXEL_BYTES
        };
        s.depth = layer * u64::from(s.layers) * texel;
        s.shift = if scrolls[i] { layer * texel } else { 0 };
        if let Some((texel, mips)) = moments[i] {
            s.moments = mip_texels(s.side, mips) * u64::from(s.layers) * texel;
            let scratch_layers = if i == 2 { 6 } else { 1 };
            // NOTE: without a blur the scratch is 1×1 texels, but it is still allocated.
            let scratch_texels = if blur[i] { layer } else { 1 };
            s.scratch = scratch_texels * scratch_layers * texel;
        }
    }
    out
}

/// How the requests fit a budget.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BudgetFit {
    /// The side each request gets (0 for a dropped one).
    pub resolutions: Vec<u32>,
    /// Requests given less than they asked for, in the order they were first lowered.
    pub lowered: Vec<usize>,
    /// Requests that get no shadow: even at [`MIN_BUDGET_RESOLUTION`] the arrays did not fit
    /// (smallest on screen first).
    pub dropped: Vec<usize>,
    /// The arrays at the fitted sides.
    pub storages: [StorageBytes; 3],
}

impl BudgetFit {
    /// Bytes of all three arrays.
    pub fn total(&self) -> u64 {
        self.storages.iter().map(StorageBytes::total).sum()
    }
}

/// Bytes of the arrays summed.
fn total(requests: &[LightRequest], resolutions: &[u32], costs: &MemoryCosts) -> u64 {
    storage_bytes(requests, resolutions, costs)
        .iter()
        .map(StorageBytes::total)
        .sum()
}

/// Lowers the requests' resolutions (and, failing that, drops requests) until their arrays
/// take at most `budget` bytes; see the module's description.
pub fn fit_budget(requests: &[LightRequest], costs: &MemoryCosts, budget: u64) -> BudgetFit {
    let mut fit = BudgetFit::default();
    fit_budget_into(requests, costs, budget, &mut fit);
    fit
}

/// [`fit_budget`] into a reused result: allocates nothing once its lists have grown to the
/// number of requests.
pub fn fit_budget_into(requests: &[LightRequest], costs: &MemoryCosts, budget: u64, fit: &mut BudgetFit) {
    let res = &mut fit.resolutions;
    res.clear();
    res.extend(requests.iter().map(|r| r.resolution.max(1)));
    fit.lowered.clear();
    fit.dropped.clear();
    while total(requests, res, costs) > budget {
        let Some((array, target)) = next_step(requests, res) else {
            break;
        };
        for i in 0..requests.len() {
            if storage_index(requests[i].kind) == array && res[i] > target {
                res[i] = target;
                if !fit.lowered.contains(&i) {
                    fit.lowered.push(i);
                }
            }
        }
    }
    // NOTE: smallest on screen first; among equals (suns) the later one.
    while total(requests, res, costs) > budget {
        let next = (0..requests.len())
            .filter(|&i| res[i] > 0)
            .min_by(|&a, &b| requests[a].coverage.total_cmp(&requests[b].coverage).then(b.cmp(&a)));
        let Some(i) = next else {
            break;
        };
        res[i] = 0;
        fit.dropped.push(i);
    }
    let dropped = &fit.dropped;
    fit.lowered.retain(|i| !dropped.contains(i));
    fit.storages = storage_bytes(requests, res, costs);
}

/// The next lowering step: the array to lower and the side its largest layers get. Halving a
/// layer that is not its array's largest frees nothing, so a step halves every light that
/// sets an array's side, in the array whose lights at that side are smallest on screen; None
/// once every array is at [`MIN_BUDGET_RESOLUTION`].
fn next_step(requests: &[LightRequest], res: &[u32]) -> Option<(usize, u32)> {
    let mut best: Option<(f32, usize, u32)> = None;
    // NOTE: suns come last, so on a tie a light whose range holds the camera (covering the
    // screen like a sun) is lowered before them.
    for kind in [LightKind::Point, LightKind::Spot, LightKind::Directional] {
        let members = || (0..requests.len()).filter(move |&i| requests[i].kind == kind && res[i] > 0);
        let Some(side) = members().map(|i| res[i]).max() else {
            continue;
        };
        let target = (side / 2).max(MIN_BUDGET_RESOLUTION);
        if target >= side {
            continue;
        }
        let importance = members()
            .filter(|&i| res[i] > target)
            .map(|i| requests[i].coverage)
            .fold(f32::NEG_INFINITY, f32::max);
        if best.is_none_or(|(b, _, _)| importance < b) {
            best = Some((importance, storage_index(kind), target));
        }
    }
    best.map(|(_, array, target)| (array, target))
}

/// Bytes `request` takes at `resolution` alone (its layers, their moments, and its array's
/// scratch): what it costs on its own.
pub fn alone_bytes(request: &LightRequest, resolution: u32, costs: &MemoryCosts) -> u64 {
    total(std::slice::from_ref(request), &[resolution], costs)
}

#[cfg(test)]
#[path = "shadow_memory_tests.rs"]
mod tests;
