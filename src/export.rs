//! Writing per-pixel scalar images (the sun shadow factor) for outside tools: 16-bit
//! greyscale PNG or 32-bit float Portable Float Map, chosen by the file extension.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use image::{ImageBuffer, Luma};
use thiserror::Error;

/// A scalar image that could not be written.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The extension is neither `.png` nor `.pfm`.
    #[error("{0}: unknown image type, expected a .png (16-bit greyscale) or .pfm (32-bit float) path")]
    Extension(String),
    /// Writing failed.
    #[error("{path}: {message}")]
    Write {
        /// Output path.
        path: String,
        /// Why.
        message: String,
    },
}

/// Writes `values` (`width * height`, rows top to bottom, nominally 0–1) to `path`: `.png`
/// stores `round(clamp(v, 0, 1) · 65535)` as 16-bit greyscale, `.pfm` stores the f32 values
/// exactly (PFM rows run bottom to top, as the format defines).
pub fn write_scalar_image(path: &Path, width: u32, height: u32, values: &[f32]) -> Result<(), ExportError> {
    let err = |e: String| ExportError::Write {
        path: path.display().to_string(),
        message: e,
    };
    let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("png") => {
            let pixels: Vec<u16> = values
                .iter()
                .map(|v| (v.clamp(0.0, 1.0) * 65535.0).round() as u16)
                .collect();
            let image: ImageBuffer<Luma<u16>, Vec<u16>> =
                ImageBuffer::from_raw(width, height, pixels).ok_or_else(|| err("size mismatch".to_string()))?;
            image.save(path).map_err(|e| err(e.to_string()))
        }
        Some("pfm") => {
            let file = File::create(path).map_err(|e| err(e.to_string()))?;
            let mut out = BufWriter::new(file);
            // A negative scale marks little-endian data.
            write!(out, "Pf\n{width} {height}\n-1.0\n").map_err(|e| err(e.to_string()))?;
            for row in values.chunks(width.max(1) as usize).rev() {
                for v in row {
                    out.write_all(&v.to_le_bytes()).map_err(|e| err(e.to_string()))?;
                }
            }
            out.flush().map_err(|e| err(e.to_string()))
        }
        _ => Err(ExportError::Extension(path.display().to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_and_pfm_round_trip() {
        let dir = std::env::temp_dir().join(format!("penumbra-export-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let values = [0.0, 0.25, 1.0, 0.5, 2.0, -1.0];
        let png = dir.join("s.png");
        write_scalar_image(&png, 3, 2, &values).unwrap();
        let back = image::open(&png).unwrap().to_luma16();
        assert_eq!(back.as_raw(), &[0, 16384, 65535, 32768, 65535, 0]);
        let pfm = dir.join("s.pfm");
        write_scalar_image(&pfm, 3, 2, &values).unwrap();
        let bytes = std::fs::read(&pfm).unwrap();
        let header = b"Pf\n3 2\n-1.0\n";
        assert_eq!(&bytes[..header.len()], header);
        let floats: Vec<f32> = bytes[header.len()..]
            .chunks(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        // Bottom row first.
        assert_eq!(floats, [0.5, 2.0, -1.0, 0.0, 0.25, 1.0]);
        let err = write_scalar_image(&dir.join("s.jpg"), 3, 2, &values)
            .unwrap_err()
            .to_string();
        assert!(err.contains("expected a .png"), "{err}");
    }
}
