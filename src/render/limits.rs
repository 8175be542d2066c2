//! Sizes that come from user data (target size, texture sizes, mesh and instance buffers)
//! checked against the device's limits before any wgpu call, so that an oversized input is
//! handled (a texture is downscaled, with a warning) or refused with an error that says what
//! was too large — never passed on to wgpu, whose default error handler panics.

use thiserror::Error;

/// The largest texture side any adapter offers (32768 on the largest desktop GPUs): the
/// bound a size can be checked against before a device is open. The device's own limit is
/// checked once it is.
pub const MAX_TEXTURE_SIDE: u32 = 32768;

/// An input size beyond what the device allows.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[error("{what} is {found}; this GPU allows {min} to {max}")]
pub struct LimitError {
    /// What was out of range, like "the render target width".
    pub what: String,
    /// The size asked for.
    pub found: u64,
    /// The smallest size accepted.
    pub min: u64,
    /// The device's limit.
    pub max: u64,
}

/// The device limits penumbra checks user data against.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeviceLimits {
    /// Largest width or height of a 2D texture (and so of a render target).
    pub max_texture_side: u32,
    /// Largest buffer, in bytes.
    pub max_buffer_bytes: u64,
    /// Largest storage-buffer binding, in bytes.
    pub max_storage_binding_bytes: u64,
}

impl DeviceLimits {
    /// The limits of an open device.
    pub fn of(device: &wgpu::Device) -> Self {
        Self::from_limits(&device.limits())
    }

    /// The limits in a [`wgpu::Limits`].
    pub fn from_limits(limits: &wgpu::Limits) -> Self {
        Self {
            max_texture_side: limits.max_texture_dimension_2d,
            max_buffer_bytes: limits.max_buffer_size,
            max_storage_binding_bytes: limits.max_storage_buffer_binding_size,
        }
    }

    /// Checks a render-target size: each side from 1 to the largest texture side.
    pub fn check_target(&self, width: u32, height: u32) -> Result<(), LimitError> {
        for (what, side) in [("the render target width", width), ("the render target height", height)] {
            if side == 0 || side > self.max_texture_side {
                return Err(LimitError {
                    what: what.to_owned(),
                    found: side as u64,
                    min: 1,
                    max: self.max_texture_side as u64,
                });
            }
        }
        Ok(())
    }

    /// The size an image of `width`×`height` must be downscaled to for this device (aspect
    /// ratio kept, each side at least 1), or None when it fits as it is.
    pub fn fit_image(&self, width: u32, height: u32) -> Option<(u32, u32)> {
        let max = self.max_texture_side.max(1);
        if width <= max && height <= max {
            return None;
        }
        let scale = max as f64 / width.max(height) as f64;
        let side = |s: u32| ((s as f64 * scale).floor() as u32).clamp(1, max);
        Some((side(width), side(height)))
    }

    /// How many elements of `element_bytes` fit one storage binding.
    pub fn storage_elements(&self, element_bytes: u64) -> u64 {
        self.max_storage_binding_bytes.min(self.max_buffer_bytes) / element_bytes.max(1)
    }

    /// Checks that the `what` buffer (named like "mesh vertex") of `bytes` can be created
    /// (and, for a storage buffer, bound).
    pub fn check_buffer(&self, what: &str, bytes: u64, storage: bool) -> Result<(), LimitError> {
        let max = match storage {
            true => self.max_storage_binding_bytes.min(self.max_buffer_bytes),
            false => self.max_buffer_bytes,
        };
        if bytes > max {
            return Err(LimitError {
                what: format!("the size in bytes of the {what} buffer"),
                found: bytes,
                min: 0,
                max,
            });
        }
        Ok(())
    }
}

/// What preparing the scene's data for upload found.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct UploadProblems {
    /// Inputs changed to fit (an image downscaled); the frame is still right.
    pub warnings: Vec<String>,
    /// Inputs that could not be used (an image drawn white, a buffer too large to draw).
    pub errors: Vec<String>,
}

impl UploadProblems {
    /// Most messages of each kind kept; older ones are dropped first.
    pub const MAX_KEPT: usize = 64;

    /// Moves `other`'s messages to the end of these, keeping the newest
    /// [`MAX_KEPT`](Self::MAX_KEPT) of each kind.
    pub fn append(&mut self, other: UploadProblems) {
        for (mine, theirs) in [(&mut self.warnings, other.warnings), (&mut self.errors, other.errors)] {
            mine.extend(theirs);
            let excess = mine.len().saturating_sub(Self::MAX_KEPT);
            mine.drain(..excess);
        }
    }
}

/// Requested device limits: wgpu's defaults raised to the adapter's texture sizes, buffer
/// size and storage-binding size, so that large scenes fit where the hardware allows.
pub fn requested_limits(adapter: &wgpu::Limits) -> wgpu::Limits {
    wgpu::Limits {
        // The analysis targets (colour + three Rgba32Float) need 56 bytes per sample.
        max_color_attachment_bytes_per_sample: adapter.max_color_attachment_bytes_per_sample,
        max_buffer_size: adapter.max_buffer_size,
        max_storage_buffer_binding_size: adapter.max_storage_buffer_binding_size,
        // Single-pass cascades render up to a sun's cascades as the views of one pass.
        max_multiview_view_count: adapter.max_multiview_view_count,
        ..wgpu::Limits::default().using_resolution(adapter.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> DeviceLimits {
        DeviceLimits {
            max_texture_side: 8192,
            max_buffer_bytes: 1 << 28,
            max_storage_binding_bytes: 1 << 27,
        }
    }

    #[test]
    fn targets_from_one_to_the_largest_side() {
        let l = limits();
        assert!(l.check_target(1, 1).is_ok());
        assert!(l.check_target(8192, 8192).is_ok());
        let err = l.check_target(8193, 10).unwrap_err();
        assert_eq!(
            err.to_string(),
            "the render target width is 8193; this GPU allows 1 to 8192"
        );
        let err = l.check_target(10, 0).unwrap_err();
        assert_eq!(
            err.to_string(),
            "the render target height is 0; this GPU allows 1 to 8192"
        );
    }

    #[test]
    fn images_shrink_to_fit_keeping_their_aspect() {
        let l = limits();
        assert_eq!(l.fit_image(8192, 1), None);
        assert_eq!(l.fit_image(16385, 1), Some((8192, 1)));
        assert_eq!(l.fit_image(20000, 10000), Some((8192, 4096)));
        assert_eq!(l.fit_image(3, 100_000), Some((1, 8192)));
        for (w, h) in [(u32::MAX, u32::MAX), (u32::MAX, 1), (8193, 8193)] {
            let (fw, fh) = l.fit_image(w, h).unwrap();
            assert!(
                (1..=8192).contains(&fw) && (1..=8192).contains(&fh),
                "{w}×{h} → {fw}×{fh}"
            );
        }
    }

    #[test]
    fn storage_counts_and_buffers() {
        let l = limits();
        assert_eq!(l.storage_elements(160), (1 << 27) / 160);
        assert!(l.check_buffer("instances", 1 << 27, true).is_ok());
        let err = l.check_buffer("instances", (1 << 27) + 1, true).unwrap_err();
        assert_eq!(err.max, 1 << 27);
        assert!(l.check_buffer("vertices", (1 << 27) + 1, false).is_ok());
        assert!(l.check_buffer("vertices", (1 << 28) + 1, false).is_err());
    }
}
