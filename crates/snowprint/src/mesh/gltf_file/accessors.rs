//! Accessors read with checked arithmetic: positions and indices.

use glam::Vec3;

use super::{MAX_GLTF_TRIANGLES, MAX_GLTF_VERTICES};

/// Where an accessor's elements lie: the buffer's bytes from the first element, the stride, the
/// count and the element size.
pub(super) struct Elements<'a> {
    bytes: &'a [u8],
    stride: usize,
    count: usize,
    size: usize,
}

impl Elements<'_> {
    fn get(&self, i: usize) -> &[u8] {
        &self.bytes[i * self.stride..i * self.stride + self.size]
    }
}

/// Locate an accessor's elements in its buffer, with every offset checked.
pub(super) fn elements<'a>(
    accessor: &gltf::Accessor<'_>,
    buffers: &'a [Vec<u8>],
    size: usize,
) -> std::result::Result<Elements<'a>, String> {
    if accessor.sparse().is_some() {
        return Err(
            "is sparse, which snowprint does not read; export without sparse accessors".into(),
        );
    }
    let count = accessor.count();
    if count == 0 {
        return Err("has count 0; an accessor needs at least one element".into());
    }
    let Some(view) = accessor.view() else {
        return Err("has no bufferView; give it one".into());
    };
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or("names a buffer that does not exist")?;
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "has a byteStride of {stride}, less than its element's {size} bytes; fix the byteStride"
        ));
    }
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&e| e <= buffer.len())
        .ok_or_else(|| {
            format!(
                "has a bufferView (bytes {} to {} of buffer {}) that does not fit its {} bytes; fix the bufferView",
                view.offset(),
                view.offset().saturating_add(view.length()),
                view.buffer().index(),
                buffer.len()
            )
        })?;
    let start = view.offset().checked_add(accessor.offset());
    let end = (count - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(size))
        .and_then(|x| x.checked_add(start?));
    match (start, end) {
        (Some(start), Some(end)) if end <= view_end => Ok(Elements {
            bytes: &buffer[start..end],
            stride,
            count,
            size,
        }),
        _ => Err(format!(
            "has {count} elements of {size} bytes at offset {} and stride {stride}, which do not fit its bufferView of {} bytes; fix the count or the offsets",
            accessor.offset(),
            view.length()
        )),
    }
}

pub(crate) fn read_positions(
    accessor: &gltf::Accessor<'_>,
    buffers: &[Vec<u8>],
) -> std::result::Result<Vec<Vec3>, String> {
    use gltf::accessor::{DataType, Dimensions};
    if accessor.data_type() != DataType::F32 || accessor.dimensions() != Dimensions::Vec3 {
        return Err(format!(
            "holds {:?} {:?}, but positions must be VEC3 of FLOAT; export positions as floats",
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    if accessor.count() > MAX_GLTF_VERTICES {
        return Err(format!(
            "has {} vertices, more than {MAX_GLTF_VERTICES}; simplify the mesh",
            accessor.count()
        ));
    }
    let e = elements(accessor, buffers, 12)?;
    Ok((0..e.count)
        .map(|i| {
            let b = e.get(i);
            let f = |k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
            Vec3::new(f(0), f(4), f(8))
        })
        .collect())
}

pub(crate) fn read_indices(
    accessor: &gltf::Accessor<'_>,
    buffers: &[Vec<u8>],
) -> std::result::Result<Vec<u32>, String> {
    use gltf::accessor::{DataType, Dimensions};
    let size = match accessor.data_type() {
        DataType::U8 => 1,
        DataType::U16 => 2,
        DataType::U32 => 4,
        other => {
            return Err(format!(
                "holds {other:?}, but indices must be unsigned integers; fix the componentType"
            ));
        }
    };
    if accessor.dimensions() != Dimensions::Scalar {
        return Err(format!(
            "holds {:?}, but indices must be SCALAR; fix the type",
            accessor.dimensions()
        ));
    }
    if accessor.count() / 3 > MAX_GLTF_TRIANGLES {
        return Err(format!(
            "has {} indices, more than {} triangles; simplify the mesh",
            accessor.count(),
            MAX_GLTF_TRIANGLES
        ));
    }
    if !accessor.count().is_multiple_of(3) {
        return Err(format!(
            "has {} indices, not a multiple of 3 as a triangle list needs; fix the count",
            accessor.count()
        ));
    }
    let e = elements(accessor, buffers, size)?;
    Ok((0..e.count)
        .map(|i| {
            let b = e.get(i);
            match size {
                1 => u32::from(b[0]),
                2 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            }
        })
        .collect())
}

/// Every component of an accessor as `f32`, `dims` components an element: floats as stored;
/// integers divided by their type's maximum when the accessor is `normalized` (glTF's rule, signed
/// ones clamped at -1), as stored when not. `what` names the expected content in messages (e.g.
/// `"VEC4 of FLOAT or normalized UNSIGNED_BYTE or UNSIGNED_SHORT"`), `types` the component types
/// accepted, `normalized` whether integers must be normalized (`Some(true)`), must not be
/// (`Some(false)`), or may be either. At most `max_count` elements are read.
pub(crate) fn read_components(
    accessor: &gltf::Accessor<'_>,
    buffers: &[Vec<u8>],
    dims: gltf::accessor::Dimensions,
    types: &[gltf::accessor::DataType],
    normalized: Option<bool>,
    what: &str,
    max_count: usize,
) -> std::result::Result<Vec<f32>, String> {
    use gltf::accessor::DataType;
    let ty = accessor.data_type();
    let integer = ty != DataType::F32;
    let wrong_norm = integer && normalized.is_some_and(|n| n != accessor.normalized());
    if accessor.dimensions() != dims || !types.contains(&ty) || wrong_norm {
        let norm = if accessor.normalized() {
            " normalized"
        } else {
            ""
        };
        return Err(format!(
            "holds {:?} of{norm} {:?}, but must hold {what}; export it again with that type",
            accessor.dimensions(),
            ty
        ));
    }
    if accessor.count() > max_count {
        return Err(format!(
            "has {} elements, more than the {max_count} snowprint reads; simplify the file",
            accessor.count()
        ));
    }
    let n = dims.multiplicity();
    let size = ty.size();
    let e = elements(accessor, buffers, n * size)?;
    let norm = accessor.normalized();
    let mut out = Vec::with_capacity(e.count * n);
    for i in 0..e.count {
        let b = e.get(i);
        for c in b.chunks_exact(size) {
            let v = match ty {
                DataType::F32 => f32::from_le_bytes([c[0], c[1], c[2], c[3]]),
                DataType::U8 if norm => f32::from(c[0]) / 255.0,
                DataType::U8 => f32::from(c[0]),
                DataType::I8 if norm => (f32::from(c[0] as i8) / 127.0).max(-1.0),
                DataType::I8 => f32::from(c[0] as i8),
                DataType::U16 if norm => f32::from(u16::from_le_bytes([c[0], c[1]])) / 65535.0,
                DataType::U16 => f32::from(u16::from_le_bytes([c[0], c[1]])),
                DataType::I16 if norm => {
                    (f32::from(i16::from_le_bytes([c[0], c[1]])) / 32767.0).max(-1.0)
                }
                DataType::I16 => f32::from(i16::from_le_bytes([c[0], c[1]])),
                DataType::U32 => u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f32,
            };
            out.push(v);
        }
    }
    Ok(out)
}
