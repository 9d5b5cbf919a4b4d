//! `KHR_draco_mesh_compression`: a primitive whose geometry is a Draco bitstream.
//!
//! The primitive's accessors keep their count, type and component type but have no
//! bufferView; the extension names the bufferView of the bitstream and, for each attribute,
//! the Draco attribute's unique id. Decoding yields per-point values and triangles; each is
//! written back in its accessor's own component type, so the primitive is then read by the
//! same code as an uncompressed one (skinning, morph targets, normalized integers and
//! KHR_mesh_quantization included).

use std::collections::HashMap;

use ::gltf::json;
use draco_core::{DataType, DecodeLimits, DecoderBuffer, Mesh, MeshDecoder};
use json::accessor::Type;
use serde_json::Value;

use super::accessor::{Comp, Reader};
use crate::scene::error::{LoadError, LoadErrorKind};

pub(crate) const EXTENSION: &str = "KHR_draco_mesh_compression";

fn invalid(msg: String) -> LoadError {
    LoadError::new(LoadErrorKind::Invalid, msg)
}

/// Components per element of an accessor type (matrices are not vertex attributes).
fn width(ty: Type) -> Option<usize> {
    match ty {
        Type::Scalar => Some(1),
        Type::Vec2 => Some(2),
        Type::Vec3 => Some(3),
        Type::Vec4 => Some(4),
        _ => None,
    }
}

/// The largest value of an integer component type (its normalization divisor).
fn int_max(c: Comp) -> f32 {
    match c {
        Comp::I8 => 127.0,
        Comp::U8 => 255.0,
        Comp::I16 => 32767.0,
        Comp::U16 => 65535.0,
        Comp::U32 => u32::MAX as f32,
        Comp::F32 => 1.0,
    }
}

fn draco_int_max(t: DataType) -> Option<f32> {
    match t {
        DataType::Int8 => Some(127.0),
        DataType::Uint8 => Some(255.0),
        DataType::Int16 => Some(32767.0),
        DataType::Uint16 => Some(65535.0),
        DataType::Int32 => Some(i32::MAX as f32),
        DataType::Uint32 => Some(u32::MAX as f32),
        _ => None,
    }
}

/// Appends `v` to `out` as one component of type `c`: floats as they are, integers rounded
/// and clamped to the type's range.
fn push(out: &mut Vec<u8>, c: Comp, v: f32) {
    let r = |lo: f32, hi: f32| v.round().clamp(lo, hi);
    match c {
        Comp::F32 => out.extend_from_slice(&v.to_le_bytes()),
        Comp::I8 => out.push(r(-128.0, 127.0) as i8 as u8),
        Comp::U8 => out.push(r(0.0, 255.0) as u8),
        Comp::I16 => out.extend_from_slice(&(r(-32768.0, 32767.0) as i16).to_le_bytes()),
        Comp::U16 => out.extend_from_slice(&(r(0.0, 65535.0) as u16).to_le_bytes()),
        Comp::U32 => out.extend_from_slice(&(r(0.0, u32::MAX as f32) as u32).to_le_bytes()),
    }
}

/// Decodes the primitive's Draco stream if it has one: accessor index -> the accessor's
/// elements, packed in its component type (what [`Reader::decoded`] holds). `None` for an
/// uncompressed primitive. `who` names the primitive in messages.
pub(crate) fn decode(
    reader: &Reader,
    raw_prim: &Value,
    prim: &json::mesh::Primitive,
    who: &str,
    limits: (usize, usize),
) -> Result<Option<HashMap<usize, Vec<u8>>>, LoadError> {
    let Some(ext) = raw_prim.get("extensions").and_then(|e| e.get(EXTENSION)) else {
        return Ok(None);
    };
    let tag = format!("{who}: {EXTENSION}");
    let vi = ext
        .get("bufferView")
        .and_then(Value::as_u64)
        .ok_or_else(|| invalid(format!("{tag}: bufferView is missing or not an index")))?;
    let attributes = ext
        .get("attributes")
        .and_then(Value::as_object)
        .ok_or_else(|| invalid(format!("{tag}: attributes is missing or not an object")))?;
    let (bytes, _) = reader.view(usize::try_from(vi).unwrap_or(usize::MAX), &tag)?;

    let (max_points, max_faces) = limits;
    let mut buffer = DecoderBuffer::new(bytes).with_limits(
        DecodeLimits::default()
            .with_max_points(max_points as u64)
            .with_max_faces(max_faces as u64),
    );
    let mut mesh = Mesh::new();
    MeshDecoder::new()
        .decode(&mut buffer, &mut mesh)
        .map_err(|e| invalid(format!("{tag}: bufferView {vi} does not decode: {e}")))?;
    let points = mesh.num_points();

    let raw_attrs = raw_prim.get("attributes").and_then(Value::as_object);
    let mut out = HashMap::new();
    for (semantic, id) in attributes {
        let id = id
            .as_u64()
            .and_then(|i| u32::try_from(i).ok())
            .ok_or_else(|| invalid(format!("{tag}: attribute {semantic} has no valid id")))?;
        let Some(ai) = raw_attrs
            .and_then(|a| a.get(semantic))
            .and_then(Value::as_u64)
            .and_then(|a| usize::try_from(a).ok())
        else {
            // Compressed data the primitive does not use.
            continue;
        };
        let what = format!("{semantic} of {who}");
        let (acc, comp, ty) = reader.describe(ai, &what)?;
        let n = width(ty).ok_or_else(|| {
            invalid(format!(
                "accessor {ai} ({what}): type {} cannot be Draco-compressed",
                super::accessor::type_name(ty)
            ))
        })?;
        if acc.count.0 != points as u64 {
            return Err(invalid(format!(
                "accessor {ai} ({what}): count {} differs from the {points} points the Draco stream decodes to",
                acc.count.0
            )));
        }
        let att = mesh.attribute_by_unique_id(id).ok_or_else(|| {
            invalid(format!(
                "{tag}: attribute {semantic} names Draco attribute {id}, which the stream does not have"
            ))
        })?;
        if usize::from(att.num_components()) < n {
            return Err(invalid(format!(
                "{tag}: Draco attribute {id} ({semantic}) has {} components where accessor {ai} needs {n}",
                att.num_components()
            )));
        }
        // Draco hands values as stored (integers unscaled); scale where the stored and the
        // accessor's normalizations differ.
        let from_norm = match draco_int_max(att.data_type()) {
            Some(m) if att.normalized() => 1.0 / m,
            _ => 1.0,
        };
        let to_norm = if acc.normalized { int_max(comp) } else { 1.0 };
        let scale = from_norm * to_norm;
        let values = att.read_f32s(points, n);
        let mut bytes = Vec::with_capacity(values.len() * comp.size());
        for v in values {
            push(&mut bytes, comp, v * scale);
        }
        out.insert(ai, bytes);
    }

    let ai = prim.indices.map(|i| i.value()).ok_or_else(|| {
        invalid(format!(
            "{tag}: the primitive has no indices accessor for the decoded triangles"
        ))
    })?;
    let what = format!("indices of {who}");
    let (acc, comp, _) = reader.describe(ai, &what)?;
    let faces = mesh.faces();
    if acc.count.0 != 3 * faces.len() as u64 {
        return Err(invalid(format!(
            "accessor {ai} ({what}): count {} differs from the {} indices of the {} decoded triangles",
            acc.count.0,
            3 * faces.len(),
            faces.len()
        )));
    }
    let cap = int_max(comp);
    let mut bytes = Vec::with_capacity(3 * faces.len() * comp.size());
    for f in faces {
        for p in f {
            if p.0 as f32 > cap || p.0 as usize >= points {
                return Err(invalid(format!(
                    "accessor {ai} ({what}): decoded index {} does not fit its component type or the {points} points",
                    p.0
                )));
            }
            match comp {
                Comp::U8 => bytes.push(p.0 as u8),
                Comp::U16 => bytes.extend_from_slice(&(p.0 as u16).to_le_bytes()),
                _ => bytes.extend_from_slice(&p.0.to_le_bytes()),
            }
        }
    }
    out.insert(ai, bytes);
    Ok(Some(out))
}
