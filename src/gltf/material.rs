//! Materials: base colour factor and texture, alpha mode, double-sidedness, diffuse
//! transmission (`KHR_materials_diffuse_transmission`).

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
        let transmission = diffuse_transmission(cx, &label, &material);
        out.push(GltfMaterial {
            name: material.name().map(str::to_owned),
            base_color: Vec4::from(pbr.base_color_factor()),
            base_color_texture,
            alpha_mode,
            double_sided: material.double_sided(),
            transmission,
        });
    }
    out
}

/// The glTF extension for thin, light-passing surfaces such as leaves.
pub(super) const DIFFUSE_TRANSMISSION: &str = "KHR_materials_diffuse_transmission";

/// `diffuseTransmissionFactor` of the material's `KHR_materials_diffuse_transmission`
/// (default 0, and 0 without the extension); a value outside 0–1 or not a number is clamped
/// or ignored with a warning. Its texture and colour are not read.
fn diffuse_transmission(cx: &mut Cx, label: &str, material: &::gltf::Material<'_>) -> f32 {
    let Some(ext) = material.extension_value(DIFFUSE_TRANSMISSION) else {
        return 0.0;
    };
    match ext.get("diffuseTransmissionFactor") {
        None => 0.0,
        Some(v) => match v.as_f64() {
            Some(f) if (0.0..=1.0).contains(&f) => f as f32,
            Some(f) if f.is_finite() => {
                cx.warn(format!("{label}: diffuseTransmissionFactor {f} clamped to 0..=1"));
                f.clamp(0.0, 1.0) as f32
            }
            _ => {
                cx.warn(format!(
                    "{label}: diffuseTransmissionFactor {v} is not a number; ignored"
                ));
                0.0
            }
        },
    }
}
