//! Material textures on the GPU: each image is checked before upload — one whose byte count
//! does not match its size is replaced by white with an error, one larger than the device's
//! largest texture is downscaled (aspect kept) with a warning — and uploaded with its full
//! mip chain ([`mip_chain`]: linear-light box filter, alpha coverage kept for masked
//! materials), which the material sampler filters trilinearly.

use std::borrow::Cow;

use image::RgbaImage;
use image::imageops::{FilterType, resize};
use wgpu::util::DeviceExt;

use crate::ecs::assets::ImageData;
use crate::render::limits::{DeviceLimits, UploadProblems};
use crate::render::mips::{MaskedAlpha, mip_chain};

/// The white 1×1 image that stands in for "no texture".
pub fn white() -> ImageData {
    ImageData {
        width: 1,
        height: 1,
        rgba: vec![255; 4],
    }
}

/// `image` as it can be uploaded to a device with `limits`: itself, a downscaled copy, or
/// white when its bytes do not match its size. `name` names it in messages.
pub fn fit_image<'a>(
    image: &'a ImageData,
    name: &str,
    limits: &DeviceLimits,
    problems: &mut UploadProblems,
) -> Cow<'a, ImageData> {
    let expected = image.width as u128 * image.height as u128 * 4;
    if image.width == 0 || image.height == 0 || image.rgba.len() as u128 != expected {
        problems.errors.push(format!(
            "{name}: {}×{} pixels need {expected} bytes of RGBA, found {}; drawn white",
            image.width,
            image.height,
            image.rgba.len()
        ));
        return Cow::Owned(white());
    }
    let Some((width, height)) = limits.fit_image(image.width, image.height) else {
        return Cow::Borrowed(image);
    };
    problems.warnings.push(format!(
        "{name}: {}×{} is larger than this GPU's largest texture ({}); downscaled to {width}×{height}",
        image.width, image.height, limits.max_texture_side
    ));
    // NOTE: the byte count was checked above, so the buffer always converts.
    let Some(full) = RgbaImage::from_raw(image.width, image.height, image.rgba.clone()) else {
        return Cow::Owned(white());
    };
    let small = resize(&full, width, height, FilterType::Triangle);
    Cow::Owned(ImageData {
        width,
        height,
        rgba: small.into_raw(),
    })
}

/// Uploads one checked image as an sRGB texture with every mip level and returns its view;
/// `masked` is the alpha test of the material that samples it (its levels keep the image's
/// alpha-test coverage), None for an opaque one.
pub fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    image: &ImageData,
    masked: Option<MaskedAlpha>,
) -> wgpu::TextureView {
    let chain = mip_chain(image, masked);
    // NOTE: level after level, as `TextureDataOrder::LayerMajor` reads them.
    let data: Vec<u8> = chain.iter().flat_map(|level| level.rgba.iter().copied()).collect();
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some("base colour"),
            size: wgpu::Extent3d {
                width: image.width,
                height: image.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: chain.len() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &data,
    );
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits(side: u32) -> DeviceLimits {
        DeviceLimits {
            max_texture_side: side,
            max_buffer_bytes: 1 << 30,
            max_storage_binding_bytes: 1 << 27,
        }
    }

    #[test]
    fn fitting_images_pass_unchanged() {
        let image = ImageData {
            width: 2,
            height: 1,
            rgba: vec![1, 2, 3, 4, 5, 6, 7, 8],
        };
        let mut problems = UploadProblems::default();
        let fitted = fit_image(&image, "image 0", &limits(8), &mut problems);
        assert!(matches!(fitted, Cow::Borrowed(_)));
        assert_eq!(problems, UploadProblems::default());
    }

    #[test]
    fn oversized_images_are_downscaled_with_a_warning() {
        let image = ImageData {
            width: 17,
            height: 1,
            rgba: vec![200; 17 * 4],
        };
        let mut problems = UploadProblems::default();
        let fitted = fit_image(&image, "texture `a.png`", &limits(16), &mut problems);
        assert_eq!((fitted.width, fitted.height), (16, 1));
        assert_eq!(fitted.rgba.len(), 16 * 4);
        assert!(fitted.rgba.iter().all(|&b| b == 200));
        assert_eq!(
            problems.warnings,
            ["texture `a.png`: 17×1 is larger than this GPU's largest texture (16); downscaled to 16×1"]
        );
        assert!(problems.errors.is_empty());
    }

    #[test]
    fn images_whose_bytes_do_not_match_are_white_with_an_error() {
        for (width, height, bytes) in [(2, 2, 15), (0, 4, 0), (4, 0, 0), (u32::MAX, u32::MAX, 4)] {
            let image = ImageData {
                width,
                height,
                rgba: vec![0; bytes],
            };
            let mut problems = UploadProblems::default();
            let fitted = fit_image(&image, "image 3", &limits(16), &mut problems);
            assert_eq!(*fitted, white());
            assert_eq!(problems.errors.len(), 1, "{problems:?}");
            assert!(problems.errors[0].starts_with("image 3: "), "{problems:?}");
        }
    }
}
