//! Skinned meshes from glTF 2.0 (`.gltf`/`.glb`, via the `gltf` crate): the
//! rest mesh, up to four joint influences per vertex, the node hierarchy and
//! the animation clips, sampled to joint matrices for linear blend skinning
//! (`kernels/skinning.cl`, CPU twin `cpu::skinning`).
//!
//! Every skinned primitive of every mesh node is gathered into one mesh; the
//! joints of all skins are concatenated into one joint list. Weights are
//! normalized to sum 1 (a vertex with no weight keeps its rest position).
//! Animation sampling follows the glTF spec: STEP, LINEAR (slerp for
//! rotations) and CUBICSPLINE (Hermite), clamped outside the clip.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use glam::{Mat4, Quat, Vec3};
use std::path::Path;

/// A node's local transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trs {
    /// Translation.
    pub t: Vec3,
    /// Rotation.
    pub r: Quat,
    /// Scale.
    pub s: Vec3,
}

impl Trs {
    /// The matrix T·R·S.
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.s, self.r, self.t)
    }
}

/// Which property an animation channel drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Property {
    /// Translation (3 values).
    Translation,
    /// Rotation (quaternion x, y, z, w).
    Rotation,
    /// Scale (3 values).
    Scale,
}

/// Keyframe interpolation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interp {
    /// Hold the previous key.
    Step,
    /// Linear (slerp for rotations).
    Linear,
    /// Cubic Hermite with in/out tangents.
    CubicSpline,
}

/// One animated property of one node.
#[derive(Clone, Debug)]
pub struct Channel {
    /// The node.
    pub node: usize,
    /// The property.
    pub property: Property,
    /// Interpolation.
    pub interp: Interp,
    /// Key times (seconds, increasing).
    pub times: Vec<f32>,
    /// Key values, 3 or 4 floats each (×3 for cubic spline: in, value, out).
    pub values: Vec<[f32; 4]>,
}

/// An animation clip.
#[derive(Clone, Debug)]
pub struct Clip {
    /// Name (or `clip <index>`).
    pub name: String,
    /// Length in seconds.
    pub duration: f32,
    /// Channels.
    pub channels: Vec<Channel>,
}

/// A mesh with a skeleton and animations.
#[derive(Clone, Debug)]
pub struct SkinnedMesh {
    /// Rest positions and faces.
    pub rest: Mesh,
    /// Four joint indices per vertex (into `joint_nodes`).
    pub joints: Vec<[u32; 4]>,
    /// Four weights per vertex, summing to 1 (or all 0).
    pub weights: Vec<[f32; 4]>,
    /// Parent of each node (`None` for roots).
    pub parents: Vec<Option<usize>>,
    /// Rest transform of each node.
    pub rest_trs: Vec<Trs>,
    /// The node of each joint.
    pub joint_nodes: Vec<usize>,
    /// Inverse bind matrix of each joint.
    pub inverse_bind: Vec<Mat4>,
    /// The skinned mesh node each joint's skin instance belongs to: joint
    /// matrices are taken relative to that node (glTF: inverse(global(mesh
    /// node)) · global(joint) · inverse bind), so poses stay in mesh space.
    pub joint_mesh_node: Vec<usize>,
    /// Animation clips.
    pub clips: Vec<Clip>,
}

/// An input error naming the glTF file, the element and the problem.
fn bad(path: &Path, element: impl Into<String>, problem: impl Into<String>) -> Error {
    Error::input(path.display().to_string(), element, problem)
}

mod check;

use check::{check_accessors, check_before_import, missing_part};

/// Loads every skinned primitive of a glTF file.
pub fn load_gltf(path: &Path) -> Result<SkinnedMesh> {
    check_before_import(path)?;
    let (doc, buffers, _) = gltf::import(path).map_err(|e| match e {
        gltf::Error::Io(source) => missing_part(path).unwrap_or(Error::Io {
            path: path.to_path_buf(),
            source,
        }),
        other => bad(path, "file", other.to_string()),
    })?;
    check_accessors(path, &doc)?;
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut m = SkinnedMesh {
        rest: Mesh::default(),
        joints: Vec::new(),
        weights: Vec::new(),
        parents: parents(&nodes),
        rest_trs: nodes.iter().map(rest_trs).collect(),
        joint_nodes: Vec::new(),
        inverse_bind: Vec::new(),
        joint_mesh_node: Vec::new(),
        clips: Vec::new(),
    };
    for node in &nodes {
        let (Some(mesh), Some(skin)) = (node.mesh(), node.skin()) else {
            continue;
        };
        let joints = add_skin(&mut m, path, node, &skin, &buffers)?;
        for prim in mesh.primitives() {
            add_primitive(&mut m, path, &mesh, &prim, &joints, &buffers)?;
        }
    }
    if m.rest.faces.is_empty() {
        return Err(bad(path, "meshes", "no skinned triangle primitive"));
    }
    for anim in doc.animations() {
        let clip = read_clip(path, &anim, &buffers)?;
        m.clips.push(clip);
    }
    Ok(m)
}

/// The parent of each node (`None` for roots).
fn parents(nodes: &[gltf::Node]) -> Vec<Option<usize>> {
    let mut parents = vec![None; nodes.len()];
    for n in nodes {
        for c in n.children() {
            parents[c.index()] = Some(n.index());
        }
    }
    parents
}

/// A node's rest transform, its rotation normalized.
fn rest_trs(n: &gltf::Node) -> Trs {
    let (t, r, s) = n.transform().decomposed();
    Trs {
        t: Vec3::from(t),
        r: Quat::from_array(r).normalize(),
        s: Vec3::from(s),
    }
}

/// The joints of one skin instance in the joint list of a [`SkinnedMesh`].
struct Joints {
    /// The index of its first joint.
    base: u32,
    /// How many joints it has.
    count: usize,
    /// The glTF index of the skin, for messages.
    skin: usize,
}

/// Appends the joints of `node`'s skin (their nodes, inverse bind matrices
/// and mesh node) to `m`.
fn add_skin(
    m: &mut SkinnedMesh,
    path: &Path,
    node: &gltf::Node,
    skin: &gltf::Skin,
    buffers: &[gltf::buffer::Data],
) -> Result<Joints> {
    let joint_base = m.joint_nodes.len() as u32;
    let reader = skin.reader(|b| Some(&buffers[b.index()]));
    let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
    let ibm: Vec<Mat4> = match reader.read_inverse_bind_matrices() {
        Some(it) => it.map(|c| Mat4::from_cols_array_2d(&c)).collect(),
        None => vec![Mat4::IDENTITY; joints.len()],
    };
    if ibm.len() != joints.len() {
        return Err(bad(
            path,
            format!("skin {}", skin.index()),
            format!(
                "{} inverse bind matrices for {} joints",
                ibm.len(),
                joints.len()
            ),
        ));
    }
    m.joint_nodes.extend(&joints);
    m.inverse_bind.extend(ibm);
    m.joint_mesh_node
        .extend(std::iter::repeat_n(node.index(), joints.len()));
    Ok(Joints {
        base: joint_base,
        count: joints.len(),
        skin: skin.index(),
    })
}

/// Appends a skinned triangle primitive's faces and vertices to `m` (other
/// primitives are skipped).
fn add_primitive(
    m: &mut SkinnedMesh,
    path: &Path,
    mesh: &gltf::Mesh,
    prim: &gltf::Primitive,
    joints: &Joints,
    buffers: &[gltf::buffer::Data],
) -> Result<()> {
    let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
    if prim.mode() != gltf::mesh::Mode::Triangles {
        return Ok(());
    }
    let r = prim.reader(|b| Some(&buffers[b.index()]));
    let pos: Vec<[f32; 3]> = r
        .read_positions()
        .ok_or_else(|| bad(path, &what, "no POSITION"))?
        .collect();
    let nv = pos.len();
    let js: Vec<[u16; 4]> = match r.read_joints(0) {
        Some(j) => j.into_u16().collect(),
        None => return Ok(()),
    };
    let ws: Vec<[f32; 4]> = r
        .read_weights(0)
        .ok_or_else(|| bad(path, &what, "JOINTS_0 without WEIGHTS_0"))?
        .into_f32()
        .collect();
    if js.len() != nv || ws.len() != nv {
        return Err(bad(
            path,
            &what,
            "JOINTS_0/WEIGHTS_0 length differs from POSITION",
        ));
    }
    let base = m.rest.positions.len() as u32;
    let idx: Vec<u32> = match r.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..nv as u32).collect(),
    };
    for (k, tri) in idx.chunks_exact(3).enumerate() {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= nv) {
            return Err(bad(
                path,
                format!("{what} triangle {k}"),
                format!("index {v} ≥ {nv} vertices"),
            ));
        }
        m.rest
            .faces
            .push([base + tri[0], base + tri[1], base + tri[2]]);
    }
    for ((p, j), w) in pos.iter().zip(&js).zip(&ws) {
        if p.iter().any(|c| !c.is_finite()) {
            return Err(bad(path, &what, "non-finite position"));
        }
        if let Some(&bad_j) = j.iter().find(|&&j| j as usize >= joints.count) {
            return Err(bad(
                path,
                &what,
                format!(
                    "joint {bad_j} ≥ {} joints of skin {}",
                    joints.count, joints.skin
                ),
            ));
        }
        m.rest.positions.push(p.map(f64::from));
        m.joints.push(j.map(|j| joints.base + j as u32));
        m.weights.push(normalized(w));
    }
    Ok(())
}

/// The weights `w` scaled to sum 1, ignoring non-finite and negative ones
/// (all 0 when none is positive).
fn normalized(w: &[f32; 4]) -> [f32; 4] {
    let sum: f32 = w.iter().filter(|x| x.is_finite() && **x > 0.0).sum();
    if sum > 0.0 {
        w.map(|x| {
            if x.is_finite() && x > 0.0 {
                x / sum
            } else {
                0.0
            }
        })
    } else {
        [0.0; 4]
    }
}

/// Reads an animation's translation, rotation and scale channels.
fn read_clip(path: &Path, anim: &gltf::Animation, buffers: &[gltf::buffer::Data]) -> Result<Clip> {
    let mut clip = Clip {
        name: anim
            .name()
            .map_or(format!("clip {}", anim.index()), str::to_string),
        duration: 0.0,
        channels: Vec::new(),
    };
    for ch in anim.channels() {
        let Some(channel) = read_channel(path, anim.index(), &ch, buffers)? else {
            continue;
        };
        clip.duration = clip.duration.max(*channel.times.last().unwrap_or(&0.0));
        clip.channels.push(channel);
    }
    Ok(clip)
}

/// Reads one channel of animation `anim`, with checked keyframes; `None`
/// for a channel without inputs or driving morph target weights.
fn read_channel(
    path: &Path,
    anim: usize,
    ch: &gltf::animation::Channel,
    buffers: &[gltf::buffer::Data],
) -> Result<Option<Channel>> {
    let r = ch.reader(|b| Some(&buffers[b.index()]));
    let times: Vec<f32> = match r.read_inputs() {
        Some(t) => t.collect(),
        None => return Ok(None),
    };
    use gltf::animation::util::ReadOutputs;
    let (property, values): (Property, Vec<[f32; 4]>) = match r.read_outputs() {
        Some(ReadOutputs::Translations(t)) => (
            Property::Translation,
            t.map(|v| [v[0], v[1], v[2], 0.0]).collect(),
        ),
        Some(ReadOutputs::Scales(s)) => (
            Property::Scale,
            s.map(|v| [v[0], v[1], v[2], 0.0]).collect(),
        ),
        Some(ReadOutputs::Rotations(q)) => (Property::Rotation, q.into_f32().collect()),
        _ => return Ok(None), // morph target weights: not skinning
    };
    let interp = match ch.sampler().interpolation() {
        gltf::animation::Interpolation::Step => Interp::Step,
        gltf::animation::Interpolation::Linear => Interp::Linear,
        gltf::animation::Interpolation::CubicSpline => Interp::CubicSpline,
    };
    check_keyframes(path, anim, &times, values.len(), interp)?;
    Ok(Some(Channel {
        node: ch.target().node().index(),
        property,
        interp,
        times,
        values,
    }))
}

/// Checks a channel has a value (three for cubic splines) per keyframe and
/// keyframe times that are finite and increase strictly (sampling bisects
/// them).
fn check_keyframes(
    path: &Path,
    anim: usize,
    times: &[f32],
    values: usize,
    interp: Interp,
) -> Result<()> {
    let per = if interp == Interp::CubicSpline { 3 } else { 1 };
    if times.is_empty() || values != per * times.len() {
        return Err(bad(
            path,
            format!("animation {anim} channel"),
            "keyframe count mismatch",
        ));
    }
    if let Some(k) =
        (0..times.len()).find(|&k| !times[k].is_finite() || (k > 0 && times[k] <= times[k - 1]))
    {
        return Err(bad(
            path,
            format!("animation {anim} channel, keyframe {k}"),
            format!(
                "time {} is not finite or not after the previous keyframe's",
                times[k]
            ),
        ));
    }
    Ok(())
}

fn sample(ch: &Channel, t: f32) -> [f32; 4] {
    let per = if ch.interp == Interp::CubicSpline {
        3
    } else {
        1
    };
    let val = |k: usize| ch.values[per * k + (per / 2)];
    let n = ch.times.len();
    if t <= ch.times[0] || n == 1 {
        return val(0);
    }
    if t >= ch.times[n - 1] {
        return val(n - 1);
    }
    // times[0] < t < times[n - 1] (loaded times increase strictly), so
    // 1 ≤ partition point ≤ n - 1; clamped all the same.
    let k = (ch.times.partition_point(|&x| x <= t).max(1) - 1).min(n - 2);
    let (t0, t1) = (ch.times[k], ch.times[k + 1]);
    let dt = t1 - t0;
    let u = if dt > 0.0 { (t - t0) / dt } else { 0.0 };
    match ch.interp {
        Interp::Step => val(k),
        Interp::Linear => {
            let (a, b) = (val(k), val(k + 1));
            if ch.property == Property::Rotation {
                Quat::from_array(a)
                    .normalize()
                    .slerp(Quat::from_array(b).normalize(), u)
                    .to_array()
            } else {
                std::array::from_fn(|i| a[i] + (b[i] - a[i]) * u)
            }
        }
        Interp::CubicSpline => {
            let (p0, m0) = (val(k), ch.values[3 * k + 2]);
            let (p1, m1) = (val(k + 1), ch.values[3 * (k + 1)]);
            let (u2, u3) = (u * u, u * u * u);
            let h = [
                2.0 * u3 - 3.0 * u2 + 1.0,
                u3 - 2.0 * u2 + u,
                -2.0 * u3 + 3.0 * u2,
                u3 - u2,
            ];
            let v: [f32; 4] = std::array::from_fn(|i| {
                h[0] * p0[i] + h[1] * dt * m0[i] + h[2] * p1[i] + h[3] * dt * m1[i]
            });
            if ch.property == Property::Rotation {
                Quat::from_array(v).normalize().to_array()
            } else {
                v
            }
        }
    }
}

impl SkinnedMesh {
    /// The mesh with vertices at bit-identical rest positions merged into
    /// one ([`Mesh::weld`]), each keeping the joints and weights of the
    /// first of them, and how many merged vertices had other weights (they
    /// move as the first does). glTF files split vertices along UV and
    /// normal seams; welding joins the surface again, so that its edges are
    /// not all boundaries.
    pub fn welded(&self) -> (SkinnedMesh, usize) {
        let (rest, remap) = self.rest.weld();
        let n = rest.n_vertices();
        let mut first: Vec<Option<usize>> = vec![None; n];
        let mut differ = 0;
        for (old, &new) in remap.iter().enumerate() {
            match first[new as usize] {
                None => first[new as usize] = Some(old),
                Some(f) => {
                    differ += usize::from(
                        self.joints[f] != self.joints[old] || self.weights[f] != self.weights[old],
                    );
                }
            }
        }
        let pick = |i: usize| first[i].expect("every new vertex has an old one");
        (
            SkinnedMesh {
                joints: (0..n).map(|i| self.joints[pick(i)]).collect(),
                weights: (0..n).map(|i| self.weights[pick(i)]).collect(),
                rest,
                ..self.clone()
            },
            differ,
        )
    }

    /// Joint matrices (global joint transform × inverse bind) of `clip` at
    /// time `t` seconds; `clip = None` gives the rest pose.
    pub fn joint_matrices(&self, clip: Option<usize>, t: f32) -> Result<Vec<Mat4>> {
        let mut trs = self.rest_trs.clone();
        if let Some(c) = clip {
            let clip = self.clips.get(c).ok_or_else(|| {
                Error::InvalidArgument(format!("clip {c}: the file has {} clips", self.clips.len()))
            })?;
            for ch in &clip.channels {
                let v = sample(ch, t);
                let x = &mut trs[ch.node];
                match ch.property {
                    Property::Translation => x.t = Vec3::new(v[0], v[1], v[2]),
                    Property::Scale => x.s = Vec3::new(v[0], v[1], v[2]),
                    Property::Rotation => x.r = Quat::from_array(v).normalize(),
                }
            }
        }
        // Global transforms by walking up the hierarchy (memoised).
        let mut global: Vec<Option<Mat4>> = vec![None; trs.len()];
        fn resolve(
            i: usize,
            parents: &[Option<usize>],
            trs: &[Trs],
            g: &mut Vec<Option<Mat4>>,
            depth: usize,
        ) -> Mat4 {
            if let Some(m) = g[i] {
                return m;
            }
            let local = trs[i].matrix();
            let m = match parents[i] {
                Some(p) if depth < parents.len() => resolve(p, parents, trs, g, depth + 1) * local,
                _ => local,
            };
            g[i] = Some(m);
            m
        }
        Ok(self
            .joint_nodes
            .iter()
            .zip(&self.inverse_bind)
            .zip(&self.joint_mesh_node)
            .map(|((&n, ib), &mn)| {
                let mesh_inv = resolve(mn, &self.parents, &trs, &mut global, 0).inverse();
                mesh_inv * resolve(n, &self.parents, &trs, &mut global, 0) * *ib
            })
            .collect())
    }

    /// Column-major floats of joint matrices, 16 per joint (device layout).
    pub fn flatten(mats: &[Mat4]) -> Vec<f32> {
        mats.iter().flat_map(|m| m.to_cols_array()).collect()
    }
}

#[cfg(test)]
mod missing_tests {
    #[test]
    fn missing_buffer_file_is_named_with_the_gltf_that_refers_to_it() {
        let dir = std::env::temp_dir().join(format!("shapecue-gltf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("x.gltf");
        std::fs::write(
            &path,
            r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"gone.bin","byteLength":4}]}"#,
        )
        .unwrap();
        let e = super::load_gltf(&path).unwrap_err().to_string();
        assert!(
            e.contains("x.gltf") && e.contains("buffer 0") && e.contains("gone.bin"),
            "{e}"
        );
        assert_eq!(e.matches("No such file").count(), 1, "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
