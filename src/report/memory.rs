//! `shapecue report memory`: bits per mesh of each cap variant of the edges
//! stage, from the buffer sizes ([`crate::spec::edges::memory_use`]); no
//! device needed.

use super::{Block, Cell, Chart, Column, Report, Row, Table, edge_meshes};
use crate::error::Result;
use crate::mesh::edges::EdgeTopology;
use crate::spec::edges::{CapMode, memory_use};

/// The report: one row per mesh of [`edge_meshes`].
///
/// # Errors
/// A mesh whose edge topology cannot be built.
pub fn report() -> Result<Report> {
    let mut r = Report::new("memory", "none (buffer sizes, computed on the host)");
    let mut t = Table::new(
        "memory",
        vec![
            Column::new("mesh", "mesh"),
            Column::new("edges", "edges"),
            Column::new("caps", "caps"),
            Column::new("none bits", "none_bits"),
            Column::new("mh bits", "mh_bits"),
            Column::new("adj bits", "adjacency_bits"),
        ],
    );
    let modes = [CapMode::None, CapMode::Mh, CapMode::Adjacency];
    let mut groups = Vec::new();
    let mut series: Vec<(String, Vec<f64>)> = modes
        .iter()
        .map(|m| (m.name().to_string(), Vec::new()))
        .collect();
    for (name, m) in edge_meshes() {
        let topo = EdgeTopology::new(&m, &[], &name)?;
        let bits = |c| {
            let u = memory_use(c, topo.edges.len(), topo.caps.len());
            u.edge_bits + u.cap_bits
        };
        let mut cells = vec![
            Cell::text(name.clone()),
            Cell::int(topo.edges.len()),
            Cell::int(topo.caps.len()),
        ];
        for (s, mode) in series.iter_mut().zip(modes) {
            let b = bits(mode);
            s.1.push(b as f64);
            cells.push(Cell::int(b));
        }
        groups.push(name);
        t.rows.push(Row::new(cells));
    }
    r.blocks.push(Block::Table(t));
    r.text(
        "(bits of the edge buffer, edge-out and kind, plus each variant's cap buffer and cap-out; 32-bit elements)",
    );
    r.charts.push(Chart::Bars {
        title: "Edges stage memory per cap variant".into(),
        y_label: "bits".into(),
        log_y: true,
        groups,
        series,
    });
    Ok(r)
}
