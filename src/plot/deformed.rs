//! The deformed tube as a PNG: the final particle positions, each a square of 1.3 particle
//! spacings (which closes the gaps of stretched regions), coloured by equivalent plastic strain
//! (viridis, 0 to the 99th percentile; the far side darkened in the whole-tube views), seen
//! from three directions: the side, an oblique view from above, and a section through the axis
//! that shows the wall's fold profile (axial) or the flattened ring (lateral). Orthographic
//! projection, far particles drawn first. The side and section views show the plates where
//! the crush left them, and every view has a scale bar in mm. Lengths in mm.

use super::font::font;
use crate::solver::model::case::{Geometry, LoadingMode, Model, Outline};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;

/// What to draw.
#[derive(Debug, Clone, Copy)]
struct TubeShape<'a> {
    title: &'a str,
    /// Final positions, mm (plates are normal to z).
    position_mm: &'a [[f32; 3]],
    plastic_strain: &'a [f32],
    /// Particle spacing h, mm: the side of each drawn square.
    spacing_mm: f64,
    /// A reduced model's own section, drawn (squares of `spacing_mm`) in the section view in
    /// place of a cut through `position_mm`, which is then the revolved or extruded tube drawn
    /// in squares of `whole_spacing_mm`. None for 3D.
    section: Option<Cut<'a>>,
    whole_spacing_mm: f64,
    /// The tube axis is x (lateral loading) rather than z (axial).
    axis_x: bool,
    /// Where the plates (normal to z) ended, bottom and top, mm; `None`: not drawn.
    plates_z: Option<[f64; 2]>,
}

const SIZE: (u32, u32) = (1280, 520);
const TITLE_PX: i32 = 44;
const LABEL_PX: i32 = 30;
const BAR_PX: i32 = 110;

/// Particles in a plane, with their strains.
#[derive(Debug, Clone, Copy)]
struct Cut<'a> {
    position_mm: &'a [[f32; 3]],
    plastic_strain: &'a [f32],
}

/// A direction to look from: screen right and up, and an optional slab (normal, half width in
/// spacings) that keeps only the particles near the centre plane.
struct View {
    name: &'static str,
    right: [f64; 3],
    up: [f64; 3],
    slab: Option<([f64; 3], f64)>,
    /// Up is z: the plates show edge-on, as bars.
    plates: bool,
}

fn views(axis_x: bool) -> [View; 3] {
    let (az, el) = (35f64.to_radians(), 25f64.to_radians());
    // Looking along f = (sin az cos el, cos az cos el, −sin el): right = f × z, up = right × f.
    let f = [az.sin() * el.cos(), az.cos() * el.cos(), -el.sin()];
    let right = normalize(cross(f, [0.0, 0.0, 1.0]));
    let up = cross(right, f);
    let section = if axis_x {
        View {
            name: "section across the axis (x = middle)",
            right: [0.0, -1.0, 0.0],
            up: [0.0, 0.0, 1.0],
            slab: Some(([1.0, 0.0, 0.0], 1.5)),
            plates: true,
        }
    } else {
        View {
            name: "section through the axis (y = 0)",
            right: [1.0, 0.0, 0.0],
            up: [0.0, 0.0, 1.0],
            slab: Some(([0.0, 1.0, 0.0], 1.5)),
            plates: true,
        }
    };
    [
        View {
            name: "side",
            right: [1.0, 0.0, 0.0],
            up: [0.0, 0.0, 1.0],
            slab: None,
            plates: true,
        },
        View {
            name: "oblique, from above",
            right,
            up,
            slab: None,
            plates: false,
        },
        section,
    ]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

/// The top of the colour scale: the 99th percentile of the plastic strain (a few particles at
/// the plate edges would otherwise wash out the folds), at least 1e-6.
fn strain_scale(strain: &[f32]) -> f64 {
    strain_percentile(strain).max(MIN_SCALE)
}

/// The bottom of the colour scale's top: below it the tube has not yielded.
const MIN_SCALE: f64 = 1e-6;

fn strain_percentile(strain: &[f32]) -> f64 {
    let mut finite: Vec<f32> = strain.iter().copied().filter(|e| e.is_finite()).collect();
    if finite.is_empty() {
        return 0.0;
    }
    let k = ((finite.len() - 1) as f64 * 0.99).round() as usize;
    let (_, top, _) = finite.select_nth_unstable_by(k, f32::total_cmp);
    *top as f64
}

/// The picture of a tube of `geometry` in its final state after a crush of `crush_mm` (`title`
/// over it), as PNG bytes.
pub fn tube_png(
    geometry: &Geometry,
    crush_mm: f64,
    title: &str,
    position_mm: &[[f32; 3]],
    plastic_strain: &[f32],
) -> anyhow::Result<Vec<u8>> {
    anyhow::ensure!(
        position_mm.len() == plastic_strain.len(),
        "{} positions but {} strains",
        position_mm.len(),
        plastic_strain.len()
    );
    let model = geometry.model;
    let h = geometry.spacing_mm();
    let axis_x = geometry.mode == LoadingMode::Lateral;
    let plates_z = Some(final_plates(geometry, crush_mm));
    if model == Model::ThreeD {
        return shape_png(&TubeShape {
            title,
            position_mm,
            plastic_strain,
            spacing_mm: h,
            section: None,
            whole_spacing_mm: h,
            axis_x,
            plates_z,
        });
    }
    let (whole, whole_strain, whole_spacing) = whole_tube(geometry, position_mm, plastic_strain);
    // The axisymmetric section through the axis shows both walls: the section and its mirror.
    let (mut cut, mut cut_strain) = (position_mm.to_vec(), plastic_strain.to_vec());
    if model == Model::Axisymmetric {
        cut.extend(position_mm.iter().map(|p| [-p[0], p[1], p[2]]));
        cut_strain.extend_from_slice(plastic_strain);
    }
    let how = match model {
        Model::Axisymmetric => "axisymmetric section, revolved",
        _ => "plane-strain section, extruded",
    };
    shape_png(&TubeShape {
        title: &format!("{title} ({how})"),
        position_mm: &whole,
        plastic_strain: &whole_strain,
        spacing_mm: h,
        section: Some(Cut {
            position_mm: &cut,
            plastic_strain: &cut_strain,
        }),
        whole_spacing_mm: whole_spacing,
        axis_x,
        plates_z,
    })
}

/// Where the plates stand once the crush is done, bottom and top, mm: the bottom one where it
/// started (it does not move), the top one the crush distance lower (the scene's start: axial,
/// 0 and the length; lateral, ∓ the outer radius).
fn final_plates(geometry: &Geometry, crush_mm: f64) -> [f64; 2] {
    let (top, bottom) = geometry.plates_z();
    [bottom, top - crush_mm]
}

/// Most points a reduced model's picture draws of the whole tube.
const WHOLE_TUBE_POINTS: usize = 250_000;

/// A reduced model's section as the tube it stands for: revolved about the axis
/// (axisymmetric; positions (r, 0, z)) or extruded along x (plane strain; positions
/// (l/2, y, z)), in copies about a particle spacing apart up to [`WHOLE_TUBE_POINTS`] in all.
/// Also the side of the squares that close the gaps between copies, mm.
fn whole_tube(
    geometry: &Geometry,
    position: &[[f32; 3]],
    strain: &[f32],
) -> (Vec<[f32; 3]>, Vec<f32>, f64) {
    let (h, d, l) = (
        geometry.spacing_mm(),
        geometry.section.width_mm(),
        geometry.length_mm,
    );
    let budget = (WHOLE_TUBE_POINTS / position.len().max(1)).max(2);
    let axisymmetric = geometry.model == Model::Axisymmetric;
    let copies = if axisymmetric {
        ((std::f64::consts::TAU * d / h).round() as usize).clamp(2, budget)
    } else {
        ((l / h).round() as usize).clamp(1, budget)
    };
    let reach = position
        .iter()
        .map(|p| p[0].abs() as f64)
        .fold(0.5 * d, f64::max);
    let gap = if axisymmetric {
        std::f64::consts::TAU * reach / copies as f64
    } else {
        l / copies as f64
    };
    let mut x = Vec::with_capacity(copies * position.len());
    let mut e = Vec::with_capacity(copies * position.len());
    for k in 0..copies {
        let share = k as f64 / copies as f64;
        let (sin, cos) = (std::f64::consts::TAU * share).sin_cos();
        let (sin, cos) = (sin as f32, cos as f32);
        let along = (l * (k as f64 + 0.5) / copies as f64) as f32;
        for (p, &strain) in position.iter().zip(strain) {
            x.push(if axisymmetric {
                [p[0] * cos, p[0] * sin, p[2]]
            } else {
                [along, p[1], p[2]]
            });
            e.push(strain);
        }
    }
    (x, e, gap.max(h))
}

/// The picture as PNG bytes.
fn shape_png(shape: &TubeShape) -> anyhow::Result<Vec<u8>> {
    anyhow::ensure!(
        shape.position_mm.len() == shape.plastic_strain.len(),
        "{} positions but {} strains",
        shape.position_mm.len(),
        shape.plastic_strain.len()
    );
    let (w, h) = SIZE;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area();
        draw(&root, shape).map_err(|e| anyhow::anyhow!("{e}"))?;
        root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    let mut png = Vec::new();
    use image::ImageEncoder;
    image::codecs::png::PngEncoder::new(&mut png).write_image(
        &buf,
        w,
        h,
        image::ColorType::Rgb8,
    )?;
    Ok(png)
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult =
    Result<(), DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>>;

fn draw(root: &Area, shape: &TubeShape) -> DrawResult {
    let text = font();
    let (w, h) = SIZE;
    let top = strain_scale(shape.plastic_strain);
    if text {
        root.draw(&Text::new(
            shape.title.to_string(),
            (16, 12),
            ("sans-serif", 22).into_font(),
        ))?;
    }
    let panels_w = w as i32 - BAR_PX;
    let views = views(shape.axis_x);
    let panel_w = panels_w / views.len() as i32;
    for (k, view) in views.iter().enumerate() {
        let x0 = k as i32 * panel_w;
        let area = root
            .clone()
            .shrink((x0, TITLE_PX), (panel_w as u32, h - TITLE_PX as u32));
        let (points, strain, spacing, slab) = match (view.slab, shape.section) {
            (Some(_), Some(cut)) => (cut.position_mm, cut.plastic_strain, shape.spacing_mm, None),
            (slab, _) => (
                shape.position_mm,
                shape.plastic_strain,
                if slab.is_some() {
                    shape.spacing_mm
                } else {
                    shape.whole_spacing_mm
                },
                slab,
            ),
        };
        let shown = Shown {
            position_mm: points,
            plastic_strain: strain,
            spacing_mm: spacing,
            slab,
            plates_z: shape.plates_z.filter(|_| view.plates),
        };
        draw_view(&area, &shown, view, top, text)?;
    }
    let bar = root
        .clone()
        .shrink((panels_w, TITLE_PX), (BAR_PX as u32, h - TITLE_PX as u32));
    colour_bar(&bar, top, text)
}

/// What one view draws: its points, their squares' side, and the slab that cuts them, if any.
struct Shown<'a> {
    position_mm: &'a [[f32; 3]],
    plastic_strain: &'a [f32],
    spacing_mm: f64,
    slab: Option<([f64; 3], f64)>,
    /// The plates' z, bottom and top, when this view shows them.
    plates_z: Option<[f64; 2]>,
}

/// Pixels of a plate's bar, across.
const PLATE_PX: i32 = 6;

/// A blue-grey that neither the strain scale nor anti-aliased text produces.
const PLATE_COLOUR: RGBColor = RGBColor(112, 118, 128);

fn draw_view(area: &Area, shape: &Shown, view: &View, top: f64, text: bool) -> DrawResult {
    let (pw, ph) = area.dim_in_pixel();
    let toward = cross(view.right, view.up);
    let centre = centroid(shape.position_mm);
    let spacing = shape.spacing_mm;
    // (screen x, screen y, depth towards the viewer, strain) of every particle shown.
    let mut points: Vec<(f64, f64, f64, f32)> = shape
        .position_mm
        .iter()
        .zip(shape.plastic_strain)
        .filter_map(|(x, &e)| {
            let x = [x[0] as f64, x[1] as f64, x[2] as f64];
            if let Some((normal, half)) = shape.slab {
                let off = [x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]];
                if dot(off, normal).abs() > half * spacing {
                    return None;
                }
            }
            Some((dot(x, view.right), dot(x, view.up), dot(x, toward), e))
        })
        .filter(|p| p.0.is_finite() && p.1.is_finite() && p.2.is_finite())
        .collect();
    if text {
        area.draw(&Text::new(
            view.name.to_string(),
            (10, ph as i32 - LABEL_PX + 6),
            ("sans-serif", 16).into_font(),
        ))?;
    }
    if points.is_empty() {
        return Ok(());
    }
    points.sort_unstable_by(|a, b| a.2.total_cmp(&b.2));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in &points {
        x0 = x0.min(p.0);
        x1 = x1.max(p.0);
        y0 = y0.min(p.1);
        y1 = y1.max(p.1);
    }
    if let Some([bottom, top]) = shape.plates_z {
        y0 = y0.min(bottom);
        y1 = y1.max(top);
    }
    let margin = 16.0 + PLATE_PX as f64;
    let (room_w, room_h) = (
        pw as f64 - 2.0 * margin,
        ph as f64 - LABEL_PX as f64 - 2.0 * margin,
    );
    let scale = (room_w / (x1 - x0 + spacing)).min(room_h / (y1 - y0 + spacing));
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let half = (0.65 * spacing * scale).max(0.6);
    let (ox, oy) = (pw as f64 / 2.0, margin + room_h / 2.0);
    // Depth cue in the whole-tube views: the far side darker, so the shape reads as 3D.
    let (d0, d1) = (points[0].2, points[points.len() - 1].2);
    let cue = |d: f64| match view.slab {
        Some(_) => 1.0,
        None if d1 > d0 => 0.55 + 0.45 * (d - d0) / (d1 - d0),
        None => 1.0,
    };
    for (sx, sy, depth, e) in points {
        let px = ox + (sx - cx) * scale;
        let py = oy - (sy - cy) * scale;
        let c = ViridisRGB.get_color_normalized(e.max(0.0).min(top as f32), 0.0, top as f32);
        let k = cue(depth);
        let shade = |v: u8| (v as f64 * k).round() as u8;
        let colour = RGBColor(shade(c.0), shade(c.1), shade(c.2));
        let a = ((px - half).round() as i32, (py - half).round() as i32);
        let b = ((px + half).round() as i32, (py + half).round() as i32);
        area.draw(&Rectangle::new([a, b], colour.filled()))?;
    }
    if let Some([bottom, top]) = shape.plates_z {
        let grey = PLATE_COLOUR.filled();
        let reach = 0.5 * (x1 - x0) + spacing;
        let (left, right) = (
            (ox - reach * scale).round() as i32,
            (ox + reach * scale).round() as i32,
        );
        let screen = |z: f64| (oy - (z - cy) * scale).round() as i32;
        let (yb, yt) = (screen(bottom), screen(top));
        area.draw(&Rectangle::new([(left, yb), (right, yb + PLATE_PX)], grey))?;
        area.draw(&Rectangle::new([(left, yt - PLATE_PX), (right, yt)], grey))?;
    }
    scale_bar(area, scale, text)
}

/// A "nice" length (1, 2 or 5 × 10^k mm) near `target` mm.
fn nice_length(target: f64) -> f64 {
    let decade = 10f64.powf(target.log10().floor());
    let m = target / decade;
    let nice = if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    };
    nice * decade
}

/// A bar of a round number of millimetres at the view's lower right, `scale` px a mm.
fn scale_bar(area: &Area, scale: f64, text: bool) -> DrawResult {
    if !(scale.is_finite() && scale > 0.0) {
        return Ok(());
    }
    let (pw, ph) = area.dim_in_pixel();
    let mm = nice_length(0.2 * pw as f64 / scale);
    let len = (mm * scale).round() as i32;
    let (x1, y) = (pw as i32 - 14, ph as i32 - LABEL_PX + 14);
    let x0 = x1 - len;
    let ink = BLACK.filled();
    area.draw(&Rectangle::new([(x0, y), (x1, y + 3)], ink))?;
    for x in [x0, x1 - 2] {
        area.draw(&Rectangle::new([(x, y - 5), (x + 2, y + 3)], ink))?;
    }
    if text {
        let label = if mm >= 1.0 {
            format!("{mm:.0} mm")
        } else {
            format!("{mm} mm")
        };
        let style = TextStyle::from(("sans-serif", 14).into_font());
        let (w, _) = area.estimate_text_size(&label, &style)?;
        let at = (x0 + (len - w as i32) / 2, y - 20);
        area.draw(&Text::new(label, at, style))?;
    }
    Ok(())
}

fn centroid(x: &[[f32; 3]]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for p in x {
        for k in 0..3 {
            c[k] += p[k] as f64;
        }
    }
    let n = x.len().max(1) as f64;
    [c[0] / n, c[1] / n, c[2] / n]
}

fn colour_bar(area: &Area, top: f64, text: bool) -> DrawResult {
    let (_, ph) = area.dim_in_pixel();
    let (bx, by0, by1) = (14, 30, ph as i32 - LABEL_PX - 20);
    let steps = (by1 - by0).max(1);
    for k in 0..steps {
        let f = 1.0 - k as f64 / steps as f64;
        let colour = ViridisRGB.get_color(f as f32);
        area.draw(&Rectangle::new(
            [(bx, by0 + k), (bx + 22, by0 + k + 1)],
            colour.filled(),
        ))?;
    }
    if text {
        let font = ("sans-serif", 14).into_font();
        let name = if top <= MIN_SCALE {
            "no plastic strain"
        } else {
            "plastic strain"
        };
        area.draw(&Text::new(name, (4, 8), font.clone()))?;
        for f in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let y = by1 - (f * steps as f64) as i32 - 7;
            let value = f * top;
            let text = if top < 0.01 {
                format!("{value:.1e}")
            } else {
                format!("{value:.3}")
            };
            let label = if f == 1.0 { format!("≥{text}") } else { text };
            area.draw(&Text::new(label, (bx + 28, y), font.clone()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strained band at mid-height of an otherwise unstrained tube.
    fn tube() -> (Vec<[f32; 3]>, Vec<f32>) {
        let mut x = Vec::new();
        let mut e = Vec::new();
        for k in 0..40 {
            for j in 0..60 {
                let a = j as f32 / 60.0 * std::f32::consts::TAU;
                x.push([10.0 * a.cos(), 10.0 * a.sin(), k as f32]);
                e.push(if (18..22).contains(&k) { 0.5 } else { 0.0 });
            }
        }
        (x, e)
    }

    #[test]
    fn the_picture_is_a_png_with_the_strained_band_in_the_hot_colour() {
        let (x, e) = tube();
        let png = shape_png(&TubeShape {
            title: "test",
            position_mm: &x,
            plastic_strain: &e,
            spacing_mm: 1.0,
            section: None,
            whole_spacing_mm: 1.0,
            axis_x: false,
            plates_z: None,
        })
        .unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        let hot = ViridisRGB.get_color(1.0);
        let cold = ViridisRGB.get_color(0.0);
        let count = |c: RGBColor| img.pixels().filter(|p| p.0 == [c.0, c.1, c.2]).count();
        // Both ends of the scale are drawn, and the band (4 of 40 layers) is a minority.
        let (h, c) = (count(hot), count(cold));
        assert!(h > 500 && c > 5 * h, "hot {h} px, cold {c} px");
    }

    #[test]
    fn the_scale_bar_is_a_round_number_of_millimetres() {
        for (target, nice) in [
            (0.7, 0.5),
            (1.2, 1.0),
            (3.0, 2.0),
            (4.0, 5.0),
            (8.0, 10.0),
            (23.0, 20.0),
        ] {
            assert!(
                (nice_length(target) - nice).abs() < 1e-12,
                "{target} → {nice}"
            );
        }
    }

    #[test]
    fn the_plates_end_a_crush_distance_apart_from_where_they_started() {
        use crate::solver::{Case, Limits};
        let axial = Case::from_json(
            r#"{"tube": {"length_mm": 50}, "loading": {"crush_distance_mm": 10}}"#,
            &Limits::default(),
        )
        .unwrap();
        assert_eq!(final_plates(axial.geometry(), 10.0), [0.0, 40.0]);
        let lateral = Case::from_json(
            r#"{"tube": {"thickness_mm": 2, "mean_diameter_mm": 20},
                "loading": {"mode": "lateral", "crush_distance_mm": 5}}"#,
            &Limits::default(),
        )
        .unwrap();
        assert_eq!(final_plates(lateral.geometry(), 5.0), [-11.0, 6.0]);
    }

    #[test]
    fn the_side_view_draws_the_plates_in_grey() {
        let (x, e) = tube();
        let grey = |plates_z| {
            let png = shape_png(&TubeShape {
                title: "",
                position_mm: &x,
                plastic_strain: &e,
                spacing_mm: 1.0,
                section: None,
                whole_spacing_mm: 1.0,
                axis_x: false,
                plates_z,
            })
            .unwrap();
            let img = image::load_from_memory(&png).unwrap().to_rgb8();
            let c = PLATE_COLOUR;
            img.pixels().filter(|p| p.0 == [c.0, c.1, c.2]).count()
        };
        assert_eq!(grey(None), 0);
        assert!(grey(Some([-0.5, 39.5])) > 1000);
    }

    #[test]
    fn the_scale_ignores_the_top_percent() {
        let mut e = vec![0.1f32; 1000];
        e[0] = 50.0;
        assert!((strain_scale(&e) - 0.1).abs() < 1e-6);
        assert_eq!(strain_scale(&[]), 1e-6);
        assert_eq!(strain_scale(&[f32::NAN]), 1e-6);
    }

    /// A reduced model's section is drawn as the tube it stands for: revolved into copies
    /// around the axis (at most the budget of points), or extruded along it.
    #[test]
    fn a_section_is_drawn_as_its_whole_tube() {
        use crate::solver::{Case, Limits};
        for text in [
            r#"{"discretization": {"model": "axisymmetric", "particles_through_thickness": 2}}"#,
            r#"{"loading": {"mode": "lateral"}, "discretization": {"model": "plane_strain"}}"#,
        ] {
            let case = Case::from_json(text, &Limits::default()).unwrap();
            let x: Vec<[f32; 3]> = case
                .geometry()
                .positions()
                .iter()
                .map(|p| p.map(|v| v as f32))
                .collect();
            let e = vec![0.5f32; x.len()];
            let (whole, strain, gap) = whole_tube(case.geometry(), &x, &e);
            assert!(
                whole.len() > 10 * x.len() && whole.len() <= WHOLE_TUBE_POINTS,
                "{text}"
            );
            assert_eq!(strain.len(), whole.len());
            assert!(gap >= case.spacing_mm(), "{text}");
            // Every copy of a section point lies at its radius from the axis.
            let axial = text.contains("axisym");
            for (p, q) in whole.iter().zip(x.iter().cycle()) {
                if axial {
                    assert!((p[0].hypot(p[1]) - q[0]).abs() < 1e-4);
                } else {
                    assert_eq!((p[1], p[2]), (q[1], q[2]));
                }
            }
            let png = tube_png(case.geometry(), case.crush_distance_mm(), "t", &x, &e).unwrap();
            assert!(image::load_from_memory(&png).is_ok());
        }
    }

    #[test]
    fn mismatched_arrays_are_refused() {
        let (x, _) = tube();
        assert!(shape_png(&TubeShape {
            title: "",
            position_mm: &x,
            plastic_strain: &[0.0],
            spacing_mm: 1.0,
            section: None,
            whole_spacing_mm: 1.0,
            axis_x: false,
            plates_z: None,
        })
        .is_err());
    }
}
