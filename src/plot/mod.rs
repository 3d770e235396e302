//! Line plots as SVG and PNG, and the deformed tube as PNG ([`tube_png`]), with plotters. Their
//! text is set in DejaVu Sans, compiled into the binary.

mod shape;

pub use shape::tube_png;

use anyhow::Context;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

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

/// DejaVu Sans, compiled in (its licence: `assets/fonts/LICENSE-DejaVu.txt`), so that every
/// plot has its text on any machine.
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Registers the embedded font as "sans-serif" once; false only if it would not load.
pub(crate) fn font() -> bool {
    static LOADED: OnceLock<bool> = OnceLock::new();
    *LOADED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()
    })
}

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
    let mut builder = ChartBuilder::on(root);
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
                let drawn = chart
                    .draw_series(LineSeries::new(
                        s.points.iter().copied(),
                        color.stroke_width(2),
                    ))
                    .map_err(|e| anyhow::anyhow!("{e}"))?;
                if text {
                    drawn.label(s.name.as_str()).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
                }
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
                let drawn = chart
                    .draw_series(dashed)
                    .map_err(|e| anyhow::anyhow!("{e}"))?;
                if text {
                    drawn.label(level.name.as_str()).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
                }
            }
            if text {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::LowerRight)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK.mix(0.3))
                    .draw()
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
