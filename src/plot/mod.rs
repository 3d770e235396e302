//! Line plots as SVG and PNG, and the deformed tube as PNG ([`tube_png`]), with plotters. Their
//! text is set in DejaVu Sans, compiled into the binary.

mod deformed;
mod font;

pub use deformed::tube_png;

use font::font;

use anyhow::Context;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// One named line.
#[derive(Debug, Clone)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// A named horizontal line across the whole plot (a mean, a reference value).
#[derive(Debug, Clone)]
pub struct Level {
    pub name: String,
    pub y: f64,
}

/// Series with at most this many points get a marker at each: more would hide the line.
const MARKED_UP_TO: usize = 25;

/// Draws `series` and the dashed `levels` as an SVG document in memory (for the service). See
/// [`lines`].
pub fn lines_svg(
    titles: (&str, &str, &str),
    series: &[Series],
    levels: &[Level],
    log: bool,
) -> anyhow::Result<String> {
    let text = font();
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (900, 600)).into_drawing_area();
        draw(&root, titles, series, levels, log, text)?;
    }
    Ok(out)
}

/// A run's load curve as SVG: the load on the moving plate (kN) against its travel (mm), from
/// `points` (travel mm, load N), with the mean load dashed when it is known: the server's
/// `plot.svg` and `crush run`'s `load.svg`.
pub fn load_curve_svg(
    title: &str,
    points: impl IntoIterator<Item = (f64, f64)>,
    mean_load_n: Option<f64>,
) -> anyhow::Result<String> {
    let series = [Series {
        name: "load on the moving plate".into(),
        points: points.into_iter().map(|(u, p)| (u, p / 1000.0)).collect(),
    }];
    let levels: Vec<Level> = mean_load_n
        .map(|n| Level {
            name: format!("mean load {:.3} kN", n / 1000.0),
            y: n / 1000.0,
        })
        .into_iter()
        .collect();
    lines_svg(
        (title, "plate travel, mm", "load, kN"),
        &series,
        &levels,
        false,
    )
}

/// Draws `series` into `<stem>.svg` and `<stem>.png`. `titles` = (title, x label, y label).
/// Both axes are logarithmic when `log` (all values must then be positive).
pub fn lines(
    stem: &Path,
    titles: (&str, &str, &str),
    series: &[Series],
    log: bool,
) -> anyhow::Result<()> {
    let text = font();
    if !text {
        tracing::warn!("the embedded font did not load: plots are drawn without text");
    }
    let svg = stem.with_extension("svg");
    let png = stem.with_extension("png");
    {
        let root = SVGBackend::new(&svg, (900, 600)).into_drawing_area();
        draw(&root, titles, series, &[], log, text)
            .with_context(|| format!("drawing {}", svg.display()))?;
    }
    {
        let root = BitMapBackend::new(&png, (900, 600)).into_drawing_area();
        draw(&root, titles, series, &[], log, text)
            .with_context(|| format!("drawing {}", png.display()))?;
    }
    Ok(())
}

/// One line of the legend: its name, colour, and whether it is drawn dashed (a level).
struct LegendEntry<'a> {
    name: &'a str,
    color: RGBAColor,
    dashed: bool,
}

/// The legend strip's height: a padding and one row per line of entries, px.
const LEGEND_PAD: i32 = 12;
const LEGEND_ROW: i32 = 24;
/// Where the legend starts, and the sample line before each name, px.
const LEGEND_LEFT: i32 = 24;
const LEGEND_SAMPLE: i32 = 30;
const LEGEND_GAP: i32 = 28;

fn legend_font() -> TextStyle<'static> {
    ("sans-serif", 15)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center))
}

/// The entries laid out left to right in rows as wide as `area`: each row, its entries'
/// indices and left edges, px.
fn legend_rows<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
) -> anyhow::Result<Vec<Vec<(usize, i32)>>>
where
    DB::ErrorType: 'static,
{
    let width = area.dim_in_pixel().0 as i32;
    let font = legend_font();
    let mut rows: Vec<Vec<(usize, i32)>> = Vec::new();
    let mut x = LEGEND_LEFT;
    for (k, e) in entries.iter().enumerate() {
        let (w, _) = area
            .estimate_text_size(e.name, &font)
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        let span = LEGEND_SAMPLE + w as i32;
        match rows.last_mut() {
            Some(row) if x + span <= width - LEGEND_LEFT => row.push((k, x)),
            _ => {
                x = LEGEND_LEFT;
                rows.push(vec![(k, x)]);
            }
        }
        x += span + LEGEND_GAP;
    }
    Ok(rows)
}

/// Draws the legend's rows into `area`: a sample of each line (dashed for a level), its name.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    rows: &[Vec<(usize, i32)>],
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let font = legend_font();
    for (r, row) in rows.iter().enumerate() {
        let y = LEGEND_PAD / 2 + LEGEND_ROW * r as i32 + LEGEND_ROW / 2;
        for &(k, x) in row {
            let e = &entries[k];
            let style = e.color.stroke_width(2);
            let pieces: Vec<(i32, i32)> = if e.dashed {
                vec![(x, x + 8), (x + 13, x + 21)]
            } else {
                vec![(x, x + 22)]
            };
            for (a, b) in pieces {
                area.draw(&PathElement::new(vec![(a, y), (b, y)], style))
                    .map_err(|e| anyhow::anyhow!("{e}"))?;
            }
            area.draw_text(e.name, &font, (x + LEGEND_SAMPLE, y))
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
    }
    Ok(())
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    (title, xlabel, ylabel): (&str, &str, &str),
    series: &[Series],
    levels: &[Level],
    log: bool,
    text: bool,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
    let level_points: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.first())
        .flat_map(|&(x, _)| levels.iter().map(move |l| (x, l.y)))
        .collect();
    let all = series
        .iter()
        .flat_map(|s| s.points.iter())
        .chain(&level_points);
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        return Ok(());
    }
    let pad = |a: f64, b: f64| {
        if log {
            (a / 1.3, b * 1.3)
        } else {
            let d = (b - a).abs().max(1e-9) * 0.05;
            (a - d, b + d)
        }
    };
    let ((x0, x1), (y0, y1)) = (pad(x0, x1), pad(y0, y1));
    // The legend goes in a strip of its own under the chart, where it hides no part of a curve
    // (inside the plot, a corner that is empty for one run holds another's last points).
    let entries: Vec<LegendEntry> = if text {
        let lines = series.iter().enumerate().map(|(k, s)| LegendEntry {
            name: &s.name,
            color: Palette99::pick(k).to_rgba(),
            dashed: false,
        });
        let dashed = levels.iter().enumerate().map(|(k, l)| LegendEntry {
            name: &l.name,
            color: Palette99::pick(series.len() + k).to_rgba(),
            dashed: true,
        });
        lines.chain(dashed).collect()
    } else {
        Vec::new()
    };
    let rows = legend_rows(root, &entries)?;
    let chart_area = if rows.is_empty() {
        root.clone()
    } else {
        let height = root.dim_in_pixel().1 as i32;
        let strip = LEGEND_PAD + LEGEND_ROW * rows.len() as i32;
        let (chart_area, strip_area) = root.split_vertically(height - strip);
        draw_legend(&strip_area, &entries, &rows)?;
        chart_area
    };
    let mut builder = ChartBuilder::on(&chart_area);
    builder.margin(20);
    if text {
        builder
            .caption(title, ("sans-serif", 22))
            .x_label_area_size(45)
            .y_label_area_size(70);
    }
    macro_rules! finish {
        ($chart:expr) => {{
            let mut chart = $chart;
            let mut mesh = chart.configure_mesh();
            mesh.bold_line_style(BLACK.mix(0.12))
                .light_line_style(TRANSPARENT)
                .x_labels(10)
                .y_labels(8);
            if text {
                mesh.x_desc(xlabel).y_desc(ylabel);
            } else {
                mesh.disable_x_axis().disable_y_axis();
            }
            mesh.draw().map_err(|e| anyhow::anyhow!("{e}"))?;
            let (left, right) = (x0, x1);
            for (k, s) in series.iter().enumerate() {
                let color = Palette99::pick(k).to_rgba();
                chart
                    .draw_series(LineSeries::new(
                        s.points.iter().copied(),
                        color.stroke_width(2),
                    ))
                    .map_err(|e| anyhow::anyhow!("{e}"))?;
                if s.points.len() <= MARKED_UP_TO {
                    chart
                        .draw_series(s.points.iter().map(|&p| Circle::new(p, 2, color.filled())))
                        .map_err(|e| anyhow::anyhow!("{e}"))?;
                }
            }
            for (k, level) in levels.iter().enumerate() {
                let color = Palette99::pick(series.len() + k).to_rgba();
                let dashed = DashedLineSeries::new(
                    [(left, level.y), (right, level.y)],
                    8,
                    5,
                    color.stroke_width(2),
                );
                chart
                    .draw_series(dashed)
                    .map_err(|e| anyhow::anyhow!("{e}"))?;
            }
        }};
    }
    if log {
        finish!(builder
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|e| anyhow::anyhow!("{e}"))?);
    } else {
        finish!(builder
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| anyhow::anyhow!("{e}"))?);
    }
    root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The (x, y) pixels of the curves' points (polylines of more than two: not the legend's
    /// samples nor a dashed level's pieces), and the y pixel of the text `label`.
    fn drawn(svg: &str, label: &str) -> (Vec<(f64, f64)>, f64) {
        let mut points = Vec::new();
        for part in svg.split("<polyline").skip(1) {
            let list = part.split("points=\"").nth(1).unwrap();
            let line: Vec<(f64, f64)> = list[..list.find('"').unwrap()]
                .split_whitespace()
                .map(|pair| {
                    let (x, y) = pair.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect();
            if line.len() > 2 {
                points.extend(line);
            }
        }
        let text = svg
            .split("<text")
            .find(|t| {
                t.split_once('>')
                    .is_some_and(|(_, rest)| rest.trim_start().starts_with(&format!("{label}\n")))
            })
            .unwrap_or_else(|| panic!("no text {label:?} in {svg}"));
        let y = text.split(" y=\"").nth(1).unwrap();
        (points, y[..y.find('"').unwrap()].parse().unwrap())
    }

    #[test]
    fn the_legend_hides_no_end_of_a_curve_that_ends_low_on_the_right() {
        // The square tube's shape of curve: a first peak, then a low plateau to the end, in the
        // lower right corner, which a legend drawn inside the plot would cover.
        let points: Vec<(f64, f64)> = (0..=400)
            .map(|i| {
                let u = i as f64 * 0.1;
                (u, if u < 2.0 { 7000.0 * u } else { 2500.0 })
            })
            .collect();
        let svg = load_curve_svg("square", points, Some(3000.0)).unwrap();
        let (curve, label_y) = drawn(&svg, "load on the moving plate");
        let (_, mean_y) = drawn(&svg, "mean load 3.000 kN");
        let lowest = curve.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        let end = curve
            .iter()
            .copied()
            .fold((f64::MIN, 0.0), |a, p| if p.0 > a.0 { p } else { a });
        assert!(
            label_y > lowest + 20.0 && mean_y > lowest + 20.0,
            "legend at y {label_y} and {mean_y}, the curve down to {lowest}, ending at {end:?}"
        );
    }
}
