//! A report's charts as one SVG (plotters, SVG backend only): the header
//! line (date, device, command) on top, then each chart of
//! [`Report::charts`] below the other: error against time on log axes with
//! a labelled point per variant, error against h on log axes with an h²
//! reference slope, and grouped bars.

use super::{Chart, Report};
use crate::error::{Error, Result};
use plotters::coord::Shift;
use plotters::coord::combinators::{BindKeyPoints, WithKeyPoints};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// Width of the SVG in pixels.
const WIDTH: u32 = 960;
/// Height of one chart in pixels.
const CHART_HEIGHT: u32 = 540;
/// Height of the header (two lines: date and device, then the command).
const HEADER: u32 = 48;
const FONT: &str = "sans-serif";

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
/// A log axis with its ticks chosen by [`log_ticks`].
type LogAxis = WithKeyPoints<LogCoord<f64>>;
/// A chart with log axes on both sides, drawn into an [`Area`].
type LogLog<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<LogAxis, LogAxis>>;

fn err(e: impl std::fmt::Display) -> Error {
    Error::Render {
        what: "drawing the report's SVG plot".into(),
        detail: e.to_string(),
    }
}

/// The report's charts as an SVG document.
///
/// # Errors
/// A report without charts; plotters' drawing errors.
pub fn svg(report: &Report) -> Result<String> {
    if report.charts.is_empty() {
        return Err(Error::InvalidArgument(format!(
            "the {} report has nothing to plot",
            report.topic
        )));
    }
    let n = report.charts.len() as u32;
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (WIDTH, HEADER + n * CHART_HEIGHT))
            .into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (top, rest) = root.split_vertically(HEADER);
        let header = report.header();
        let (first, second) = match header.split_once(", command ") {
            Some((a, b)) => (a.to_string(), format!("command {b}")),
            None => (header.clone(), String::new()),
        };
        let style = TextStyle::from((FONT, 14).into_font()).color(&BLACK);
        top.draw_text(&first, &style, (12, 8)).map_err(err)?;
        top.draw_text(&second, &style, (12, 26)).map_err(err)?;
        for (area, chart) in rest
            .split_evenly((n as usize, 1))
            .iter()
            .zip(&report.charts)
        {
            match chart {
                Chart::Scatter {
                    title,
                    x_label,
                    y_label,
                    points,
                } => scatter(area, title, x_label, y_label, points)?,
                Chart::Convergence {
                    title,
                    x_label,
                    y_label,
                    series,
                } => convergence(area, title, x_label, y_label, series)?,
                Chart::Lines {
                    title,
                    x_label,
                    y_label,
                    series,
                } => lines(area, title, (x_label, y_label), series)?,
                Chart::Bars {
                    title,
                    y_label,
                    log_y,
                    groups,
                    series,
                } => {
                    let data = BarChart {
                        y_label,
                        groups,
                        series,
                    };
                    bars(area, &root, title, *log_y, &data)?
                }
            }
        }
        root.present().map_err(err)?;
    }
    Ok(buf)
}

/// The range of the positive finite values of `v`, widened by a factor
/// on each side (log axes); `None` when there are none.
fn log_range(v: impl Iterator<Item = f64>, pad: f64) -> Option<std::ops::Range<f64>> {
    let (lo, hi) = v
        .filter(|x| x.is_finite() && *x > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(l, h), x| (l.min(x), h.max(x)));
    (lo <= hi).then(|| lo / pad..hi * pad)
}

/// The ticks of a log axis over `r`: 1, 2 and 5 times each power of ten
/// inside it; where that gives fewer than four (a range within a decade or
/// two), every digit times the powers of ten; where that still gives fewer
/// than three (a narrow range), evenly spaced round values (1, 2 or 5 times
/// a power of ten apart, at least four of them).
pub fn log_ticks(r: &std::ops::Range<f64>) -> Vec<f64> {
    let (lo, hi) = (r.start.min(r.end), r.start.max(r.end));
    if !(lo > 0.0 && hi.is_finite()) {
        return Vec::new();
    }
    let within = |mantissas: &[f64]| -> Vec<f64> {
        let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (k0..=k1)
            .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|v| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9))
            .collect()
    };
    let t = within(&[1.0, 2.0, 5.0]);
    if t.len() >= 4 {
        return t;
    }
    let t = within(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    if t.len() >= 3 {
        return t;
    }
    let raw = (hi - lo) / 4.0;
    let p = 10f64.powf(raw.log10().floor());
    let step = [5.0, 2.0, 1.0]
        .iter()
        .map(|m| m * p)
        .find(|s| *s <= raw)
        .unwrap_or(p);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last)
        .map(|i| i as f64 * step)
        .filter(|v| *v > 0.0)
        .collect()
}

/// A tick label: at most three significant digits, plain decimals from
/// 0.001 to 99999, else `1e5`-style.
fn tick(v: &f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        return "0".into();
    }
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.2e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = m.trim_end_matches('0').trim_end_matches('.');
        return format!("{m}e{e}");
    }
    let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn no_data(area: &Area, title: &str) -> Result<()> {
    area.draw_text(
        &format!("{title}: nothing to plot"),
        &TextStyle::from((FONT, 16).into_font()),
        (40, 40),
    )
    .map_err(err)
}

/// A chart with log axes over `xr` × `yr`, its caption, axis labels and
/// grid drawn (the scatter and convergence charts share it).
fn log_log<'a, 'b>(
    area: &'a Area<'b>,
    title: &str,
    x_label: &str,
    y_label: &str,
    xr: std::ops::Range<f64>,
    yr: std::ops::Range<f64>,
) -> Result<LogLog<'a, 'b>> {
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 17))
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(80)
        .build_cartesian_2d(
            xr.clone().log_scale().with_key_points(log_ticks(&xr)),
            yr.clone().log_scale().with_key_points(log_ticks(&yr)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_labels(12)
        .y_labels(12)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .draw()
        .map_err(err)?;
    Ok(chart)
}

fn scatter(
    area: &Area,
    title: &str,
    x_label: &str,
    y_label: &str,
    points: &[(String, f64, f64)],
) -> Result<()> {
    let ok = |x: f64| x.is_finite() && x > 0.0;
    let pts: Vec<&(String, f64, f64)> = points.iter().filter(|p| ok(p.1) && ok(p.2)).collect();
    let (Some(xr), Some(yr)) = (
        log_range(pts.iter().map(|p| p.1), 1.6),
        log_range(pts.iter().map(|p| p.2), 1.6),
    ) else {
        return no_data(area, title);
    };
    let mut chart = log_log(area, title, x_label, y_label, xr, yr)?;
    // Labels alternate above and below their points in the order of x, so
    // that variants of equal error but near times stay readable.
    let mut order: Vec<usize> = (0..pts.len()).collect();
    order.sort_by(|&a, &b| pts[a].1.total_cmp(&pts[b].1));
    let mut offset = vec![0; pts.len()];
    for (rank, &i) in order.iter().enumerate() {
        offset[i] = [-16, 6, -30, 20][rank % 4];
    }
    chart
        .draw_series(pts.iter().enumerate().map(|(i, (label, x, y))| {
            let c = Palette99::pick(i).to_rgba();
            EmptyElement::at((*x, *y))
                + Circle::new((0, 0), 5, c.filled())
                + Text::new(label.clone(), (7, offset[i]), (FONT, 12).into_font())
        }))
        .map_err(err)?;
    Ok(())
}

fn convergence(
    area: &Area,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<()> {
    let ok = |p: &&(f64, f64)| p.0.is_finite() && p.0 > 0.0 && p.1.is_finite() && p.1 > 0.0;
    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.1.iter().filter(ok).copied())
        .collect();
    let (Some(xr), Some(yr)) = (
        log_range(all.iter().map(|p| p.0), 1.3),
        log_range(all.iter().map(|p| p.1), 2.0),
    ) else {
        return no_data(area, title);
    };
    let mut chart = log_log(area, title, x_label, y_label, xr.clone(), yr.clone())?;
    for (i, (name, pts)) in series.iter().enumerate() {
        let c = Palette99::pick(i).to_rgba();
        let pts: Vec<(f64, f64)> = pts.iter().filter(ok).copied().collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(err)?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled())))
            .map_err(err)?;
    }
    // The reference slope h², through the smallest error at the largest h.
    let h0 = all.iter().map(|p| p.0).fold(0.0f64, f64::max);
    let e0 = all
        .iter()
        .filter(|p| p.0 == h0)
        .map(|p| p.1)
        .fold(f64::INFINITY, f64::min);
    let grey = RGBColor(110, 110, 110);
    let slope: Vec<(f64, f64)> = (0..=32)
        .map(|i| {
            let h = xr.start * (xr.end / xr.start).powf(f64::from(i) / 32.0);
            (h, e0 * (h / h0).powi(2))
        })
        .filter(|p| yr.contains(&p.1))
        .collect();
    chart
        .draw_series(LineSeries::new(slope, grey.stroke_width(1)))
        .map_err(err)?
        .label("h² slope")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey.stroke_width(1)));
    // Errors fall with h, so the data and the slope run from the lower left
    // to the upper right: the legend goes in the empty upper left.
    legend_upper_left(&mut chart)
}

/// Lines on linear axes, one per series, with a legend in the upper left.
fn lines(
    area: &Area,
    title: &str,
    (x_label, y_label): (&str, &str),
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<()> {
    let ok = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
    let all: Vec<(f64, f64)> = (series.iter())
        .flat_map(|s| s.1.iter().filter(ok).copied())
        .collect();
    if all.is_empty() {
        return no_data(area, title);
    }
    let (x0, x1) = all
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.0), h.max(p.0))
        });
    let y1 = all.iter().map(|p| p.1).fold(0.0f64, f64::max);
    let x1 = if x1 > x0 { x1 } else { x0 + 1.0 };
    let y1 = if y1 > 0.0 { 1.1 * y1 } else { 1.0 };
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 17))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(x0..x1, 0.0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .label_style((FONT, 12))
        .draw()
        .map_err(err)?;
    for (i, (name, pts)) in series.iter().enumerate() {
        let c = Palette99::pick(i).to_rgba();
        let pts: Vec<(f64, f64)> = pts.iter().filter(ok).copied().collect();
        chart
            .draw_series(LineSeries::new(pts, c.stroke_width(2)))
            .map_err(err)?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    }
    legend_upper_left(&mut chart)
}

/// The series' legend in the chart's upper left, on a light box.
fn legend_upper_left<'a, 'b: 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, CT>,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 12))
        .draw()
        .map_err(err)
}

/// A bar chart's data: one bar per series in each group.
struct BarChart<'s> {
    /// The y axis' label.
    y_label: &'s str,
    /// The group names along x.
    groups: &'s [String],
    /// (name, one value per group) per series.
    series: &'s [(String, Vec<f64>)],
}

/// Grouped bars on a linear or log y axis, the group names drawn on `root`
/// under the axis.
fn bars(area: &Area, root: &Area, title: &str, log_y: bool, data: &BarChart) -> Result<()> {
    let values = || data.series.iter().flat_map(|s| s.1.iter().copied());
    let n = data.groups.len();
    if n == 0 || values().all(|v| !v.is_finite()) {
        return no_data(area, title);
    }
    let hi = values().filter(|v| v.is_finite()).fold(0.0f64, f64::max);
    let x = -0.5..n as f64 - 0.5;
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(title, (FONT, 17))
        .margin(16)
        .x_label_area_size(36)
        .y_label_area_size(80);
    if log_y {
        let lo = values()
            .filter(|v| v.is_finite() && *v > 0.0)
            .fold(f64::INFINITY, f64::min);
        let (lo, hi) = (lo / 2.0, hi * 2.0);
        let chart = builder
            .build_cartesian_2d(
                x,
                (lo..hi).log_scale().with_key_points(log_ticks(&(lo..hi))),
            )
            .map_err(err)?;
        draw_bars(chart, root, lo, data)
    } else {
        let chart = builder
            .build_cartesian_2d(x, 0.0..(hi * 1.1).max(1e-9))
            .map_err(err)?;
        draw_bars(chart, root, 0.0, data)
    }
}

/// The mesh, the bars from `base` up, their legend (more than one series)
/// and the group names centred under their bars, on a linear or log y axis.
fn draw_bars<'a, 'b: 'a, Y>(
    mut chart: ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, Y>>,
    root: &Area,
    base: f64,
    data: &BarChart,
) -> Result<()>
where
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let series = data.series;
    let width = 0.8 / series.len().max(1) as f64;
    // One bar: series j of group i, from `base` to `v`.
    let rect = |i: usize, j: usize, v: f64| {
        let x0 = i as f64 - 0.4 + j as f64 * width;
        Rectangle::new(
            [(x0, base), (x0 + width * 0.92, v)],
            Palette99::pick(j).to_rgba().filled(),
        )
    };
    let legend = |j: usize| {
        let c = Palette99::pick(j).to_rgba();
        move |(x, y): (i32, i32)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], c.filled())
    };
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_labels(12)
        .y_label_formatter(&tick)
        .y_desc(data.y_label)
        .draw()
        .map_err(err)?;
    for (j, (name, vals)) in series.iter().enumerate() {
        chart
            .draw_series(
                vals.iter()
                    .enumerate()
                    .filter(|(_, v)| v.is_finite() && **v > base)
                    .map(|(i, &v)| rect(i, j, v)),
            )
            .map_err(err)?
            .label(name.clone())
            .legend(legend(j));
    }
    if series.len() > 1 {
        legend_upper_left(&mut chart)?;
    }
    // The group names under the axis, centred on their bars.
    for (i, g) in data.groups.iter().enumerate() {
        let (px, py) = chart.backend_coord(&(i as f64, base));
        let style =
            TextStyle::from((FONT, 12).into_font()).pos(plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Center,
                plotters::style::text_anchor::VPos::Top,
            ));
        root.draw_text(g, &style, (px, py + 8)).map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axes_get_one_two_five_ticks_or_finer() {
        // Three decades: 1-2-5.
        let close = |a: Vec<f64>, b: &[f64]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12 * y)
        };
        let t = log_ticks(&(0.15..60.0));
        assert!(
            close(t.clone(), &[0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0]),
            "{t:?}"
        );
        // 1.9 to 9 ms (the curvature chart): every digit.
        let t = log_ticks(&(1.9..9.0));
        assert!(
            close(t.clone(), &[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]),
            "{t:?}"
        );
        // Narrow: round steps inside the range.
        let t = log_ticks(&(0.0412..0.0433));
        assert!(
            t.len() >= 3 && t.iter().all(|v| (0.0412..=0.0433).contains(v)),
            "{t:?}"
        );
        assert!(log_ticks(&(0.0..1.0)).is_empty());
    }

    #[test]
    fn tick_labels_are_short_and_distinct() {
        assert_eq!(tick(&0.1), "0.1");
        assert_eq!(tick(&0.12), "0.12");
        assert_eq!(tick(&0.125), "0.125");
        assert_eq!(tick(&2.0), "2");
        assert_eq!(tick(&1500.0), "1500");
        assert_eq!(tick(&2e-5), "2e-5");
        assert_eq!(tick(&1.5e6), "1.5e6");
        let t = log_ticks(&(0.0412..0.0433));
        let labels: Vec<String> = t.iter().map(tick).collect();
        let mut unique = labels.clone();
        unique.dedup();
        assert_eq!(labels, unique, "{labels:?}");
    }
}
