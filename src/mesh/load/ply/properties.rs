//! Property mapping: what the element reader of `ply-rs-bw` keeps of each
//! element (the positions of `vertex`, the index list of `face`, nothing of
//! the others).

use ply_rs_bw::ply::{Property, PropertyAccess, PropertyAccessResult};

/// Names accepted for the face index list.
pub(super) const FACE_LISTS: [&str; 2] = ["vertex_indices", "vertex_index"];

/// A vertex: x, y and z converted to f64, and its stored normal `nx ny nz`.
pub(super) struct Vertex(pub(super) [f64; 3], pub(super) [f32; 3]);

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex([0.0; 3], [0.0; 3])
    }
    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let (k, normal) = match name {
            "x" => (0, false),
            "y" => (1, false),
            "z" => (2, false),
            "nx" => (0, true),
            "ny" => (1, true),
            "nz" => (2, true),
            _ => return PropertyAccessResult::Ignored,
        };
        let v: f64 = match property {
            Property::Char(v) => v.into(),
            Property::UChar(v) => v.into(),
            Property::Short(v) => v.into(),
            Property::UShort(v) => v.into(),
            Property::Int(v) => v.into(),
            Property::UInt(v) => v.into(),
            Property::Float(v) => v.into(),
            Property::Double(v) => v,
            _ => return PropertyAccessResult::UnsupportedType,
        };
        if normal {
            self.1[k] = v as f32;
        } else {
            self.0[k] = v;
        }
        PropertyAccessResult::Set
    }
}

/// A face: only the index list is kept, widened to i64 so that negative
/// values can be reported.
pub(super) struct Face(pub(super) Vec<i64>);

impl PropertyAccess for Face {
    fn new() -> Self {
        Face(Vec::new())
    }
    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if !FACE_LISTS.contains(&name) {
            return PropertyAccessResult::Ignored;
        }
        self.0 = match property {
            Property::ListChar(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUChar(v) => v.into_iter().map(i64::from).collect(),
            Property::ListShort(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUShort(v) => v.into_iter().map(i64::from).collect(),
            Property::ListInt(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUInt(v) => v.into_iter().map(i64::from).collect(),
            _ => return PropertyAccessResult::UnsupportedType,
        };
        PropertyAccessResult::Set
    }
}

/// An element shapecue does not use: parsed (to advance the stream) and dropped.
pub(super) struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}
