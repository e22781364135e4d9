//! Reading accessors from buffer bytes: vertex positions (VEC3 float) and triangle indices
//! (unsigned byte, short or int scalars), with the accessor's and the buffer view's byte
//! offsets and the view's byte stride. Every range is checked; nothing here can panic.

use super::buffers::Buffers;
use crate::Result;
use glam::DVec3;
use gltf::json;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;

/// Where the elements of an accessor lie.
enum Layout {
    /// An accessor without a buffer view: `count` zeros.
    Zeros,
    /// In buffer `buffer`, element `k` starts at `start + k * stride`.
    InBuffer {
        buffer: usize,
        start: usize,
        stride: usize,
    },
}

fn err(file: &str, message: String) -> crate::Error {
    crate::Error::File {
        file: file.to_owned(),
        message,
    }
}

fn component_size(c: ComponentType) -> usize {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

fn component_name(c: ComponentType) -> &'static str {
    match c {
        ComponentType::I8 => "BYTE",
        ComponentType::U8 => "UNSIGNED_BYTE",
        ComponentType::I16 => "SHORT",
        ComponentType::U16 => "UNSIGNED_SHORT",
        ComponentType::U32 => "UNSIGNED_INT",
        ComponentType::F32 => "FLOAT",
    }
}

fn type_name(t: Type) -> &'static str {
    match t {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

/// Accessor `index`, its element type checked against what `role` needs.
fn accessor<'r>(
    root: &'r json::Root,
    index: usize,
    file: &str,
    role: &str,
) -> Result<(&'r json::Accessor, ComponentType, Type)> {
    let a = root.accessors.get(index).ok_or_else(|| {
        err(
            file,
            format!(
                "{role}: accessors[{index}] does not exist ({} accessors)",
                root.accessors.len()
            ),
        )
    })?;
    let (Checked::Valid(c), Checked::Valid(t)) = (&a.component_type, &a.type_) else {
        return Err(err(
            file,
            format!("accessors[{index}] ({role}): invalid componentType or type"),
        ));
    };
    if a.sparse.is_some() {
        return Err(err(
            file,
            format!("accessors[{index}] ({role}): sparse accessors are not supported"),
        ));
    }
    Ok((a, c.0, *t))
}

/// Checks that `count` elements of `elem` bytes fit where the accessor says they are.
fn layout(
    root: &json::Root,
    buffers: &mut Buffers,
    index: usize,
    a: &json::Accessor,
    elem: usize,
    file: &str,
    role: &str,
) -> Result<Layout> {
    let here = |m: String| err(file, format!("accessors[{index}] ({role}): {m}"));
    let Some(view_index) = &a.buffer_view else {
        return Ok(Layout::Zeros);
    };
    let vi = view_index.value();
    let view = root.buffer_views.get(vi).ok_or_else(|| {
        here(format!(
            "bufferView {vi} does not exist ({} buffer views)",
            root.buffer_views.len()
        ))
    })?;
    let stride = match &view.byte_stride {
        Some(s) if s.0 < elem => {
            return Err(here(format!(
                "bufferViews[{vi}].byteStride {} is smaller than an element ({elem} bytes)",
                s.0
            )));
        }
        Some(s) => s.0 as u64,
        None => elem as u64,
    };
    let count = a.count.0;
    let acc_offset = a.byte_offset.map_or(0, |o| o.0);
    let view_offset = view.byte_offset.map_or(0, |o| o.0);
    let view_length = view.byte_length.0;
    // The last element ends at acc_offset + (count - 1) * stride + elem within the view.
    let end = match count {
        0 => Some(acc_offset),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(acc_offset))
            .and_then(|x| x.checked_add(elem as u64)),
    };
    match end {
        Some(end) if end <= view_length => {}
        _ => {
            return Err(here(format!(
                "{count} elements of {elem} bytes (stride {stride}) from byteOffset \
                 {acc_offset} do not fit in bufferViews[{vi}] ({view_length} bytes)"
            )));
        }
    }
    let bi = view.buffer.value();
    let data_len = buffers.get(bi)?.len() as u64;
    match view_offset.checked_add(view_length) {
        Some(view_end) if view_end <= data_len => {}
        _ => {
            return Err(err(
                file,
                format!(
                    "bufferViews[{vi}] (bytes {view_offset}..+{view_length}) lies outside \
                     buffers[{bi}] ({data_len} bytes)"
                ),
            ));
        }
    }
    // All of it fits in a buffer held in memory, so it fits in usize.
    Ok(Layout::InBuffer {
        buffer: bi,
        start: (view_offset + acc_offset) as usize,
        stride: stride as usize,
    })
}

/// The elements' bytes, `elem` bytes each (an empty slice for each element of a view-less
/// accessor, which the caller reads as zeros).
fn elements<'b>(
    layout: &Layout,
    data: &'b [u8],
    count: usize,
    elem: usize,
) -> impl Iterator<Item = &'b [u8]> + 'b {
    let (start, stride, zeros) = match *layout {
        Layout::Zeros => (0, 0, true),
        Layout::InBuffer { start, stride, .. } => (start, stride, false),
    };
    (0..count).map(move |k| {
        if zeros {
            &[][..]
        } else {
            let s = start + k * stride;
            data.get(s..s + elem).unwrap_or(&[])
        }
    })
}

fn f32_at(b: &[u8], at: usize) -> f32 {
    match b.get(at..at + 4) {
        Some(x) => f32::from_le_bytes([x[0], x[1], x[2], x[3]]),
        None => 0.0,
    }
}

/// The accessor's element count, bounded by what a buffer can hold (a view-less accessor
/// has no bytes to bound it).
fn element_count(a: &json::Accessor, index: usize, file: &str, role: &str) -> Result<usize> {
    // Elements in a buffer are bounded by its bytes; a view-less accessor (all zeros) is not.
    const MAX_ELEMENTS: u64 = 1 << 28;
    const MAX_ZEROS: u64 = 1 << 20;
    if a.buffer_view.is_none() && a.count.0 > MAX_ZEROS {
        return Err(err(
            file,
            format!(
                "accessors[{index}] ({role}): {} zeros without a bufferView is more than \
                 penumbra reads ({MAX_ZEROS})",
                a.count.0
            ),
        ));
    }
    if a.count.0 > MAX_ELEMENTS {
        return Err(err(
            file,
            format!(
                "accessors[{index}] ({role}): count {} is more than penumbra reads ({MAX_ELEMENTS})",
                a.count.0
            ),
        ));
    }
    Ok(a.count.0 as usize)
}

/// Reads a POSITION accessor: VEC3 of FLOAT, every coordinate finite.
pub(super) fn read_positions(
    root: &json::Root,
    buffers: &mut Buffers,
    index: usize,
    file: &str,
) -> Result<Vec<DVec3>> {
    let role = "POSITION";
    let (a, c, t) = accessor(root, index, file, role)?;
    if c != ComponentType::F32 || t != Type::Vec3 || a.normalized {
        return Err(err(
            file,
            format!(
                "accessors[{index}] ({role}): {} of {}{} is not supported (VEC3 of FLOAT only; \
                 quantized positions are not read)",
                type_name(t),
                component_name(c),
                if a.normalized { ", normalized" } else { "" }
            ),
        ));
    }
    let count = element_count(a, index, file, role)?;
    let layout = layout(root, buffers, index, a, 12, file, role)?;
    let data: &[u8] = match &layout {
        Layout::Zeros => &[],
        Layout::InBuffer { buffer, .. } => buffers.get(*buffer)?,
    };
    let mut out = Vec::with_capacity(count);
    for (k, b) in elements(&layout, data, count, 12).enumerate() {
        let p = DVec3::new(
            f32_at(b, 0) as f64,
            f32_at(b, 4) as f64,
            f32_at(b, 8) as f64,
        );
        if !p.is_finite() {
            return Err(err(
                file,
                format!("accessors[{index}] ({role}) element {k}: non-finite position {p}"),
            ));
        }
        out.push(p);
    }
    Ok(out)
}

/// Reads an index accessor: SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT, each
/// index below `vertices`.
pub(super) fn read_indices(
    root: &json::Root,
    buffers: &mut Buffers,
    index: usize,
    vertices: usize,
    file: &str,
) -> Result<Vec<u32>> {
    let role = "indices";
    let (a, c, t) = accessor(root, index, file, role)?;
    if t != Type::Scalar
        || !matches!(
            c,
            ComponentType::U8 | ComponentType::U16 | ComponentType::U32
        )
    {
        return Err(err(
            file,
            format!(
                "accessors[{index}] ({role}): {} of {} is not an index type (SCALAR of \
                 UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT)",
                type_name(t),
                component_name(c)
            ),
        ));
    }
    let size = component_size(c);
    let count = element_count(a, index, file, role)?;
    let layout = layout(root, buffers, index, a, size, file, role)?;
    let data: &[u8] = match &layout {
        Layout::Zeros => &[],
        Layout::InBuffer { buffer, .. } => buffers.get(*buffer)?,
    };
    let mut out = Vec::with_capacity(count);
    for (k, b) in elements(&layout, data, count, size).enumerate() {
        let i = match (b, size) {
            ([x], 1) => *x as u32,
            ([x, y], 2) => u16::from_le_bytes([*x, *y]) as u32,
            ([x, y, z, w], 4) => u32::from_le_bytes([*x, *y, *z, *w]),
            _ => 0,
        };
        if i as usize >= vertices {
            return Err(err(
                file,
                format!(
                    "accessors[{index}] ({role}) element {k}: vertex index {i} is out of range \
                     ({vertices} vertices)"
                ),
            ));
        }
        out.push(i);
    }
    Ok(out)
}
