//! Measurement, above the front door: the accuracy/time tables and plots of
//! `shapecue report <topic>`, the error metrics and the timed runs they are
//! made of. One module per topic builds a [`Report`] (text, tables whose
//! rows carry numbers, and the charts of those numbers); this module writes
//! it as Markdown or JSON, [`plot`] draws it as SVG.
//!
//! Nothing below the front door imports this module (`scripts/check-layers.sh`):
//! the library's calls return their timings in the one timing type
//! ([`crate::spec::timing::Timing`]) and know nothing of tables.

pub mod caps;
pub mod coherence;
pub mod curvature;
pub mod frames;
pub mod isosurface;
pub mod line_agreement;
pub mod lines;
pub mod lines_batch;
pub mod memory;
pub mod metrics;
pub mod pipeline;
pub mod plot;
pub mod strokes;
pub mod visibility;

use crate::mesh::{self, LoadOptions, Mesh};
use serde_json::{Map, Value, json};
use std::path::PathBuf;

/// A measured report: who measured what where, its text and tables in
/// order, and the charts of its numbers.
#[derive(Clone, Debug)]
pub struct Report {
    /// The topic (`curvature`, `isosurface`, `strokes`, `pipeline`, `caps`,
    /// `lines-batch`, `visibility`, `memory`).
    pub topic: &'static str,
    /// The device measured on (its name), or what computed the numbers.
    pub device: String,
    /// The command that made the report, as the caller gives it
    /// (`shapecue report curvature --runs 3`); empty when not given.
    pub command: String,
    /// When it was measured: `YYYY-MM-DD HH:MM UTC`.
    pub measured_utc: String,
    /// Text lines and tables, in the order they print.
    pub blocks: Vec<Block>,
    /// The charts [`plot::svg`] draws.
    pub charts: Vec<Chart>,
}

/// A part of a report: lines of text printed as they are, or a table.
#[derive(Clone, Debug)]
pub enum Block {
    /// Lines of text (a leading `\n` leaves a blank line before them).
    Text(String),
    /// A table, printed as Markdown.
    Table(Table),
}

/// A table: columns with their JSON field names, rows of cells.
#[derive(Clone, Debug)]
pub struct Table {
    /// The table's key in the JSON document (`variants`, `refinement`, ...).
    pub key: &'static str,
    /// The columns.
    pub columns: Vec<Column>,
    /// The rows.
    pub rows: Vec<Row>,
}

/// A column: its Markdown heading and its JSON field (with its unit:
/// `kernel_ms`, `gap_px`, `none_bits`); a column without a heading is in
/// the JSON only.
#[derive(Clone, Debug)]
pub struct Column {
    /// The heading in the Markdown table; `None`: JSON only.
    pub title: Option<String>,
    /// The field name of the rows' JSON objects.
    pub key: String,
}

/// A row: its cells in column order, or a note in place of the cells after
/// the first (a variant the device cannot run).
#[derive(Clone, Debug)]
pub struct Row {
    /// One cell per column.
    pub cells: Vec<Cell>,
    /// Printed in the second column, the others left empty; in the JSON as `note`.
    pub note: Option<String>,
}

/// A cell: the text printed and the value written to JSON.
#[derive(Clone, Debug)]
pub struct Cell {
    /// As printed in the table.
    pub text: String,
    /// As written to JSON (a number where it is one).
    pub value: Value,
}

/// A chart of a report's numbers (see [`plot::svg`]).
#[derive(Clone, Debug)]
pub enum Chart {
    /// Error against time on log axes, one labelled point per variant.
    Scatter {
        /// Title above the chart.
        title: String,
        /// Axis captions.
        x_label: String,
        /// Axis captions.
        y_label: String,
        /// (label, x, y); points with a non-positive or non-finite
        /// coordinate are left out (log axes).
        points: Vec<(String, f64, f64)>,
    },
    /// Error against the mesh or grid spacing h on log axes, one line per
    /// series, with a reference slope of h².
    Convergence {
        /// Title above the chart.
        title: String,
        /// Axis captions.
        x_label: String,
        /// Axis captions.
        y_label: String,
        /// (series name, [(h, error)]).
        series: Vec<(String, Vec<(f64, f64)>)>,
    },
    /// Lines over a linear x (frames, sizes) and a linear y, one per series.
    Lines {
        /// Title above the chart.
        title: String,
        /// Axis captions.
        x_label: String,
        /// Axis captions.
        y_label: String,
        /// (series name, [(x, y)]); non-finite points are left out.
        series: Vec<(String, Vec<(f64, f64)>)>,
    },
    /// Bars: one group per category, one bar per series in each group.
    Bars {
        /// Title above the chart.
        title: String,
        /// Axis caption of the values.
        y_label: String,
        /// A logarithmic value axis (values spanning orders of magnitude).
        log_y: bool,
        /// The categories along the axis.
        groups: Vec<String>,
        /// (series name, one value per group).
        series: Vec<(String, Vec<f64>)>,
    },
}

impl Cell {
    /// A text cell (a name, a label).
    pub fn text(s: impl Into<String>) -> Cell {
        let s = s.into();
        Cell {
            value: Value::String(s.clone()),
            text: s,
        }
    }

    /// A number printed as `text`.
    pub fn num(v: f64, text: String) -> Cell {
        Cell {
            text,
            value: if v.is_finite() { json!(v) } else { Value::Null },
        }
    }

    /// A number in scientific notation with `digits` decimals (`1.23e-4`),
    /// and an exact zero as `0`, the same in every report.
    pub fn sci(v: f64, digits: usize) -> Cell {
        let text = if v == 0.0 {
            "0".to_string()
        } else {
            format!("{v:.digits$e}")
        };
        Cell::num(v, text)
    }

    /// A count, printed as it is.
    pub fn int<T: Into<Value> + ToString>(v: T) -> Cell {
        Cell {
            text: v.to_string(),
            value: v.into(),
        }
    }

    /// An empty cell (`null` in JSON).
    pub fn empty() -> Cell {
        Cell {
            text: String::new(),
            value: Value::Null,
        }
    }

    /// An empty cell printed as `text` (`-`, `0 (reference)`), `value` in JSON.
    pub fn shown(text: &str, value: Value) -> Cell {
        Cell {
            text: text.to_string(),
            value,
        }
    }
}

impl Column {
    /// A column printed under `title`, `key` in JSON.
    pub fn new(title: &str, key: &str) -> Column {
        Column {
            title: Some(title.to_string()),
            key: key.to_string(),
        }
    }

    /// A column in the JSON only.
    pub fn hidden(key: &str) -> Column {
        Column {
            title: None,
            key: key.to_string(),
        }
    }
}

impl Row {
    /// A row of cells.
    pub fn new(cells: Vec<Cell>) -> Row {
        Row { cells, note: None }
    }
}

impl Table {
    /// A table with `columns` and no rows yet.
    pub fn new(key: &'static str, columns: Vec<Column>) -> Table {
        Table {
            key,
            columns,
            rows: Vec::new(),
        }
    }

    /// The rows as JSON objects (`note` added where a row has one).
    pub fn json_rows(&self) -> Vec<Value> {
        self.rows
            .iter()
            .map(|r| {
                let mut o = Map::new();
                for (c, cell) in self.columns.iter().zip(&r.cells) {
                    o.insert(c.key.clone(), cell.value.clone());
                }
                if let Some(n) = &r.note {
                    o.insert("note".into(), json!(n));
                }
                Value::Object(o)
            })
            .collect()
    }

    /// The table as Markdown: heading, delimiter row, rows, each line ended.
    pub fn markdown(&self) -> String {
        let shown: Vec<usize> = (0..self.columns.len())
            .filter(|&i| self.columns[i].title.is_some())
            .collect();
        let line = |cells: Vec<&str>| format!("| {} |\n", cells.join(" | "));
        let mut s = line(
            shown
                .iter()
                .map(|&i| self.columns[i].title.as_deref().unwrap_or(""))
                .collect(),
        );
        s.push_str(&format!("|{}\n", "---|".repeat(shown.len())));
        for r in &self.rows {
            match &r.note {
                Some(note) => {
                    let first = r.cells.first().map_or("", |c| c.text.as_str());
                    s.push_str(&format!(
                        "| {first} | {note} |{}\n",
                        " |".repeat(shown.len().saturating_sub(2))
                    ));
                }
                None => s.push_str(&line(
                    shown
                        .iter()
                        .map(|&i| r.cells.get(i).map_or("", |c| c.text.as_str()))
                        .collect(),
                )),
            }
        }
        s
    }
}

impl Report {
    /// An empty report on `device`, measured now (the command is set by
    /// the caller with [`Report::with_command`]).
    pub fn new(topic: &'static str, device: impl Into<String>) -> Report {
        Report {
            topic,
            device: device.into(),
            command: String::new(),
            measured_utc: utc_now(),
            blocks: Vec::new(),
            charts: Vec::new(),
        }
    }

    /// The report, naming the command that made it.
    pub fn with_command(mut self, command: impl Into<String>) -> Report {
        self.command = command.into();
        self
    }

    /// Adds lines of text.
    pub fn text(&mut self, s: impl Into<String>) {
        self.blocks.push(Block::Text(s.into()));
    }

    /// The table with `key`, if the report has one.
    pub fn table(&self, key: &str) -> Option<&Table> {
        self.blocks.iter().find_map(|b| match b {
            Block::Table(t) if t.key == key => Some(t),
            _ => None,
        })
    }

    /// The header line every output starts with: when, on what, by which command.
    pub fn header(&self) -> String {
        let mut s = format!("Measured {}, device {}", self.measured_utc, self.device);
        if !self.command.is_empty() {
            s.push_str(&format!(", command `{}`", self.command));
        }
        s
    }

    /// The report as Markdown: the header line, a blank line, then its text
    /// and tables in order (a blank line after a table that text follows,
    /// so the text is not read as a row).
    pub fn markdown(&self) -> String {
        let mut s = self.header() + "\n\n";
        let mut after_table = false;
        for b in &self.blocks {
            match b {
                Block::Text(t) => {
                    if after_table && !t.starts_with('\n') {
                        s.push('\n');
                    }
                    s.push_str(t);
                    s.push('\n');
                    after_table = false;
                }
                Block::Table(t) => {
                    s.push_str(&t.markdown());
                    after_table = true;
                }
            }
        }
        s
    }

    /// The report's numbers as JSON: topic, date, device, command, its text
    /// lines (`text`) and each table's rows as objects (`tables.<key>`).
    pub fn json(&self) -> Value {
        let mut tables = Map::new();
        let mut text = Vec::new();
        for b in &self.blocks {
            match b {
                Block::Text(t) => {
                    text.extend(t.lines().filter(|l| !l.trim().is_empty()).map(|l| json!(l)))
                }
                Block::Table(t) => {
                    tables.insert(t.key.to_string(), Value::Array(t.json_rows()));
                }
            }
        }
        json!({
            "topic": self.topic,
            "measured_utc": self.measured_utc,
            "device": self.device,
            "command": self.command,
            "text": text,
            "tables": tables,
        })
    }
}

/// The current time as `YYYY-MM-DD HH:MM UTC`.
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    utc_string(secs)
}

/// `secs` after the Unix epoch as `YYYY-MM-DD HH:MM UTC` (the proleptic
/// Gregorian calendar, Howard Hinnant's days-to-civil algorithm).
pub fn utc_string(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02} UTC",
        rem / 3600,
        (rem % 3600) / 60
    )
}

/// The folder of the larger data sets some reports use (scans, skinned
/// animations; docs/performance.md): `$SHAPECUE_SHARED_DATA`, else
/// `../shared/data` from the current folder (beside a clone of the
/// repository, run from its root). Nothing of the build machine is kept in
/// the binary.
pub fn shared_data() -> PathBuf {
    std::env::var_os("SHAPECUE_SHARED_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("../shared/data"))
}

/// The meshes of the edges tables (House & Li's comparison): generated
/// cube, cylinder, cone and icosphere, and the shared teapot and bunny when
/// present (a note on stderr when not); all unit-sized.
pub fn edge_meshes() -> Vec<(String, Mesh)> {
    let mut v = vec![
        ("cube".to_string(), mesh::cube(1.0)),
        ("cylinder".to_string(), mesh::capped_cylinder(0.5, 1.0, 32)),
        ("cone".to_string(), mesh::cone(0.5, 1.0, 32)),
        ("icosphere".to_string(), mesh::icosphere(0.5, 3)),
    ];
    let dir = shared_data().join("meshes");
    for (name, file) in [("teapot", "teapot.obj"), ("bunny", "stanford-bunny.obj")] {
        match mesh::load(&dir.join(file), &LoadOptions::default()) {
            Ok(m) => v.push((name.to_string(), m)),
            Err(e) => eprintln!("skipping {name}: {e}"),
        }
    }
    v.into_iter()
        .map(|(n, m)| (n, mesh::unit_sized(&m)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_dates_follow_the_calendar() {
        assert_eq!(utc_string(0), "1970-01-01 00:00 UTC");
        assert_eq!(utc_string(951_782_400 + 3_660), "2000-02-29 01:01 UTC");
        assert_eq!(utc_string(1_796_400_000), "2026-12-04 16:00 UTC");
    }

    #[test]
    fn tables_print_as_markdown_and_json() {
        let mut t = Table::new(
            "t",
            vec![
                Column::new("name", "name"),
                Column::new("time ms", "time_ms"),
                Column::hidden("h"),
                Column::new("err", "err"),
            ],
        );
        t.rows.push(Row::new(vec![
            Cell::text("a"),
            Cell::num(1.5, "1.50".into()),
            Cell::num(0.1, String::new()),
            Cell::empty(),
        ]));
        t.rows.push(Row {
            cells: vec![Cell::text("b")],
            note: Some("not here".into()),
        });
        assert_eq!(
            t.markdown(),
            "| name | time ms | err |\n|---|---|---|\n| a | 1.50 |  |\n| b | not here | |\n"
        );
        let rows = t.json_rows();
        assert_eq!(rows[0]["time_ms"], json!(1.5));
        assert_eq!(rows[0]["h"], json!(0.1));
        assert!(rows[0]["err"].is_null());
        assert_eq!(rows[1]["note"], json!("not here"));
    }
}
