//! The accessor reader: every component type, normalized integers, `byteStride`, matrix
//! column padding and sparse substitution, with every offset and length checked.

use ::gltf::json;
use json::accessor::{ComponentType, Type};
use json::validation::Checked;

use crate::scene::error::{LoadError, LoadErrorKind};
use std::collections::HashMap;

/// Accessors without a bufferView (all zeros, perhaps sparse) may hold at most this many
/// elements, or as many as the file has binary bytes, whichever is more.
const MIN_ZERO_ACCESSOR_CAP: usize = 1 << 16;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Comp {
    I8,
    U8,
    I16,
    U16,
    U32,
    F32,
}

impl Comp {
    fn from_json(c: ComponentType) -> Comp {
        match c {
            ComponentType::I8 => Comp::I8,
            ComponentType::U8 => Comp::U8,
            ComponentType::I16 => Comp::I16,
            ComponentType::U16 => Comp::U16,
            ComponentType::U32 => Comp::U32,
            ComponentType::F32 => Comp::F32,
        }
    }

    pub(crate) fn size(self) -> usize {
        match self {
            Comp::I8 | Comp::U8 => 1,
            Comp::I16 | Comp::U16 => 2,
            Comp::U32 | Comp::F32 => 4,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Comp::I8 => "BYTE",
            Comp::U8 => "UNSIGNED_BYTE",
            Comp::I16 => "SHORT",
            Comp::U16 => "UNSIGNED_SHORT",
            Comp::U32 => "UNSIGNED_INT",
            Comp::F32 => "FLOAT",
        }
    }
}

/// Reads one component as `f32`, applying glTF's normalization rules when `normalized`.
/// `b` holds at least `c.size()` bytes.
pub(crate) fn decode_f32(b: &[u8], c: Comp, normalized: bool) -> f32 {
    match c {
        Comp::I8 => {
            let v = b[0] as i8 as f32;
            if normalized { (v / 127.0).max(-1.0) } else { v }
        }
        Comp::U8 => {
            let v = b[0] as f32;
            if normalized { v / 255.0 } else { v }
        }
        Comp::I16 => {
            let v = i16::from_le_bytes([b[0], b[1]]) as f32;
            if normalized {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        Comp::U16 => {
            let v = u16::from_le_bytes([b[0], b[1]]) as f32;
            if normalized { v / 65535.0 } else { v }
        }
        Comp::U32 => {
            let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            if normalized {
                (v as f64 / u32::MAX as f64) as f32
            } else {
                v as f32
            }
        }
        Comp::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

/// Reads one unsigned integer component (indices). Callers check the type first.
pub(crate) fn decode_u32(b: &[u8], c: Comp) -> u32 {
    match c {
        Comp::U8 => b[0] as u32,
        Comp::U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

/// What a read produced: `count` elements, their components flattened.
#[derive(Debug)]
pub(crate) struct Values<T> {
    pub data: Vec<T>,
    pub count: usize,
}

impl Values<f32> {
    pub(crate) fn vec3(&self) -> Vec<glam::Vec3> {
        self.data
            .chunks_exact(3)
            .map(|c| glam::Vec3::new(c[0], c[1], c[2]))
            .collect()
    }
    pub(crate) fn vec2(&self) -> Vec<glam::Vec2> {
        self.data
            .chunks_exact(2)
            .map(|c| glam::Vec2::new(c[0], c[1]))
            .collect()
    }
}

/// Element layout: number of components, element size in bytes, and byte offset of each
/// component inside the element (matrices pad each column to 4 bytes).
fn layout(ty: Type, comp: Comp) -> (usize, usize, Vec<usize>) {
    let (cols, rows) = match ty {
        Type::Scalar => (1, 1),
        Type::Vec2 => (1, 2),
        Type::Vec3 => (1, 3),
        Type::Vec4 => (1, 4),
        Type::Mat2 => (2, 2),
        Type::Mat3 => (3, 3),
        Type::Mat4 => (4, 4),
    };
    let cs = comp.size();
    let col_bytes = if cols > 1 {
        (rows * cs).div_ceil(4) * 4
    } else {
        rows * cs
    };
    let mut offsets = Vec::with_capacity(cols * rows);
    for c in 0..cols {
        for r in 0..rows {
            offsets.push(c * col_bytes + r * cs);
        }
    }
    (cols * rows, cols * col_bytes, offsets)
}

pub(crate) fn type_name(ty: Type) -> &'static str {
    match ty {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

/// Reads accessors out of resolved buffers.
pub(crate) struct Reader<'a> {
    pub root: &'a json::Root,
    /// Buffer contents, each exactly `byteLength` long.
    pub buffers: &'a [&'a [u8]],
    /// BufferViews decoded from a compressed stream (meshopt): view index -> its bytes, read
    /// in place of the view's buffer range.
    pub views: &'a HashMap<usize, Vec<u8>>,
    /// Accessors whose data was decoded from a compressed stream (a Draco primitive's):
    /// accessor index -> tightly packed elements in the accessor's own component type, read
    /// in place of a bufferView.
    pub decoded: HashMap<usize, Vec<u8>>,
}

fn invalid(msg: String) -> LoadError {
    LoadError::new(LoadErrorKind::Invalid, msg)
}

impl<'a> Reader<'a> {
    fn zero_cap(&self) -> usize {
        let total: usize = self.buffers.iter().map(|b| b.len()).sum();
        total.max(MIN_ZERO_ACCESSOR_CAP)
    }

    /// The bytes of bufferView `vi` and its stride.
    pub(crate) fn view(
        &self,
        vi: usize,
        who: &str,
    ) -> Result<(&'a [u8], Option<usize>), LoadError> {
        let view = self.root.buffer_views.get(vi).ok_or_else(|| {
            invalid(format!(
                "{who}: bufferView {vi} does not exist (the file has {})",
                self.root.buffer_views.len()
            ))
        })?;
        let stride = match view.byte_stride {
            Some(s) if s.0 == 0 => None,
            Some(s) => Some(s.0),
            None => None,
        };
        if let Some(bytes) = self.views.get(&vi) {
            return Ok((bytes, stride));
        }
        let bi = view.buffer.value();
        let buf = *self.buffers.get(bi).ok_or_else(|| {
            invalid(format!(
                "bufferView {vi}: buffer {bi} does not exist (the file has {})",
                self.buffers.len()
            ))
        })?;
        let off = view.byte_offset.map(|o| o.0).unwrap_or(0);
        let len = view.byte_length.0;
        let end = off.checked_add(len);
        match end {
            Some(end) if end <= buf.len() as u64 => Ok((&buf[off as usize..end as usize], stride)),
            _ => Err(invalid(format!(
                "bufferView {vi}: byteOffset {off} + byteLength {len} exceeds buffer {bi} of {} bytes",
                buf.len()
            ))),
        }
    }

    /// The accessor's JSON, component type and element type.
    pub(crate) fn describe(
        &self,
        ai: usize,
        what: &str,
    ) -> Result<(&'a json::Accessor, Comp, Type), LoadError> {
        let acc = self.root.accessors.get(ai).ok_or_else(|| {
            invalid(format!(
                "accessor {ai} ({what}) does not exist (the file has {})",
                self.root.accessors.len()
            ))
        })?;
        let comp = match &acc.component_type {
            Checked::Valid(c) => Comp::from_json(c.0),
            Checked::Invalid => {
                return Err(invalid(format!(
                    "accessor {ai} ({what}): invalid componentType"
                )));
            }
        };
        let ty = match &acc.type_ {
            Checked::Valid(t) => *t,
            Checked::Invalid => {
                return Err(invalid(format!("accessor {ai} ({what}): invalid type")));
            }
        };
        Ok((acc, comp, ty))
    }

    /// Reads accessor `ai` (described as `what` in messages), converting each component
    /// with `dec(bytes, component type, normalized)`.
    pub(crate) fn read<T: Copy + Default>(
        &self,
        ai: usize,
        what: &str,
        dec: &dyn Fn(&[u8], Comp, bool) -> T,
    ) -> Result<Values<T>, LoadError> {
        let (acc, comp, ty) = self.describe(ai, what)?;
        let tag = || format!("accessor {ai} ({what})");
        let (ncomp, elem, offsets) = layout(ty, comp);
        let count = usize::try_from(acc.count.0)
            .map_err(|_| invalid(format!("{}: count {} is too large", tag(), acc.count.0)))?;
        let total = count
            .checked_mul(ncomp)
            .ok_or_else(|| invalid(format!("{}: count {count} is too large", tag())))?;
        let normalized = acc.normalized;
        let mut data: Vec<T>;
        let source = match (self.decoded.get(&ai), acc.buffer_view) {
            // Decoded elements are packed from the start; a byteOffset belongs to a view.
            (Some(bytes), _) => Some((bytes.as_slice(), elem, 0, "the decoded data".to_string())),
            (None, Some(vi)) => {
                let vi = vi.value();
                let (bytes, stride) = self.view(vi, &tag())?;
                let off = acc.byte_offset.map(|o| o.0).unwrap_or(0);
                Some((
                    bytes,
                    stride.unwrap_or(elem),
                    off,
                    format!("bufferView {vi}"),
                ))
            }
            (None, None) => None,
        };
        if let Some((bytes, stride, off, src)) = source {
            if stride < elem {
                return Err(invalid(format!(
                    "{}: {src} byteStride {stride} is smaller than the {elem}-byte element",
                    tag()
                )));
            }
            if count > 0 {
                let need = (count as u64 - 1)
                    .checked_mul(stride as u64)
                    .and_then(|v| v.checked_add(elem as u64))
                    .and_then(|v| v.checked_add(off));
                match need {
                    Some(n) if n <= bytes.len() as u64 => {}
                    _ => {
                        return Err(invalid(format!(
                            "{}: byteOffset+length {} exceeds {src} of {} bytes",
                            tag(),
                            need.map(|n| n.to_string())
                                .unwrap_or_else(|| "(overflow)".into()),
                            bytes.len()
                        )));
                    }
                }
            } else if off > bytes.len() as u64 {
                return Err(invalid(format!(
                    "{}: byteOffset {off} exceeds {src} of {} bytes",
                    tag(),
                    bytes.len()
                )));
            }
            // Bounded: count * stride <= bytes.len(), and stride >= 1.
            data = Vec::with_capacity(total);
            let off = off as usize;
            let cs = comp.size();
            for i in 0..count {
                let base = off + i * stride;
                for &o in &offsets {
                    let b = &bytes[base + o..base + o + cs];
                    data.push(dec(b, comp, normalized));
                }
            }
        } else {
            if acc.byte_offset.is_some_and(|o| o.0 != 0) {
                return Err(invalid(format!(
                    "{}: byteOffset without a bufferView",
                    tag()
                )));
            }
            let cap = self.zero_cap();
            if count > cap {
                return Err(LoadError::new(
                    LoadErrorKind::TooLarge,
                    format!(
                        "{}: count {count} without a bufferView exceeds the limit of {cap} elements",
                        tag()
                    ),
                ));
            }
            data = vec![T::default(); total];
        }
        if let Some(sparse) = &acc.sparse {
            self.apply_sparse(
                ai, what, sparse, comp, normalized, &offsets, elem, count, &mut data, dec,
            )?;
        }
        Ok(Values { data, count })
    }

    #[allow(clippy::too_many_arguments)]
    fn apply_sparse<T: Copy>(
        &self,
        ai: usize,
        what: &str,
        sparse: &json::accessor::sparse::Sparse,
        comp: Comp,
        normalized: bool,
        offsets: &[usize],
        elem: usize,
        count: usize,
        data: &mut [T],
        dec: &dyn Fn(&[u8], Comp, bool) -> T,
    ) -> Result<(), LoadError> {
        let tag = || format!("accessor {ai} ({what}) sparse");
        let n = usize::try_from(sparse.count.0).unwrap_or(usize::MAX);
        if n > count {
            return Err(invalid(format!(
                "{}: sparse count {} exceeds the accessor's count {count}",
                tag(),
                sparse.count.0
            )));
        }
        // Indices.
        let icomp = match &sparse.indices.component_type {
            Checked::Valid(c) => Comp::from_json(c.0),
            Checked::Invalid => {
                return Err(invalid(format!("{}: invalid indices componentType", tag())));
            }
        };
        if !matches!(icomp, Comp::U8 | Comp::U16 | Comp::U32) {
            return Err(invalid(format!(
                "{}: indices componentType {} is not an unsigned integer",
                tag(),
                icomp.name()
            )));
        }
        let ivi = sparse.indices.buffer_view.value();
        let (ibytes, _) = self.view(ivi, &tag())?;
        let ioff = sparse.indices.byte_offset.0;
        let ineed = (n as u64)
            .checked_mul(icomp.size() as u64)
            .and_then(|v| v.checked_add(ioff));
        if ineed.is_none_or(|v| v > ibytes.len() as u64) {
            return Err(invalid(format!(
                "{}: indices (byteOffset {ioff}, {n} x {} bytes) exceed bufferView {ivi} of {} bytes",
                tag(),
                icomp.size(),
                ibytes.len()
            )));
        }
        // Values.
        let vvi = sparse.values.buffer_view.value();
        let (vbytes, _) = self.view(vvi, &tag())?;
        let voff = sparse.values.byte_offset.0;
        let vneed = (n as u64)
            .checked_mul(elem as u64)
            .and_then(|v| v.checked_add(voff));
        if vneed.is_none_or(|v| v > vbytes.len() as u64) {
            return Err(invalid(format!(
                "{}: values (byteOffset {voff}, {n} x {elem} bytes) exceed bufferView {vvi} of {} bytes",
                tag(),
                vbytes.len()
            )));
        }
        let (ioff, voff) = (ioff as usize, voff as usize);
        let ncomp = offsets.len();
        let cs = comp.size();
        for k in 0..n {
            let ib = ioff + k * icomp.size();
            let target = decode_u32(&ibytes[ib..ib + icomp.size()], icomp) as usize;
            if target >= count {
                return Err(invalid(format!(
                    "{}: index {target} (entry {k}) is out of range for count {count}",
                    tag()
                )));
            }
            let vb = voff + k * elem;
            for (j, &o) in offsets.iter().enumerate() {
                data[target * ncomp + j] = dec(&vbytes[vb + o..vb + o + cs], comp, normalized);
            }
        }
        Ok(())
    }

    /// Reads a float attribute of type `ty` (any component type; normalized as flagged).
    pub(crate) fn read_f32(
        &self,
        ai: usize,
        what: &str,
        ty: Type,
    ) -> Result<Values<f32>, LoadError> {
        let (_, _, actual) = self.describe(ai, what)?;
        if actual != ty {
            return Err(invalid(format!(
                "accessor {ai} ({what}): type {} where {} is expected",
                type_name(actual),
                type_name(ty)
            )));
        }
        self.read(ai, what, &decode_f32)
    }

    /// Reads an index accessor (SCALAR, unsigned integer components).
    pub(crate) fn read_indices(&self, ai: usize, what: &str) -> Result<Vec<u32>, LoadError> {
        let (_, comp, ty) = self.describe(ai, what)?;
        if ty != Type::Scalar {
            return Err(invalid(format!(
                "accessor {ai} ({what}): type {} where SCALAR is expected",
                type_name(ty)
            )));
        }
        if !matches!(comp, Comp::U8 | Comp::U16 | Comp::U32) {
            return Err(invalid(format!(
                "accessor {ai} ({what}): componentType {} is not an unsigned integer",
                comp.name()
            )));
        }
        Ok(self.read(ai, what, &|b, c, _| decode_u32(b, c))?.data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn root(json: &str) -> json::Root {
        serde_json::from_str(json).unwrap()
    }

    fn doc(views: &str, accessors: &str, len: usize) -> json::Root {
        root(&format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{len}}}],"bufferViews":{views},"accessors":{accessors}}}"#
        ))
    }

    fn f32s(v: &[f32]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_le_bytes()).collect()
    }

    #[test]
    fn tight_and_strided_floats() {
        let buf = f32s(&[1., 2., 3., 9., 4., 5., 6., 9.]);
        let r = doc(
            r#"[{"buffer":0,"byteLength":32},{"buffer":0,"byteLength":32,"byteStride":16}]"#,
            r#"[{"bufferView":0,"componentType":5126,"count":2,"type":"VEC3"},
                {"bufferView":1,"componentType":5126,"count":2,"type":"VEC3"},
                {"bufferView":1,"byteOffset":4,"componentType":5126,"count":2,"type":"VEC3"}]"#,
            32,
        );
        let bufs = [&buf[..]];
        let rd = Reader {
            root: &r,
            buffers: &bufs,
            views: &HashMap::new(),
            decoded: HashMap::new(),
        };
        assert_eq!(
            rd.read_f32(0, "t", Type::Vec3).unwrap().data,
            [1., 2., 3., 9., 4., 5.]
        );
        assert_eq!(
            rd.read_f32(1, "t", Type::Vec3).unwrap().data,
            [1., 2., 3., 4., 5., 6.]
        );
        assert_eq!(
            rd.read_f32(2, "t", Type::Vec3).unwrap().data,
            [2., 3., 9., 5., 6., 9.]
        );
        // Wrong type is refused.
        let e = rd.read_f32(0, "t", Type::Vec2).unwrap_err();
        assert!(e.message.contains("VEC3 where VEC2"), "{e}");
    }

    #[test]
    fn normalized_integers() {
        let buf: Vec<u8> = vec![
            255, 0, 128, 0, // u8: 1, 0, 128/255, pad
            0x81, 0x7f, 0x80, 0, // i8: -127 -> -1, 127 -> 1, -128 -> -1 (clamped)
            0xff, 0xff, 0x00, 0x80, // u16 65535 -> 1 ; i16 -32768 -> -1
        ];
        let r = doc(
            r#"[{"buffer":0,"byteLength":12}]"#,
            r#"[{"bufferView":0,"componentType":5121,"normalized":true,"count":3,"type":"SCALAR"},
                {"bufferView":0,"byteOffset":4,"componentType":5120,"normalized":true,"count":3,"type":"SCALAR"},
                {"bufferView":0,"byteOffset":8,"componentType":5123,"normalized":true,"count":1,"type":"SCALAR"},
                {"bufferView":0,"byteOffset":10,"componentType":5122,"normalized":true,"count":1,"type":"SCALAR"},
                {"bufferView":0,"byteOffset":8,"componentType":5123,"count":1,"type":"SCALAR"}]"#,
            12,
        );
        let bufs = [&buf[..]];
        let rd = Reader {
            root: &r,
            buffers: &bufs,
            views: &HashMap::new(),
            decoded: HashMap::new(),
        };
        let s = Type::Scalar;
        assert_eq!(
            rd.read_f32(0, "a", s).unwrap().data,
            [1.0, 0.0, 128.0 / 255.0]
        );
        assert_eq!(rd.read_f32(1, "a", s).unwrap().data, [-1.0, 1.0, -1.0]);
        assert_eq!(rd.read_f32(2, "a", s).unwrap().data, [1.0]);
        assert_eq!(rd.read_f32(3, "a", s).unwrap().data, [-1.0]);
        assert_eq!(rd.read_f32(4, "a", s).unwrap().data, [65535.0]);
        // u8 indices
        assert_eq!(rd.read_indices(0, "i").unwrap(), [255, 0, 128]);
        // signed indices are refused
        assert!(rd.read_indices(1, "i").is_err());
    }

    #[test]
    fn byte_matrices_pad_columns() {
        // MAT2 of u8: each 2-byte column padded to 4 bytes.
        let buf: Vec<u8> = vec![1, 2, 0, 0, 3, 4, 0, 0];
        let r = doc(
            r#"[{"buffer":0,"byteLength":8}]"#,
            r#"[{"bufferView":0,"componentType":5121,"count":1,"type":"MAT2"}]"#,
            8,
        );
        let bufs = [&buf[..]];
        let rd = Reader {
            root: &r,
            buffers: &bufs,
            views: &HashMap::new(),
            decoded: HashMap::new(),
        };
        assert_eq!(rd.read(0, "m", &decode_f32).unwrap().data, [1., 2., 3., 4.]);
    }

    #[test]
    fn bounds_are_checked() {
        let buf = [0u8; 24];
        let r = doc(
            r#"[{"buffer":0,"byteLength":24},{"buffer":0,"byteOffset":16,"byteLength":16},
                {"buffer":0,"byteLength":24,"byteStride":8}]"#,
            r#"[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},
                {"bufferView":0,"byteOffset":4,"componentType":5126,"count":2,"type":"VEC3"},
                {"bufferView":1,"componentType":5126,"count":1,"type":"SCALAR"},
                {"bufferView":2,"componentType":5126,"count":2,"type":"VEC3"},
                {"bufferView":7,"componentType":5126,"count":1,"type":"SCALAR"},
                {"bufferView":0,"componentType":5126,"count":4294967295,"type":"MAT4"},
                {"componentType":5126,"count":99999999999,"type":"VEC3"}]"#,
            24,
        );
        let bufs = [&buf[..]];
        let rd = Reader {
            root: &r,
            buffers: &bufs,
            views: &HashMap::new(),
            decoded: HashMap::new(),
        };
        let e = rd
            .read_f32(0, "POSITION of mesh 0 primitive 1", Type::Vec3)
            .unwrap_err();
        assert_eq!(
            e.message,
            "accessor 0 (POSITION of mesh 0 primitive 1): byteOffset+length 36 exceeds bufferView 0 of 24 bytes"
        );
        assert!(
            rd.read_f32(1, "p", Type::Vec3)
                .unwrap_err()
                .message
                .contains("28 exceeds")
        );
        let e = rd.read_f32(2, "p", Type::Scalar).unwrap_err();
        assert!(e.message.contains("exceeds buffer 0 of 24 bytes"), "{e}");
        let e = rd.read_f32(3, "p", Type::Vec3).unwrap_err();
        assert!(e.message.contains("byteStride 8 is smaller"), "{e}");
        let e = rd.read_f32(4, "p", Type::Scalar).unwrap_err();
        assert!(e.message.contains("bufferView 7 does not exist"), "{e}");
        assert!(rd.read(5, "p", &decode_f32).is_err());
        let e = rd.read_f32(6, "p", Type::Vec3).unwrap_err();
        assert_eq!(e.kind, LoadErrorKind::TooLarge, "{e}");
        let e = rd.read_f32(9, "p", Type::Vec3).unwrap_err();
        assert!(e.message.contains("accessor 9 (p) does not exist"), "{e}");
    }

    #[test]
    fn sparse_substitution() {
        // base: 4 scalars 10, 11, 12, 13; sparse: indices [1, 3] (u16) values [20, 30]
        let mut buf = f32s(&[10., 11., 12., 13.]);
        buf.extend_from_slice(&[1, 0, 3, 0]);
        buf.extend_from_slice(&f32s(&[20., 30.]));
        let r = doc(
            r#"[{"buffer":0,"byteLength":16},{"buffer":0,"byteOffset":16,"byteLength":4},
                {"buffer":0,"byteOffset":20,"byteLength":8}]"#,
            r#"[{"bufferView":0,"componentType":5126,"count":4,"type":"SCALAR",
                 "sparse":{"count":2,"indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":2}}},
                {"componentType":5126,"count":4,"type":"SCALAR",
                 "sparse":{"count":2,"indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":2}}},
                {"componentType":5126,"count":3,"type":"SCALAR",
                 "sparse":{"count":2,"indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":2}}},
                {"componentType":5126,"count":4,"type":"SCALAR",
                 "sparse":{"count":3,"indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":2}}}]"#,
            28,
        );
        let bufs = [&buf[..]];
        let rd = Reader {
            root: &r,
            buffers: &bufs,
            views: &HashMap::new(),
            decoded: HashMap::new(),
        };
        let s = Type::Scalar;
        assert_eq!(rd.read_f32(0, "s", s).unwrap().data, [10., 20., 12., 30.]);
        assert_eq!(rd.read_f32(1, "s", s).unwrap().data, [0., 20., 0., 30.]);
        let e = rd.read_f32(2, "s", s).unwrap_err();
        assert!(
            e.message.contains("index 3 (entry 1) is out of range"),
            "{e}"
        );
        let e = rd.read_f32(3, "s", s).unwrap_err();
        assert!(
            e.message
                .contains("indices (byteOffset 0, 3 x 2 bytes) exceed"),
            "{e}"
        );
    }
}
