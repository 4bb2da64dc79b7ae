//! Estimators of a whole mesh computed in a cache-friendly memory order, and
//! the one-shot [`estimate`] the front door calls.

use super::{CurvatureEstimator, MappedField};
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::mesh::order::{LocalityOrder, MeshOrder};
use crate::spec::curvature::{CurvatureField, CurvatureOptions};
use std::sync::Arc;
use std::time::Instant;

/// An estimator of a whole mesh computed in the memory order `order` asks
/// for ([`crate::mesh::order`]): built, each vertex's frame seeded from the
/// face that seeds it in the input's order (so directions keep their
/// signs), and the pose uploaded. Run it through `est`; read its results in
/// the input's vertex order with [`OrderedEstimator::read`].
pub struct OrderedEstimator {
    /// The estimator, on the mesh in its computing order.
    pub est: CurvatureEstimator,
    /// The renumbering it computes in, or `None` for the input's order.
    pub order: Option<LocalityOrder>,
    /// Host ms of choosing and applying the order
    /// ([`OrderedEstimator::reorder_ms`]).
    reorder_ms: f64,
}

/// The host half of an [`OrderedEstimator`], which needs no device: the
/// memory order chosen for a mesh, the mesh renumbered in it and each
/// vertex's frame-seeding face. A caller can compute it while the device
/// opens ([`OrderedEstimator::with_plan`]).
pub struct OrderPlan {
    order: Option<LocalityOrder>,
    reordered: Option<crate::Mesh>,
    frame_faces: Option<Vec<i32>>,
    /// Host ms of choosing and applying the order.
    reorder_ms: f64,
}

impl OrderPlan {
    /// Chooses the order `order` asks for on `mesh` and applies it.
    pub fn new(mesh: &crate::Mesh, order: MeshOrder) -> OrderPlan {
        let t0 = Instant::now();
        let order = LocalityOrder::choose(mesh, order);
        let reordered = order.as_ref().map(|o| o.apply(mesh));
        let frame_faces = order.as_ref().map(|o| o.frame_faces(mesh));
        OrderPlan {
            order,
            reordered,
            frame_faces,
            reorder_ms: t0.elapsed().as_secs_f64() * 1e3,
        }
    }
}

impl OrderedEstimator {
    /// Builds the estimator of `mesh` for `opts` in the order `order` picks.
    pub fn new(
        gpu: Arc<Gpu>,
        mesh: &crate::Mesh,
        opts: CurvatureOptions,
        order: MeshOrder,
    ) -> Result<Self> {
        Self::with_plan(gpu, mesh, opts, OrderPlan::new(mesh, order))
    }

    /// Builds the estimator of `mesh` for `opts` in the order of `plan`,
    /// made for this `mesh` by [`OrderPlan::new`].
    pub fn with_plan(
        gpu: Arc<Gpu>,
        mesh: &crate::Mesh,
        opts: CurvatureOptions,
        plan: OrderPlan,
    ) -> Result<Self> {
        if let Some(o) = &plan.order
            && (o.input_vertex.len() != mesh.n_vertices() || o.input_face.len() != mesh.n_faces())
        {
            return Err(Error::InvalidArgument(format!(
                "memory order made for a mesh of {} vertices and {} faces, given one of {} and {}",
                o.input_vertex.len(),
                o.input_face.len(),
                mesh.n_vertices(),
                mesh.n_faces()
            )));
        }
        let m = plan.reordered.as_ref().unwrap_or(mesh);
        let mut est = CurvatureEstimator::new(gpu, m.n_vertices(), &m.faces, opts)?;
        if let Some(f) = &plan.frame_faces {
            est.set_frame_faces(f)?;
        }
        est.set_stored_normals(m.normals.as_deref())?;
        est.set_positions(&m.positions)?;
        Ok(OrderedEstimator {
            est,
            order: plan.order,
            reorder_ms: plan.reorder_ms,
        })
    }

    /// Host wall ms of choosing and applying the memory order (in
    /// [`OrderPlan::new`]); a caller's `reorder` phase.
    pub fn reorder_ms(&self) -> f64 {
        self.reorder_ms
    }

    /// The results of the last full run, in the input's vertex order.
    pub fn read(&self) -> Result<CurvatureField> {
        self.est
            .read_placed(self.order.as_ref().map(|o| &o.input_vertex[..]))
    }

    /// [`OrderedEstimator::read`] without the copy: the device buffers
    /// mapped, read vertex by vertex in the input's order
    /// ([`CurvatureEstimator::mapped`]); the same values, bit for bit.
    pub fn mapped(&self) -> Result<MappedField<'_>> {
        self.est
            .mapped(self.order.as_ref().map(|o| &o.input_vertex[..]))
    }
}

/// One-shot estimation: allocate, upload, run every pass, read back (the
/// front door's `shapecue::curvature_on`). A mesh whose order is scattered
/// is computed in a Morton order for cache locality and its results are
/// mapped back ([`OrderedEstimator`], [`MeshOrder::Auto`]); the time of
/// reordering counts as topology.
pub fn estimate(
    gpu: Arc<Gpu>,
    mesh: &crate::Mesh,
    opts: CurvatureOptions,
) -> Result<crate::spec::curvature::Curvature> {
    let mut o = OrderedEstimator::new(gpu, mesh, opts, MeshOrder::Auto)?;
    let mut timing = o.est.run()?;
    timing.phase("topology", o.reorder_ms() + o.est.topology_ms());
    Ok(crate::spec::curvature::Curvature {
        field: o.read()?,
        counts: o.est.counts()?,
        timing,
        device_bytes: o.est.device_bytes(),
    })
}
