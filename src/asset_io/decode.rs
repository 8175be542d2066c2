//! Decoding images under the limits: each image under the per-image cap, and all of a
//! scene's images together under the texture budget. An image that would take the scene's
//! decoded images (RGBA8 with their mip chains) past the budget is halved until it fits, and
//! a note says so; one that cannot fit even at 1×1 is refused. Images are tallied in the
//! order they are loaded, so the peak memory of loading is the budget plus one image.

use std::io::Cursor;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use image::imageops::FilterType;
use image::{ImageReader, RgbaImage};

use crate::asset_io::{AssetError, AssetIo};
use crate::ecs::assets::ImageData;
use crate::text::{echoed, format_bytes};

/// Most notes kept; later ones are counted in the last.
const MAX_NOTES: usize = 16;

/// The bytes of one scene's decoded images so far, and the notes about images downscaled.
#[derive(Debug, Default)]
pub struct TextureTally {
    used: AtomicU64,
    notes: Mutex<Vec<String>>,
    more_notes: AtomicU64,
}

/// Bytes of a `width`×`height` RGBA8 image with its full mip chain (down to 1×1).
pub fn mip_chain_bytes(width: u32, height: u32) -> u64 {
    let (mut w, mut h) = (u64::from(width.max(1)), u64::from(height.max(1)));
    let mut bytes = 0;
    loop {
        bytes += w * h * 4;
        if w == 1 && h == 1 {
            return bytes;
        }
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
    }
}

/// The size `width`×`height` is halved to (each side at least 1) until its mip chain fits
/// `room` bytes; None when even 1×1 does not.
fn fitted_size(width: u32, height: u32, room: u64) -> Option<(u32, u32)> {
    let (mut w, mut h) = (width.max(1), height.max(1));
    while mip_chain_bytes(w, h) > room {
        if w == 1 && h == 1 {
            return None;
        }
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
    }
    Some((w, h))
}

impl AssetIo {
    /// Decodes image bytes to RGBA8 under the image limits and the texture budget (halving an
    /// image that would pass the budget, with a note). `what` names the image in errors.
    pub fn decode_image(&self, bytes: &[u8], what: &str) -> Result<ImageData, AssetError> {
        let image_error = |message: String| AssetError::Image {
            reference: what.to_owned(),
            message,
        };
        let mut reader = ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| image_error(e.to_string()))?;
        let mut limits = image::Limits::default();
        // NOTE: the decoder's own buffer may be wider than RGBA8 (16-bit channels); the RGBA8
        // copy is checked separately below.
        limits.max_alloc = Some(self.max_image_bytes.saturating_mul(2));
        reader.limits(limits.clone());
        let (width, height) = reader.into_dimensions().map_err(|e| image_error(e.to_string()))?;
        let rgba_bytes = width as u64 * height as u64 * 4;
        if rgba_bytes > self.max_image_bytes {
            let message = format!(
                "{width}×{height} pixels need {rgba_bytes} bytes, more than the {} allowed",
                self.max_image_bytes
            );
            return Err(image_error(message));
        }
        let used = self.tally.used.load(Ordering::Relaxed);
        let room = self.max_texture_bytes.saturating_sub(used);
        let Some((fw, fh)) = fitted_size(width, height, room) else {
            return Err(image_error(format!(
                "the scene's textures already take {} of the {} texture budget, and not even 1×1 texels fit (raise the budget with --texture-budget)",
                format_bytes(used),
                format_bytes(self.max_texture_bytes)
            )));
        };
        let mut reader = ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| image_error(e.to_string()))?;
        reader.limits(limits);
        let mut decoded = reader.decode().map_err(|e| image_error(e.to_string()))?.to_rgba8();
        if (fw, fh) != (width, height) {
            decoded = image::imageops::resize(&decoded, fw, fh, FilterType::Triangle);
            self.note(format!(
                "{} downscaled from {width}×{height} to {fw}×{fh}: at full size the scene's textures would take {} with their mips, over the {} texture budget (raise it with --texture-budget)",
                echoed(what),
                format_bytes(used + mip_chain_bytes(width, height)),
                format_bytes(self.max_texture_bytes)
            ));
        }
        self.tally.used.fetch_add(mip_chain_bytes(fw, fh), Ordering::Relaxed);
        Ok(image_data(decoded))
    }

    /// Bytes of the images decoded so far, RGBA8 with their mip chains.
    pub fn texture_bytes(&self) -> u64 {
        self.tally.used.load(Ordering::Relaxed)
    }

    /// Takes the notes about images downscaled to fit the texture budget.
    pub fn take_notes(&self) -> Vec<String> {
        let mut notes = std::mem::take(&mut *self.tally.notes.lock().unwrap_or_else(|p| p.into_inner()));
        let more = self.tally.more_notes.swap(0, Ordering::Relaxed);
        if more > 0 {
            notes.push(format!("{more} more images downscaled to fit the texture budget"));
        }
        notes
    }

    fn note(&self, message: String) {
        log::warn!("{message}");
        let mut notes = self.tally.notes.lock().unwrap_or_else(|p| p.into_inner());
        if notes.len() < MAX_NOTES {
            notes.push(message);
        } else {
            self.tally.more_notes.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// An RGBA8 image as the asset stores hold it.
fn image_data(image: RgbaImage) -> ImageData {
    ImageData {
        width: image.width(),
        height: image.height(),
        rgba: image.into_raw(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mip_chain_takes_a_third_more_and_sizes_halve_to_fit() {
        assert_eq!(mip_chain_bytes(1, 1), 4);
        assert_eq!(mip_chain_bytes(4, 4), (16 + 4 + 1) * 4);
        assert_eq!(mip_chain_bytes(4, 1), (4 + 2 + 1) * 4);
        assert_eq!(mip_chain_bytes(8192, 8192), 357_913_940);
        assert_eq!(fitted_size(8192, 8192, u64::MAX), Some((8192, 8192)));
        assert_eq!(fitted_size(8192, 8192, 100 << 20), Some((4096, 4096)));
        assert_eq!(fitted_size(8192, 2, 1000), Some((64, 1)));
        assert_eq!(fitted_size(8192, 8192, 3), None);
    }
}
