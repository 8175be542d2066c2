//! Accessor checks that make the `gltf` crate's readers safe: the crate slices buffer views
//! with unchecked arithmetic and asserts element sizes, so every accessor is checked
//! against its view (offset, count, stride, element size, sparse storage) and its type
//! against what the reader of its semantic expects, before it is read.

use ::gltf::Accessor;
use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::buffer::View;

use crate::gltf::GltfError;
use crate::gltf::load::Cx;

/// The most elements an accessor without a buffer view (all zeros plus sparse values) may
/// have: its count is not bounded by any storage, so it is bounded here.
const MAX_UNSTORED_COUNT: usize = 1 << 24;

/// The element types a semantic accepts.
#[derive(Clone, Copy, Debug)]
pub(super) enum Expect {
    /// `VEC3` of `FLOAT` (POSITION, NORMAL).
    Vec3F32,
    /// `VEC2` of `FLOAT`, or of normalized `UNSIGNED_BYTE` / `UNSIGNED_SHORT` (TEXCOORD_n).
    TexCoord,
    /// `SCALAR` `UNSIGNED_BYTE`, `UNSIGNED_SHORT` or `UNSIGNED_INT` (indices).
    Index,
    /// `VEC4` `UNSIGNED_BYTE` or `UNSIGNED_SHORT`, not normalized (JOINTS_0).
    Joints,
    /// `VEC4` `FLOAT`, or normalized `UNSIGNED_BYTE` / `UNSIGNED_SHORT` (WEIGHTS_0).
    Weights,
    /// `MAT4` `FLOAT` (inverse bind matrices).
    Mat4F32,
    /// `SCALAR` `FLOAT` (animation key times).
    ScalarF32,
    /// `VEC4` `FLOAT`, or normalized `BYTE` / `UNSIGNED_BYTE` / `SHORT` / `UNSIGNED_SHORT`
    /// (rotation keys).
    Rotation,
}

impl Expect {
    fn accepts(self, data_type: DataType, dimensions: Dimensions, normalized: bool) -> bool {
        match self {
            Self::Vec3F32 => dimensions == Dimensions::Vec3 && data_type == DataType::F32,
            Self::TexCoord => {
                dimensions == Dimensions::Vec2
                    && (data_type == DataType::F32 || (normalized && matches!(data_type, DataType::U8 | DataType::U16)))
            }
            Self::Index => {
                dimensions == Dimensions::Scalar
                    && !normalized
                    && matches!(data_type, DataType::U8 | DataType::U16 | DataType::U32)
            }
            Self::Joints => {
                dimensions == Dimensions::Vec4 && !normalized && matches!(data_type, DataType::U8 | DataType::U16)
            }
            Self::Weights => {
                dimensions == Dimensions::Vec4
                    && (data_type == DataType::F32 || (normalized && matches!(data_type, DataType::U8 | DataType::U16)))
            }
            Self::Mat4F32 => dimensions == Dimensions::Mat4 && data_type == DataType::F32,
            Self::ScalarF32 => dimensions == Dimensions::Scalar && data_type == DataType::F32,
            Self::Rotation => {
                dimensions == Dimensions::Vec4
                    && (data_type == DataType::F32
                        || (normalized
                            && matches!(data_type, DataType::I8 | DataType::U8 | DataType::I16 | DataType::U16)))
            }
        }
    }

    fn describe(self) -> &'static str {
        match self {
            Self::Vec3F32 => "VEC3 FLOAT",
            Self::TexCoord => "VEC2 FLOAT or normalized VEC2 UNSIGNED_BYTE/UNSIGNED_SHORT",
            Self::Index => "SCALAR UNSIGNED_BYTE/UNSIGNED_SHORT/UNSIGNED_INT",
            Self::Joints => "VEC4 UNSIGNED_BYTE/UNSIGNED_SHORT",
            Self::Weights => "VEC4 FLOAT or normalized VEC4 UNSIGNED_BYTE/UNSIGNED_SHORT",
            Self::Mat4F32 => "MAT4 FLOAT",
            Self::ScalarF32 => "SCALAR FLOAT",
            Self::Rotation => "VEC4 FLOAT or normalized VEC4 BYTE/UNSIGNED_BYTE/SHORT/UNSIGNED_SHORT",
        }
    }
}

fn type_name(data_type: DataType, dimensions: Dimensions, normalized: bool) -> String {
    let dims = match dimensions {
        Dimensions::Scalar => "SCALAR",
        Dimensions::Vec2 => "VEC2",
        Dimensions::Vec3 => "VEC3",
        Dimensions::Vec4 => "VEC4",
        Dimensions::Mat2 => "MAT2",
        Dimensions::Mat3 => "MAT3",
        Dimensions::Mat4 => "MAT4",
    };
    let component = match data_type {
        DataType::I8 => "BYTE",
        DataType::U8 => "UNSIGNED_BYTE",
        DataType::I16 => "SHORT",
        DataType::U16 => "UNSIGNED_SHORT",
        DataType::U32 => "UNSIGNED_INT",
        DataType::F32 => "FLOAT",
    };
    let norm = if normalized { "normalized " } else { "" };
    format!("{norm}{dims} {component}")
}

/// Checks that `accessor` (used as `semantic` by `context`, like `mesh 0 primitive 1`) has
/// an accepted type, at least one element, and storage that holds every element it reads.
pub(super) fn check(
    cx: &Cx,
    context: &str,
    semantic: &str,
    accessor: &Accessor,
    expect: Expect,
) -> Result<(), GltfError> {
    let a = accessor.index();
    let what = format!("{semantic} (accessor {a})");
    let err = |problem: String| cx.data(context, format!("{what}: {problem}"));
    let (data_type, dimensions, normalized) = (accessor.data_type(), accessor.dimensions(), accessor.normalized());
    if !expect.accepts(data_type, dimensions, normalized) {
        return Err(err(format!(
            "must be {}, found {}",
            expect.describe(),
            type_name(data_type, dimensions, normalized)
        )));
    }
    let count = accessor.count();
    if count == 0 {
        return Err(err("has count 0".to_owned()));
    }
    let element = accessor.size();
    match accessor.view() {
        Some(view) => check_range(accessor.offset(), count, element, &view).map_err(err)?,
        None if accessor.sparse().is_none() => {
            return Err(err("has neither a buffer view nor sparse values".to_owned()));
        }
        None if count > MAX_UNSTORED_COUNT => {
            return Err(err(format!(
                "has {count} elements without a buffer view (at most {MAX_UNSTORED_COUNT})"
            )));
        }
        None => {}
    }
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        if n == 0 || n > count {
            return Err(err(format!("sparse count {n} is not in 1..={count}")));
        }
        let indices = sparse.indices();
        check_range(indices.offset(), n, indices.index_type().size(), &indices.view())
            .map_err(|p| err(format!("sparse indices: {p}")))?;
        let values = sparse.values();
        check_range(values.offset(), n, element, &values.view()).map_err(|p| err(format!("sparse values: {p}")))?;
    }
    Ok(())
}

/// Checks that `count` elements of `element` bytes, `offset` bytes into `view` and spaced by
/// the view's stride (or packed), lie inside the view. The view itself lies inside its
/// buffer (checked on loading).
fn check_range(offset: usize, count: usize, element: usize, view: &View) -> Result<(), String> {
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!(
            "byte stride {stride} of buffer view {} is smaller than an element ({element} bytes)",
            view.index()
        ));
    }
    let end = (count as u64 - 1)
        .checked_mul(stride as u64)
        .and_then(|e| e.checked_add(element as u64))
        .and_then(|e| e.checked_add(offset as u64));
    match end {
        Some(end) if end <= view.length() as u64 => Ok(()),
        _ => Err(format!(
            "{count} elements of {element} bytes from byte {offset} (stride {stride}) reach {}, past the end of buffer view {} ({} bytes)",
            end.map_or("beyond 2^64 bytes".to_owned(), |e| format!("byte {e}")),
            view.index(),
            view.length()
        )),
    }
}
