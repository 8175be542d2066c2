//! Materials: base colour factor and texture, alpha mode, double-sidedness.

use ::gltf::Document;
use ::gltf::material::AlphaMode as GltfAlphaMode;
use glam::Vec4;

use crate::ecs::assets::AlphaMode;
use crate::gltf::GltfMaterial;
use crate::gltf::load::Cx;

/// glTF's default `alphaCutoff`, also the cutoff `BLEND` materials are masked at.
pub(super) const DEFAULT_CUTOFF: f32 = 0.5;

/// Reads every material of the document. Nothing here can fail: the crate's validation
/// has checked the texture and image indices.
pub(super) fn read_materials(cx: &mut Cx, document: &Document) -> Vec<GltfMaterial> {
    let mut out = Vec::new();
    for material in document.materials() {
        let i = material.index().unwrap_or_default();
        let label = match material.name() {
            Some(name) => format!("material {i} (`{name}`)"),
            None => format!("material {i}"),
        };
        let pbr = material.pbr_metallic_roughness();
        let base_color_texture = pbr.base_color_texture().and_then(|info| {
            if info.tex_coord() == 0 {
                Some(info.texture().source().index())
            } else {
                cx.warn(format!(
                    "{label}: base colour texture uses TEXCOORD_{}; only TEXCOORD_0 is read, so the texture is ignored",
                    info.tex_coord()
                ));
                None
            }
        });
        let alpha_mode = match material.alpha_mode() {
            GltfAlphaMode::Opaque => AlphaMode::Opaque,
            GltfAlphaMode::Mask => {
                let cutoff = material.alpha_cutoff().unwrap_or(DEFAULT_CUTOFF);
                if (0.0..=1.0).contains(&cutoff) {
                    AlphaMode::Mask(cutoff)
                } else {
                    cx.warn(format!("{label}: alphaCutoff {cutoff} clamped to 0..=1"));
                    AlphaMode::Mask(if cutoff > 1.0 { 1.0 } else { 0.0 })
                }
            }
            GltfAlphaMode::Blend => {
                cx.warn(format!(
                    "{label}: alphaMode BLEND is not supported; masked at {DEFAULT_CUTOFF}, the closest shadow behaviour"
                ));
                AlphaMode::Mask(DEFAULT_CUTOFF)
            }
        };
        out.push(GltfMaterial {
            name: material.name().map(str::to_owned),
            base_color: Vec4::from(pbr.base_color_factor()),
            base_color_texture,
            alpha_mode,
            double_sided: material.double_sided(),
        });
    }
    out
}
