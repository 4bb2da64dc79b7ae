//! The checks made on a glTF file before and after the `gltf` crate
//! imports it, where that crate would panic, allocate unbounded memory or
//! report an error that names nothing.

use std::path::Path;

use super::bad;
use crate::error::{Error, Result};
/// When a glTF file reads but a buffer or image it refers to does not, the
/// error names that file and the glTF file that refers to it (the glTF
/// crate's I/O error names neither).
pub(super) fn missing_part(path: &Path) -> Option<Error> {
    let doc = gltf::Gltf::open(path).ok()?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let buffers = doc.buffers().filter_map(|b| match b.source() {
        gltf::buffer::Source::Uri(u) => Some((format!("buffer {}", b.index()), u.to_string())),
        gltf::buffer::Source::Bin => None,
    });
    let images = doc.images().filter_map(|i| match i.source() {
        gltf::image::Source::Uri { uri, .. } => {
            Some((format!("image {}", i.index()), uri.to_string()))
        }
        gltf::image::Source::View { .. } => None,
    });
    for (element, uri) in buffers.chain(images) {
        if uri.starts_with("data:") {
            continue;
        }
        let file = dir.join(&uri);
        if let Err(source) = std::fs::metadata(&file) {
            return Some(bad(
                path,
                element,
                format!(
                    "cannot read {} (referred to by this file): {source}",
                    file.display()
                ),
            ));
        }
    }
    None
}

/// Checks an accessor before the glTF crate's reader casts its bytes: its
/// element type must be one of `dims` with a component type in `types`,
/// and a sparse accessor must have at least one entry (the crate's reader
/// panics on a mismatch, or indexes before the buffer on an empty sparse
/// set). `what` names the accessor's role in the error.
fn check_accessor(
    path: &Path,
    what: &str,
    acc: Option<gltf::Accessor>,
    dims: gltf::accessor::Dimensions,
    types: &[gltf::accessor::DataType],
) -> Result<()> {
    let Some(acc) = acc else {
        return Ok(());
    };
    let element = format!("accessor {}", acc.index());
    if acc.dimensions() != dims || !types.contains(&acc.data_type()) {
        return Err(bad(
            path,
            element,
            format!(
                "used as {what}, it must hold {} of {}, not {} of {}",
                dims_name(dims),
                types
                    .iter()
                    .map(|t| type_name(*t))
                    .collect::<Vec<_>>()
                    .join(" or "),
                dims_name(acc.dimensions()),
                type_name(acc.data_type())
            ),
        ));
    }
    if acc.sparse().is_some_and(|sp| sp.count() == 0) {
        return Err(bad(path, element, "a sparse accessor with no entries"));
    }
    Ok(())
}

/// The glTF name of an element type.
fn dims_name(d: gltf::accessor::Dimensions) -> &'static str {
    use gltf::accessor::Dimensions as D;
    match d {
        D::Scalar => "SCALAR",
        D::Vec2 => "VEC2",
        D::Vec3 => "VEC3",
        D::Vec4 => "VEC4",
        D::Mat2 => "MAT2",
        D::Mat3 => "MAT3",
        D::Mat4 => "MAT4",
    }
}

/// A component type in words.
fn type_name(t: gltf::accessor::DataType) -> &'static str {
    use gltf::accessor::DataType as T;
    match t {
        T::I8 => "signed bytes",
        T::U8 => "unsigned bytes",
        T::I16 => "signed shorts",
        T::U16 => "unsigned shorts",
        T::U32 => "unsigned ints",
        T::F32 => "floats",
    }
}

/// Checks every accessor [`super::load_gltf`] reads (see [`check_accessor`]).
pub(super) fn check_accessors(path: &Path, doc: &gltf::Document) -> Result<()> {
    use gltf::Semantic;
    use gltf::accessor::{DataType as T, Dimensions as D};
    for skin in doc.skins() {
        let ibm = skin.inverse_bind_matrices();
        check_accessor(path, "inverse bind matrices", ibm, D::Mat4, &[T::F32])?;
    }
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            let pos = prim.get(&Semantic::Positions);
            check_accessor(path, "POSITION", pos, D::Vec3, &[T::F32])?;
            let joints = prim.get(&Semantic::Joints(0));
            check_accessor(path, "JOINTS_0", joints, D::Vec4, &[T::U8, T::U16])?;
            let weights = prim.get(&Semantic::Weights(0));
            check_accessor(
                path,
                "WEIGHTS_0",
                weights,
                D::Vec4,
                &[T::F32, T::U8, T::U16],
            )?;
            let ints = [T::U8, T::U16, T::U32];
            check_accessor(path, "indices", prim.indices(), D::Scalar, &ints)?;
        }
    }
    for anim in doc.animations() {
        for ch in anim.channels() {
            let s = ch.sampler();
            check_accessor(
                path,
                "keyframe times",
                Some(s.input()),
                D::Scalar,
                &[T::F32],
            )?;
            use gltf::animation::Property as P;
            let (dims, types): (D, &[T]) = match ch.target().property() {
                P::Translation | P::Scale => (D::Vec3, &[T::F32]),
                P::Rotation => (D::Vec4, &[T::F32, T::I8, T::U8, T::I16, T::U16]),
                P::MorphTargetWeights => (D::Scalar, &[T::F32, T::I8, T::U8, T::I16, T::U16]),
            };
            check_accessor(path, "keyframe values", Some(s.output()), dims, types)?;
        }
    }
    Ok(())
}

/// Checks a GLB header's length against the file size, and the accessor
/// indices of mesh primitives on the document read
/// without the glTF crate's validation, whose hook for primitives indexes
/// the accessor list with the POSITION index before checking it (a panic on
/// a file naming a missing accessor). A file that does not parse passes:
/// the import reports it.
pub(super) fn check_before_import(path: &Path) -> Result<()> {
    let Ok(bytes) = std::fs::read(path) else {
        return Ok(());
    };
    check_length(path, &bytes)?;
    let Ok(g) = gltf::Gltf::from_slice_without_validation(&bytes) else {
        return Ok(());
    };
    let root = g.document.as_json();
    check_primitive_indices(path, root)?;
    check_animation_indices(path, root)
}

/// Refuses a file too short for a magic, and a GLB header declaring more
/// bytes than the file holds or fewer than the header itself.
fn check_length(path: &Path, bytes: &[u8]) -> Result<()> {
    // The glTF crate reads a 4-byte magic first, and a shorter file fails
    // with an I/O message that names nothing.
    if bytes.len() < 4 {
        return Err(bad(
            path,
            "file",
            format!(
                "{} bytes: too short for glTF (a JSON document with an asset, or a GLB file)",
                bytes.len()
            ),
        ));
    }
    // The memory bound: the glTF crate allocates the length a GLB header
    // declares before reading, so a header claiming more than the file
    // holds is refused here; so is one claiming less than the header itself,
    // which the crate subtracts the header's size from unchecked.
    if let Some(h) = bytes.first_chunk::<12>()
        && h.starts_with(b"glTF")
    {
        let declared = u32::from_le_bytes([h[8], h[9], h[10], h[11]]);
        if declared < 12 {
            return Err(bad(
                path,
                "GLB header",
                format!("declares {declared} bytes, less than its own 12"),
            ));
        }
        if declared as usize > bytes.len() {
            return Err(bad(
                path,
                "GLB header",
                format!(
                    "declares {declared} bytes, but the file has {}",
                    bytes.len()
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses a mesh primitive naming an accessor the file does not have.
fn check_primitive_indices(path: &Path, root: &gltf::json::Root) -> Result<()> {
    let n = root.accessors.len();
    for (i, mesh) in root.meshes.iter().enumerate() {
        for (j, prim) in mesh.primitives.iter().enumerate() {
            let refs = prim.attributes.values().map(|a| a.value());
            let indices = prim.indices.iter().map(|a| a.value());
            if let Some(a) = refs.chain(indices).find(|&a| a >= n) {
                return Err(bad(
                    path,
                    format!("mesh {i} primitive {j}"),
                    format!("refers to accessor {a}, but the file has {n} accessors"),
                ));
            }
        }
    }
    Ok(())
}

/// Refuses animation channels without a valid target path or naming a
/// missing node or sampler, and samplers naming a missing accessor: the
/// glTF crate unwraps the path and indexes the others unchecked.
fn check_animation_indices(path: &Path, root: &gltf::json::Root) -> Result<()> {
    let n = root.accessors.len();
    let nodes = root.nodes.len();
    for (i, anim) in root.animations.iter().enumerate() {
        let samplers = anim.samplers.len();
        for (j, ch) in anim.channels.iter().enumerate() {
            let what = format!("animation {i} channel {j}");
            if let Some(p) = channel_problem(ch, nodes, samplers) {
                return Err(bad(path, what, p));
            }
        }
        for (j, s) in anim.samplers.iter().enumerate() {
            if let Some(a) = [s.input.value(), s.output.value()]
                .into_iter()
                .find(|&a| a >= n)
            {
                return Err(bad(
                    path,
                    format!("animation {i} sampler {j}"),
                    format!("refers to accessor {a}, but the file has {n} accessors"),
                ));
            }
        }
    }
    Ok(())
}

/// What is wrong with an animation channel's target path, node or sampler.
fn channel_problem(
    ch: &gltf::json::animation::Channel,
    nodes: usize,
    samplers: usize,
) -> Option<String> {
    if matches!(ch.target.path, gltf::json::validation::Checked::Invalid) {
        Some("has no valid target path (translation, rotation, scale or weights)".into())
    } else if ch.target.node.value() >= nodes {
        Some(format!(
            "targets node {}, but the file has {nodes} nodes",
            ch.target.node.value()
        ))
    } else if ch.sampler.value() >= samplers {
        Some(format!(
            "uses sampler {}, but the animation has {samplers} samplers",
            ch.sampler.value()
        ))
    } else {
        None
    }
}
