//! Pure math of the shadow system: bounding boxes, reverse-Z projections, the light frame,
//! camera frusta, cascade splitting, fitting (clipped to the receivers' box) and snapping, PCSS parameters, caster culling,
//! Poisson-disk kernels, spot-light views with their perspective penumbra estimate, and the
//! choice of shadowed lights under a budget, contact-shadow marches, linear blend skinning
//! and keyframe tracks. Only `glam` and `std`; no GPU types.
//!
//! Conventions: right-handed world with +Y up; cameras look down local −Z; matrices are
//! named `target_from_source`; depth is reverse-Z in `[0, 1]` (near → 1); NDC +y is up and
//! texture `uv = (x·0.5 + 0.5, 0.5 − y·0.5)`; a light's `direction` is where its light
//! travels, and light space looks down −Z.

pub mod aabb;
pub mod animation;
pub mod cascade_coverage;
pub mod cascades;
pub mod chunk_groups;
pub mod chunks;
pub mod clip;
pub mod clipmap;
pub mod contact;
pub mod culling;
pub mod evsm;
pub mod footprint;
pub mod frustum;
pub mod light_budget;
pub mod light_space;
pub mod moments;
pub mod msm;
pub mod occlusion;
pub mod page_sampling;
pub mod pages;
pub mod pcss;
pub mod point;
pub mod poisson;
pub mod pose;
pub mod projection;
pub mod receivers;
pub mod seen_depths;
pub mod shadow_memory;
pub mod skinning;
pub mod snapping;
pub mod space_order;
pub mod splits;
pub mod spot;

pub use aabb::Aabb;
pub use cascades::{Cascade, CascadeInput, CascadeSet, compute_cascades};
pub use culling::{cull_casters, cull_spheres_frustum};
pub use frustum::{CameraView, Frustum, Plane, slice_corners};
pub use light_budget::{BudgetChoice, LightCandidate, LightKind, ShadowBudget, choose_shadowed_lights};
pub use light_space::{light_from_world, light_rotation};
pub use pcss::{PcssParams, pcss_params};
pub use poisson::{STANDARD_SETS, min_pairwise_distance, poisson_disk};
pub use projection::{ndc_to_uv, ortho_reverse_z, perspective_reverse_z, uv_to_ndc};
pub use splits::{pssm_splits, wide_view_splits};
pub use spot::{SpotInput, SpotView, perspective_penumbra, spot_view};
