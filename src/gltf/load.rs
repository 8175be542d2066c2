//! Reading a glTF document: the GLB container or JSON, the checks that must precede the
//! `gltf` crate's own validation and readers, buffers (external, `data:` or GLB chunk),
//! buffer views and images.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use ::gltf::json::validation::{Error as RuleError, Validate};
use ::gltf::json::{self, Path as JsonPath};
use ::gltf::{Document, binary::Glb, buffer, image as gimage};
use base64::Engine;
use base64::engine::general_purpose::STANDARD as BASE64;

use crate::asset_io::{AssetError, AssetIo, AssetPath};
use crate::diagnostic::SourceLines;
use crate::ecs::assets::ImageData;
use crate::gltf::json_path::{char_column, path_lines};
use crate::gltf::{GltfError, GltfModel, JsonContext, animation, material, mesh, nodes, skin};

/// The file being loaded, its directory, the asset root and the warnings collected so far.
pub(super) struct Cx<'a> {
    /// The file given to `load`.
    pub path: &'a Path,
    /// Directory relative URIs resolve against.
    dir: PathBuf,
    /// Where URIs may point, and the read limits.
    io: &'a AssetIo,
    /// Things skipped or approximated.
    pub warnings: Vec<String>,
}

impl<'a> Cx<'a> {
    fn new(path: &'a Path, io: &'a AssetIo) -> Self {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        Self {
            path,
            dir,
            io,
            warnings: Vec::new(),
        }
    }

    /// A [`GltfError::Asset`] about `what`.
    fn asset(&self, what: &str, source: AssetError) -> GltfError {
        GltfError::Asset {
            path: self.path.to_path_buf(),
            what: what.to_owned(),
            source,
        }
    }

    /// A [`GltfError::Data`] about `context`.
    pub fn data(&self, context: impl Into<String>, problem: impl Into<String>) -> GltfError {
        GltfError::Data {
            path: self.path.to_path_buf(),
            context: context.into(),
            problem: problem.into(),
        }
    }

    /// A [`GltfError::Invalid`] with no place in the JSON text.
    fn invalid(&self, message: impl Into<String>) -> GltfError {
        self.invalid_at(message, JsonContext::Unknown)
    }

    /// A [`GltfError::Invalid`] at a place in the JSON text.
    fn invalid_at(&self, message: impl Into<String>, json: JsonContext) -> GltfError {
        GltfError::Invalid {
            path: self.path.to_path_buf(),
            message: message.into(),
            json,
        }
    }

    /// Records a warning.
    pub fn warn(&mut self, message: impl Into<String>) {
        self.warnings.push(message.into());
    }
}

/// Reads the glTF file itself: a regular file, at most the read cap.
fn read_model_file(path: &Path, io: &AssetIo) -> Result<Vec<u8>, GltfError> {
    let io_error = |source| GltfError::Io {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io_error)?;
    if !meta.is_file() {
        return Err(io_error(std::io::Error::other("not a regular file")));
    }
    if meta.len() > io.max_file_bytes {
        let message = format!("{} bytes, more than the {} allowed", meta.len(), io.max_file_bytes);
        return Err(io_error(std::io::Error::other(message)));
    }
    std::fs::read(path).map_err(io_error)
}

/// Loads the file at `path`; see [`crate::gltf::load_with`].
pub(super) fn load(path: &Path, io: &AssetIo) -> Result<GltfModel, GltfError> {
    let bytes = read_model_file(path, io)?;
    let mut cx = Cx::new(path, io);
    let (root, blob) = parse(&cx, &bytes)?;
    precheck(&cx, &root)?;
    validate(&cx, &root, json_text(&bytes))?;
    drop(bytes);
    for ext in &root.extensions_used {
        // NOTE: only the diffuse transmission factor is read of the one extension supported.
        if ext != material::DIFFUSE_TRANSMISSION && !root.extensions_required.contains(ext) {
            cx.warn(format!("extension {ext} is ignored"));
        }
    }
    let document = Document::from_json_without_validation(root);
    let buffers = load_buffers(&cx, &document, blob)?;
    check_views(&cx, &document)?;
    let (images, image_slots) = load_images(&cx, &document, &buffers)?;
    let mut materials = material::read_materials(&mut cx, &document);
    // Materials index the distinct images.
    for m in &mut materials {
        m.base_color_texture = m.base_color_texture.and_then(|i| image_slots.get(i).copied());
    }
    let meshes = mesh::read_meshes(&mut cx, &document, &buffers)?;
    let skins = skin::read_skins(&cx, &document, &buffers)?;
    let nodes = nodes::flatten(&mut cx, &document, &meshes, &skins)?;
    let hierarchy = animation::read_hierarchy(&cx, &document)?;
    let animations = animation::read_animations(&mut cx, &document, &buffers)?;
    Ok(GltfModel {
        meshes,
        materials,
        images,
        nodes,
        hierarchy,
        skins,
        animations,
        warnings: cx.warnings,
    })
}

/// Splits a GLB container (checking its header first: the crate's reader underflows on a
/// short length) or takes the bytes as JSON, and deserializes the JSON.
fn parse(cx: &Cx, bytes: &[u8]) -> Result<(json::Root, Option<Vec<u8>>), GltfError> {
    let (json_bytes, blob) = if bytes.starts_with(b"glTF") {
        let word = |i: usize| {
            bytes
                .get(i..i + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        };
        let (Some(version), Some(length)) = (word(4), word(8)) else {
            return Err(cx.invalid(format!("GLB header is truncated: {} bytes", bytes.len())));
        };
        if version != 2 {
            return Err(cx.invalid(format!("GLB version {version}; only version 2 is supported")));
        }
        let length = length as usize;
        if length < 20 {
            return Err(cx.invalid(format!(
                "GLB header declares {length} bytes, fewer than a header and a chunk"
            )));
        }
        if length > bytes.len() {
            return Err(cx.invalid(format!(
                "GLB header declares {length} bytes, the file has {}",
                bytes.len()
            )));
        }
        let glb = Glb::from_slice(&bytes[..length]).map_err(|e| cx.invalid(format!("GLB container: {e}")))?;
        (glb.json.into_owned(), glb.bin.map(|b| b.into_owned()))
    } else {
        (bytes.to_vec(), None)
    };
    // Some exporters pad the JSON chunk with NULs instead of spaces.
    let end = json_bytes.iter().rposition(|&b| b != 0).map_or(0, |i| i + 1);
    let root: json::Root = json::deserialize::from_slice(&json_bytes[..end]).map_err(|e| {
        let message = e.to_string();
        let json = match json_text(bytes) {
            Some(text) if e.line() > 0 => {
                let (line, column) = (e.line(), char_column(text, e.line(), e.column()));
                let at = format!(" at line {line} column {}", e.column());
                JsonContext::Position {
                    line,
                    column,
                    message: message.strip_suffix(&at).unwrap_or(&message).to_owned(),
                    source_lines: SourceLines::new(text, &[(line, column, 1)]),
                }
            }
            _ => JsonContext::Unknown,
        };
        cx.invalid_at(message, json)
    })?;
    Ok((root, blob))
}

/// The JSON text of a `.gltf` file (NUL padding cut), to show the lines of errors; `None`
/// for a GLB file (binary) or JSON that is not UTF-8.
fn json_text(bytes: &[u8]) -> Option<&str> {
    if bytes.starts_with(b"glTF") {
        return None;
    }
    let end = bytes.iter().rposition(|&b| b != 0).map_or(0, |i| i + 1);
    std::str::from_utf8(&bytes[..end]).ok()
}

/// Checks the crate relies on without checking: every primitive has a `POSITION` attribute
/// that names an existing accessor (its validation hook indexes the accessor list with it),
/// and every image has a `uri` or a `bufferView`, the latter with a `mimeType` (its image
/// source unwraps them).
fn precheck(cx: &Cx, root: &json::Root) -> Result<(), GltfError> {
    for (i, image) in root.images.iter().enumerate() {
        let problem = match (&image.uri, &image.buffer_view, &image.mime_type) {
            (None, None, _) => "has neither a `uri` nor a `bufferView`",
            (_, Some(_), None) => "is in a `bufferView` but has no `mimeType`",
            _ => continue,
        };
        return Err(cx.data(format!("image {i}"), problem));
    }
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = json::validation::Checked::Valid(json::mesh::Semantic::Positions);
            let Some(index) = primitive.attributes.get(&position) else {
                return Err(GltfError::MissingPosition {
                    path: cx.path.to_path_buf(),
                    mesh: m,
                    primitive: p,
                });
            };
            if index.value() >= root.accessors.len() {
                return Err(cx.data(
                    format!("mesh {m} primitive {p}"),
                    format!(
                        "POSITION refers to accessor {}, but there are {} accessors",
                        index.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The `gltf` crate's validation: indices in range, required properties present, enums
/// known, required extensions supported. A POSITION accessor without `min`/`max` is
/// accepted: the spec requires them but nothing here uses them. `text` is the JSON text of a
/// `.gltf` file, kept in the error to show where the problems are.
fn validate(cx: &Cx, root: &json::Root, text: Option<&str>) -> Result<(), GltfError> {
    let mut problems: Vec<(String, String)> = Vec::new();
    root.validate(
        root,
        JsonPath::new,
        &mut |path: &dyn Fn() -> JsonPath, error: RuleError| {
            let path = path();
            let bounds = path.as_str().ends_with("[\"POSITION\"].min") || path.as_str().ends_with("[\"POSITION\"].max");
            if !(bounds && matches!(error, RuleError::Missing)) {
                problems.push((path.to_string(), error.to_string()));
            }
        },
    );
    if problems.is_empty() {
        return Ok(());
    }
    let message: Vec<String> = problems
        .iter()
        .map(|(path, error)| format!("{path}: {error}"))
        .collect();
    let json = match text {
        Some(text) => JsonContext::Paths {
            source_lines: path_lines(text, &problems),
            problems,
        },
        None => JsonContext::Unknown,
    };
    Err(cx.invalid_at(message.join("; "), json))
}

/// Where a URI points: embedded bytes or a file inside the asset root.
enum Uri {
    Data(Vec<u8>),
    File(AssetPath, String),
}

/// A URI as it appears in messages: the text for files, `data URI` for embedded data.
fn describe_uri(uri: &str) -> String {
    if uri.starts_with("data:") {
        "data URI".to_owned()
    } else {
        format!("`{uri}`")
    }
}

/// Resolves a URI: `data:` (base64 or percent-encoded), or a relative reference, percent
/// decoded, against the file's directory and confined to the asset root. Other schemes are
/// refused.
fn resolve_uri(cx: &Cx, what: &str, uri: &str) -> Result<Uri, GltfError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((header, payload)) = rest.split_once(',') else {
            return Err(cx.data(what, "data URI has no `,` before its data"));
        };
        return if header.ends_with(";base64") {
            let payload: String = payload.chars().filter(|c| !c.is_ascii_whitespace()).collect();
            BASE64
                .decode(payload)
                .map(Uri::Data)
                .map_err(|e| cx.data(what, format!("data URI is not valid base64: {e}")))
        } else {
            Ok(Uri::Data(percent_decode(payload)))
        };
    }
    let scheme_len = uri.find(':').filter(|&i| {
        let scheme = &uri[..i];
        scheme.len() > 1
            && scheme.starts_with(|c: char| c.is_ascii_alphabetic())
            && scheme.chars().all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    });
    if let Some(i) = scheme_len {
        return Err(cx.data(
            what,
            format!(
                "URI scheme `{}:` is not supported (only relative paths and data URIs)",
                &uri[..i]
            ),
        ));
    }
    let decoded = String::from_utf8_lossy(&percent_decode(uri)).into_owned();
    let file = cx.io.resolve(&cx.dir, &decoded).map_err(|e| cx.asset(what, e))?;
    Ok(Uri::File(file, decoded))
}

/// Decodes `%XX` escapes; malformed escapes are kept as they are.
pub(super) fn percent_decode(text: &str) -> Vec<u8> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && let (Some(hi), Some(lo)) = (
                bytes.get(i + 1).and_then(|&b| hex(b)),
                bytes.get(i + 2).and_then(|&b| hex(b)),
            )
        {
            out.push((hi * 16 + lo) as u8);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    out
}

/// Reads a buffer URI's bytes: at most `declared` bytes of a file.
fn read_buffer_uri(cx: &Cx, what: &str, uri: &str, declared: u64) -> Result<Vec<u8>, GltfError> {
    match resolve_uri(cx, what, uri)? {
        Uri::Data(bytes) => Ok(bytes),
        Uri::File(file, reference) => cx
            .io
            .read(&file, &reference, Some(declared))
            .map_err(|e| cx.asset(what, e)),
    }
}

/// Every buffer's bytes, cut to its declared `byteLength` (a GLB chunk may be padded).
fn load_buffers(cx: &Cx, document: &Document, blob: Option<Vec<u8>>) -> Result<Vec<Vec<u8>>, GltfError> {
    let mut out = Vec::new();
    for buffer in document.buffers() {
        let i = buffer.index();
        let (what, mut data) = match buffer.source() {
            buffer::Source::Bin => {
                let what = format!("buffer {i} (GLB BIN chunk)");
                let Some(blob) = &blob else {
                    return Err(cx.data(format!("buffer {i}"), "has no uri and the file has no GLB BIN chunk"));
                };
                (what, blob.clone())
            }
            buffer::Source::Uri(uri) => {
                let what = format!("buffer {i} ({})", describe_uri(uri));
                let data = read_buffer_uri(cx, &what, uri, buffer.length() as u64)?;
                (what, data)
            }
        };
        let declared = buffer.length() as u64;
        let actual = data.len() as u64;
        if actual < declared {
            return Err(GltfError::Truncated {
                path: cx.path.to_path_buf(),
                what,
                actual,
                declared,
            });
        }
        data.truncate(buffer.length());
        out.push(data);
    }
    Ok(out)
}

/// Every buffer view lies inside its buffer (buffer lengths were checked on loading).
fn check_views(cx: &Cx, document: &Document) -> Result<(), GltfError> {
    for view in document.views() {
        let buffer = view.buffer();
        let start = view.offset() as u64;
        let end = start.checked_add(view.length() as u64);
        if end.is_none_or(|end| end > buffer.length() as u64) {
            return Err(cx.data(
                format!("buffer view {}", view.index()),
                format!(
                    "bytes {start}..{} are outside buffer {} ({} bytes)",
                    end.map_or("overflow".to_owned(), |e| e.to_string()),
                    buffer.index(),
                    buffer.length()
                ),
            ));
        }
    }
    Ok(())
}

/// The bytes of a buffer view (checked by [`check_views`]).
pub(super) fn view_bytes<'b>(view: &buffer::View, buffers: &'b [Vec<u8>]) -> &'b [u8] {
    &buffers[view.buffer().index()][view.offset()..view.offset() + view.length()]
}

/// Every distinct image decoded to RGBA8 (under the image limits), and for each glTF image
/// the index of its decoded copy: images naming one file (by any spelling) decode once.
fn load_images(cx: &Cx, document: &Document, buffers: &[Vec<u8>]) -> Result<(Vec<ImageData>, Vec<usize>), GltfError> {
    let mut out = Vec::new();
    let mut slots = Vec::new();
    let mut by_file: HashMap<AssetPath, usize> = HashMap::new();
    for image in document.images() {
        let i = image.index();
        let (what, bytes) = match image.source() {
            gimage::Source::Uri { uri, .. } => {
                let what = format!("image {i} ({})", describe_uri(uri));
                match resolve_uri(cx, &what, uri)? {
                    Uri::Data(bytes) => (what, bytes),
                    Uri::File(file, reference) => {
                        if let Some(&slot) = by_file.get(&file) {
                            slots.push(slot);
                            continue;
                        }
                        let bytes = cx.io.read(&file, &reference, None).map_err(|e| cx.asset(&what, e))?;
                        by_file.insert(file, out.len());
                        (what, bytes)
                    }
                }
            }
            gimage::Source::View { view, .. } => (
                format!("image {i} (buffer view {})", view.index()),
                view_bytes(&view, buffers).to_vec(),
            ),
        };
        let decoded = cx.io.decode_image(&bytes, &what).map_err(|e| cx.asset(&what, e))?;
        slots.push(out.len());
        out.push(decoded);
    }
    Ok((out, slots))
}

#[cfg(test)]
mod tests {
    use super::percent_decode;

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("leaf%20card.png"), b"leaf card.png");
        assert_eq!(percent_decode("a%2Fb%zz%4"), b"a/b%zz%4");
        assert_eq!(percent_decode("%C3%A9"), "é".as_bytes());
    }
}
