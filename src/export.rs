//! Writing output files so that nothing is lost silently: the colour image (PNG), per-pixel
//! scalar images for outside tools (16-bit greyscale PNG or 32-bit float Portable Float Map,
//! chosen by the file extension), and any other bytes.
//!
//! Every path is checked with [`prepare_output`] before the work that produces it (a bad
//! path or extension is reported before a long render, not after). Every write goes to a
//! temporary file beside the target, is flushed and synced, and only then renamed over the
//! target, so a full disk or a failed write is an error and never leaves a 0-byte or half
//! file behind. An existing special file (a device such as `/dev/stdout`, or a pipe) is
//! written in place, and its write and flush errors are reported too.

use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder, RgbaImage};
use thiserror::Error;

/// An output file that could not be written.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The extension is not one this output can be written as.
    #[error("{path}: unknown image type, expected {expected}")]
    Extension {
        /// Output path.
        path: String,
        /// The accepted extensions, in words.
        expected: String,
    },
    /// The path cannot be written, or writing failed.
    #[error("{path}: {message}")]
    Write {
        /// Output path.
        path: String,
        /// Why.
        message: String,
    },
}

/// The kinds of output a path can name, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputKind {
    /// A colour image: `.png`.
    ColorImage,
    /// A scalar image: `.png` (16-bit greyscale) or `.pfm` (32-bit float).
    ScalarImage,
    /// Any file (a report, a settings file): no extension check.
    Any,
}

impl OutputKind {
    fn extensions(self) -> &'static [&'static str] {
        match self {
            OutputKind::ColorImage => &["png"],
            OutputKind::ScalarImage => &["png", "pfm"],
            OutputKind::Any => &[],
        }
    }

    fn expected(self) -> &'static str {
        match self {
            OutputKind::ColorImage => "a .png path",
            OutputKind::ScalarImage => "a .png (16-bit greyscale) or .pfm (32-bit float) path",
            OutputKind::Any => "any path",
        }
    }
}

fn write_error(path: &Path, message: impl Into<String>) -> ExportError {
    ExportError::Write {
        path: path.display().to_string(),
        message: message.into(),
    }
}

/// The lower-case extension of `path`.
fn extension(path: &Path) -> Option<String> {
    path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase)
}

/// Checks, before any work is done, that `path` can be written as `kind`: its extension is
/// one the kind accepts, it is not a directory, and its folder exists (it is created if
/// missing) and accepts new files. Nothing is left behind by the check.
pub fn prepare_output(path: &Path, kind: OutputKind) -> Result<(), ExportError> {
    prepare_extension(path, kind)?;
    if path.file_name().is_none() {
        return Err(write_error(path, "not a file name"));
    }
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_dir() => return Err(write_error(path, "is a directory")),
        Ok(meta) if !meta.is_file() => {
            // A device or a pipe: it must open for writing.
            return open_special(path).map(drop);
        }
        _ => {}
    }
    let dir = parent(path);
    std::fs::create_dir_all(&dir).map_err(|e| write_error(path, format!("cannot create its folder: {e}")))?;
    let probe = temp_path(path);
    File::create(&probe).map_err(|e| write_error(path, format!("cannot create files in its folder: {e}")))?;
    std::fs::remove_file(&probe).map_err(|e| write_error(path, e.to_string()))
}

/// The folder of `path` (`.` for a bare file name).
fn parent(path: &Path) -> PathBuf {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.to_owned(),
        _ => PathBuf::from("."),
    }
}

/// A temporary file name beside `path`, unique to this process.
fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    parent(path).join(format!(".{name}.{}.partial", std::process::id()))
}

fn open_special(path: &Path) -> Result<File, ExportError> {
    OpenOptions::new()
        .write(true)
        .open(path)
        .map_err(|e| write_error(path, format!("cannot open for writing: {e}")))
}

/// True for an existing path that is neither a regular file nor a folder.
fn is_special(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Writes `bytes` to `path` through a temporary file (flushed, synced, then renamed), or in
/// place for an existing special file; every error is returned and no partial file is left.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    if is_special(path) {
        let mut file = open_special(path)?;
        return write_all_synced(&mut file, bytes, false).map_err(|e| write_error(path, e.to_string()));
    }
    let temp = temp_path(path);
    let written = File::create(&temp).and_then(|mut file| write_all_synced(&mut file, bytes, true));
    let renamed = written.and_then(|()| std::fs::rename(&temp, path));
    renamed.map_err(|e| {
        // NOTE: the temporary file may not exist (creation failed); nothing to report then.
        let _ = std::fs::remove_file(&temp);
        write_error(path, e.to_string())
    })
}

/// Writes everything, flushes and (for regular files) syncs, so that a full disk is an
/// error here rather than a silently short file.
fn write_all_synced(out: &mut File, bytes: &[u8], sync: bool) -> io::Result<()> {
    out.write_all(bytes)?;
    out.flush()?;
    if sync { out.sync_all() } else { Ok(()) }
}

/// Encodes an RGBA8 image as PNG bytes.
pub fn encode_png(image: &RgbaImage) -> Result<Vec<u8>, image::ImageError> {
    let mut bytes = Vec::new();
    PngEncoder::new(&mut bytes).write_image(image.as_raw(), image.width(), image.height(), ExtendedColorType::Rgba8)?;
    Ok(bytes)
}

/// Writes a colour image as PNG (the path must end in `.png`).
pub fn write_color_image(path: &Path, image: &RgbaImage) -> Result<(), ExportError> {
    prepare_extension(path, OutputKind::ColorImage)?;
    let bytes = encode_png(image).map_err(|e| write_error(path, e.to_string()))?;
    write_file(path, &bytes)
}

/// Checks the extension of `path` for `kind`. An existing special file (a device or a pipe,
/// like `/dev/stdout`) takes the kind's first format whatever its name.
fn prepare_extension(path: &Path, kind: OutputKind) -> Result<(), ExportError> {
    let allowed = kind.extensions();
    if allowed.is_empty() || is_special(path) {
        return Ok(());
    }
    match extension(path) {
        Some(e) if allowed.contains(&e.as_str()) => Ok(()),
        _ => Err(ExportError::Extension {
            path: path.display().to_string(),
            expected: kind.expected().to_owned(),
        }),
    }
}

/// Writes `values` (`width * height`, rows top to bottom, nominally 0–1) to `path`: `.png`
/// stores `round(clamp(v, 0, 1) · 65535)` as 16-bit greyscale, `.pfm` stores the f32 values
/// exactly (PFM rows run bottom to top, as the format defines).
pub fn write_scalar_image(path: &Path, width: u32, height: u32, values: &[f32]) -> Result<(), ExportError> {
    prepare_extension(path, OutputKind::ScalarImage)?;
    if values.len() as u64 != width as u64 * height as u64 {
        let message = format!("{} values for a {width}×{height} image", values.len());
        return Err(write_error(path, message));
    }
    let bytes = match extension(path).as_deref().filter(|_| !is_special(path)) {
        Some("pfm") => {
            // A negative scale marks little-endian data.
            let mut bytes = format!("Pf\n{width} {height}\n-1.0\n").into_bytes();
            for row in values.chunks(width.max(1) as usize).rev() {
                bytes.extend(row.iter().flat_map(|v| v.to_le_bytes()));
            }
            bytes
        }
        _ => {
            let pixels: Vec<u8> = values
                .iter()
                .flat_map(|v| ((v.clamp(0.0, 1.0) * 65535.0).round() as u16).to_ne_bytes())
                .collect();
            let mut bytes = Vec::new();
            PngEncoder::new(&mut bytes)
                .write_image(&pixels, width, height, ExtendedColorType::L16)
                .map_err(|e| write_error(path, e.to_string()))?;
            bytes
        }
    };
    write_file(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("penumbra-export-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn png_and_pfm_round_trip() {
        let dir = scratch("round-trip");
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
        assert!(!dir.join("s.jpg").exists(), "no file is left for a refused extension");
        // Only the two outputs: no temporary files left behind.
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
    }

    #[test]
    fn outputs_are_checked_before_any_work() {
        let dir = scratch("prepare");
        let nested = dir.join("a/b/out.png");
        prepare_output(&nested, OutputKind::ColorImage).unwrap();
        assert!(nested.parent().unwrap().is_dir(), "the folder is created");
        assert!(!nested.exists(), "the check leaves no file");
        assert_eq!(std::fs::read_dir(nested.parent().unwrap()).unwrap().count(), 0);
        let err = prepare_output(&dir.join("out.jpg"), OutputKind::ColorImage).unwrap_err();
        assert_eq!(
            err.to_string(),
            format!(
                "{}: unknown image type, expected a .png path",
                dir.join("out.jpg").display()
            )
        );
        let err = prepare_output(&dir.join("a.png"), OutputKind::ScalarImage);
        assert!(err.is_ok(), "{err:?}");
        std::fs::create_dir_all(dir.join("d.png")).unwrap();
        let err = prepare_output(&dir.join("d.png"), OutputKind::ColorImage).unwrap_err();
        assert!(err.to_string().ends_with("d.png: is a directory"), "{err}");
        // A folder that is a file.
        std::fs::write(dir.join("f"), b"x").unwrap();
        let err = prepare_output(&dir.join("f/out.png"), OutputKind::ColorImage).unwrap_err();
        assert!(err.to_string().contains("cannot create its folder"), "{err}");
    }

    /// Linux's always-full device stands in for a full disk.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_full_device_is_an_error_not_a_silent_success() {
        let full = Path::new("/dev/full");
        let image = RgbaImage::new(4, 4);
        let err = write_file(full, &encode_png(&image).unwrap()).unwrap_err().to_string();
        assert!(err.starts_with("/dev/full: "), "{err}");
        assert!(err.to_lowercase().contains("space"), "{err}");
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_partial_file() {
        let dir = scratch("failed");
        let out = dir.join("out.png");
        std::fs::write(&out, b"old").unwrap();
        // A temporary name that cannot be created: its place is taken by a folder.
        std::fs::create_dir_all(temp_path(&out)).unwrap();
        std::fs::write(temp_path(&out).join("keep"), b"x").unwrap();
        assert!(write_file(&out, b"new").is_err());
        assert_eq!(std::fs::read(&out).unwrap(), b"old");
    }
}
