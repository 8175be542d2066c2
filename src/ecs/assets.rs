//! Asset stores for meshes, materials and images, addressed by small copyable handles.

use bevy_ecs::resource::Resource;
use glam::Vec4;

use crate::mesh::MeshData;

/// Index of a mesh in [`Meshes`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MeshHandle(pub u32);

/// Index of a material in [`Materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialHandle(pub u32);

/// Index of an image in [`Images`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ImageHandle(pub u32);

/// How a material's alpha is used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored.
    Opaque,
    /// Texels with alpha below the cutoff are cut out, in the camera view and in the shadow.
    Mask(f32),
}

/// A surface description: base colour, optional texture, alpha mode.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Linear RGBA base colour factor.
    pub base_color: Vec4,
    /// Optional sRGB base-colour texture, multiplied with the factor.
    pub base_color_texture: Option<ImageHandle>,
    /// Opaque or alpha-masked.
    pub alpha_mode: AlphaMode,
    /// Drawn from both sides (back faces are lit with the flipped normal); single-sided
    /// materials cull back faces in the camera view. Shadow casters are always two-sided.
    pub double_sided: bool,
    /// Diffuse transmission of a double-sided material, 0–1: the share of the light on one
    /// side that its other side shows (a thin leaf's underside glows in the sun; 0.3–0.5 suits
    /// leaves). The transmitted light is shadowed as the lit side is. 0 (the default) for
    /// solids; ignored on single-sided materials.
    pub transmission: f32,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            base_color: Vec4::ONE,
            base_color_texture: None,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
            transmission: 0.0,
        }
    }
}

impl Material {
    /// The diffuse transmission the shaders use: [`transmission`](Self::transmission)
    /// clamped to 0–1 on a double-sided material, 0 on a single-sided one.
    pub fn effective_transmission(&self) -> f32 {
        if self.double_sided && self.transmission.is_finite() {
            self.transmission.clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// The alpha cutoff the shaders use: the mask's cutoff, or 0 for opaque materials.
    pub fn alpha_cutoff(&self) -> f32 {
        match self.alpha_mode {
            AlphaMode::Opaque => 0.0,
            AlphaMode::Mask(c) => c,
        }
    }

    /// True for alpha-masked materials.
    pub fn is_masked(&self) -> bool {
        matches!(self.alpha_mode, AlphaMode::Mask(_))
    }

    /// True for opaque materials without a texture: their surfaces' colour is the factor
    /// alone, which the renderer can light from the depth prepass's pixels.
    pub fn is_untextured(&self) -> bool {
        !self.is_masked() && self.base_color_texture.is_none()
    }
}

/// An 8-bit sRGB RGBA image.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageData {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes, rows top to bottom.
    pub rgba: Vec<u8>,
}

/// A store of assets addressed by a handle type: `add`, `clear`, `get`, `as_slice`, `len`,
/// `is_empty` and a generation bumped by every change.
macro_rules! asset_store {
    ($(#[$doc:meta])* $store:ident, $item:ty, $handle:ident) => {
        $(#[$doc])*
        #[derive(Resource, Debug, Default)]
        pub struct $store {
            items: Vec<$item>,
            generation: u64,
        }

        impl $store {
            /// Stores an item and returns its handle.
            pub fn add(&mut self, item: $item) -> $handle {
                self.items.push(item);
                self.generation += 1;
                $handle((self.items.len() - 1) as u32)
            }

            /// Removes every item (handles taken before are invalid afterwards).
            pub fn clear(&mut self) {
                self.items.clear();
                self.generation += 1;
            }

            /// Bumped by every change, so the renderer knows when to upload again (a store
            /// cleared and refilled to the same length still counts as changed).
            pub fn generation(&self) -> u64 {
                self.generation
            }

            /// The item behind a handle, if it exists.
            pub fn get(&self, handle: $handle) -> Option<&$item> {
                self.items.get(handle.0 as usize)
            }

            /// All items, indexed by handle.
            pub fn as_slice(&self) -> &[$item] {
                &self.items
            }

            /// Number of items.
            pub fn len(&self) -> usize {
                self.items.len()
            }

            /// True when nothing is stored.
            pub fn is_empty(&self) -> bool {
                self.items.is_empty()
            }
        }
    };
}

pub(crate) use asset_store;

asset_store!(
    /// All meshes, addressed by [`MeshHandle`].
    Meshes, MeshData, MeshHandle
);
asset_store!(
    /// All materials, addressed by [`MaterialHandle`].
    Materials, Material, MaterialHandle
);
asset_store!(
    /// All images, addressed by [`ImageHandle`].
    Images, ImageData, ImageHandle
);
