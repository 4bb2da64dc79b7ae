//! Writers for curvature-directed strokes ([`crate::spec::sdf_lines`]):
//! SVG (each stroke a filled variable-width outline, projected with a
//! camera) and PLY (the strips as a triangle mesh, vertices on the surface,
//! with their normals), for other tools.

use std::io::Write as _;
use std::path::Path;

use crate::error::Result;
use crate::render::Camera;
use crate::spec::sdf_lines::Stroke;

/// The SVG text: a `<path>` per stroke, the closed outline of its strip
/// (left side forward, right side back), in pixels of a `size` image seen
/// by `camera`. Strokes with a vertex behind the eye are left out. No
/// hidden-line removal: strokes on the far side are drawn too unless the
/// caller filters them (for example by the normal facing the eye).
pub fn svg_string(strokes: &[Stroke], camera: &Camera, size: [u32; 2], color: &str) -> String {
    let [w, h] = size;
    let vp = camera.view_proj(w as f32 / h.max(1) as f32);
    let px = |p: [f64; 3]| -> Option<[f32; 2]> {
        crate::spec::view::project_to_pixel(vp, p.map(|c| c as f32), w, h)
    };
    let mut doc = super::svg::SvgDocument::new(w, h);
    doc.background("white");
    for st in strokes {
        let left: Option<Vec<_>> = st.strip.iter().step_by(2).map(|&p| px(p)).collect();
        let right: Option<Vec<_>> = st.strip.iter().skip(1).step_by(2).map(|&p| px(p)).collect();
        let (Some(l), Some(r)) = (left, right) else {
            continue;
        };
        doc.outline(l.into_iter().chain(r.into_iter().rev()), color);
    }
    doc.finish()
}

/// Writes [`svg_string`] to `path`.
///
/// # Errors
///
/// [`Error::Write`] naming the file.
pub fn write_svg(path: &Path, strokes: &[Stroke], camera: &Camera, size: [u32; 2]) -> Result<()> {
    super::output::write_bytes_atomic(path, svg_string(strokes, camera, size, "#111").as_bytes())
}

/// Writes the strips as a binary little-endian PLY triangle mesh: vertices
/// `x y z nx ny nz width` (float32; two per traced point, on the surface),
/// faces as triangle-strip triangles.
///
/// # Errors
///
/// [`Error::Write`] naming the file.
pub fn write_ply(path: &Path, strokes: &[Stroke]) -> Result<()> {
    let mut verts: Vec<[f32; 7]> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    for st in strokes {
        let base = verts.len() as u32;
        for (j, pair) in st.strip.chunks_exact(2).enumerate() {
            let n = st.normals[j].map(|c| c as f32);
            let w = st.widths[j] as f32;
            for p in pair {
                verts.push([p[0] as f32, p[1] as f32, p[2] as f32, n[0], n[1], n[2], w]);
            }
        }
        let m = st.strip.len() as u32;
        for i in 0..m.saturating_sub(2) {
            let t = [base + i, base + i + 1, base + i + 2];
            // Alternate the winding so every triangle faces the same way.
            faces.push(if i % 2 == 0 { t } else { [t[1], t[0], t[2]] });
        }
    }
    let mut b: Vec<u8> = Vec::new();
    let _ = write!(
        b,
        "ply\nformat binary_little_endian 1.0\ncomment shapecue curvature-directed strokes\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\nproperty float width\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        verts.len(),
        faces.len()
    );
    for v in &verts {
        for c in v {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in &faces {
        b.push(3);
        for i in f {
            b.extend_from_slice(&i.to_le_bytes());
        }
    }
    super::output::write_bytes_atomic(path, &b)
}
