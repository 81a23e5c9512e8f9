//! Work-precision charts: log error against log cost, one line per family, and a vertical
//! line at cost = 1 (a plane that costs more than one wall second per simulated second cannot
//! run in real time). SVG only, drawn with plotters.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::point::Point;
use super::sweep::Family;
use crate::error::{BenchError, BenchResult};

const COLORS: [RGBColor; 3] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
];

/// Draws `DIR/accuracy-<scene>.svg` for every scene; returns the paths.
pub fn draw_all(dir: &Path, points: &[Point]) -> BenchResult<Vec<PathBuf>> {
    let mut names: Vec<&str> = points.iter().map(|p| p.scene).collect();
    names.dedup();
    let mut paths = Vec::new();
    for name in names {
        let these: Vec<&Point> = points.iter().filter(|p| p.scene == name).collect();
        let path = dir.join(format!("accuracy-{name}.svg"));
        draw(&path, name, &these)
            .map_err(|e| BenchError::Failed(format!("draw {}: {e}", path.display())))?;
        paths.push(path);
    }
    Ok(paths)
}

/// Errors of exactly 0 cannot sit on a log axis: they are drawn at the axis floor, a decade
/// below the smallest non-zero error (the table keeps the true value).
fn floor_of(points: &[&Point]) -> f64 {
    points
        .iter()
        .map(|p| p.error)
        .filter(|e| e.is_finite() && *e > 0.0)
        .fold(f64::INFINITY, f64::min)
        .clamp(1e-12, 1.0)
        / 10.0
}

fn draw(path: &Path, name: &str, points: &[&Point]) -> Result<(), Box<dyn std::error::Error>> {
    let floor = floor_of(points);
    let shown = |p: &Point| p.error.max(floor);
    let usable: Vec<&&Point> = points
        .iter()
        .filter(|p| p.error.is_finite() && p.cost.is_finite() && p.cost > 0.0)
        .collect();
    let (mut x0, mut x1, mut y1) = (1.0f64, 1.0f64, floor * 10.0);
    for p in &usable {
        x0 = x0.min(p.cost);
        x1 = x1.max(p.cost);
        y1 = y1.max(shown(p));
    }
    let unit = points.first().map_or("", |p| p.error_unit);
    let root = SVGBackend::new(path, (820, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{name}: error vs cost{}",
                if usable.iter().any(|p| p.error == 0.0) {
                    " (error 0 drawn at the bottom edge)"
                } else {
                    ""
                }
            ),
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(72)
        .build_cartesian_2d(
            (x0 / 2.0..x1 * 2.0).log_scale(),
            (floor / 2.0..y1 * 2.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("cost: wall s per simulated s (log)")
        .y_desc(format!("error, {unit} (log)"))
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    let on_a_line = |p: &Point| Family::ALL.iter().any(|f| f.configs().contains(&p.config));
    let others: Vec<(f64, f64)> = usable
        .iter()
        .filter(|p| !on_a_line(p))
        .map(|p| (p.cost, shown(p)))
        .collect();
    if !others.is_empty() {
        let grey = RGBColor(160, 160, 160);
        chart
            .draw_series(
                others
                    .iter()
                    .map(|&(x, y)| Circle::new((x, y), 2, grey.filled())),
            )?
            .label("other grid points")
            .legend(move |(x, y)| Circle::new((x + 10, y), 2, grey.filled()));
    }
    for (family, color) in Family::ALL.iter().zip(COLORS) {
        let line: Vec<(f64, f64)> = family
            .configs()
            .iter()
            .filter_map(|c| usable.iter().find(|p| p.config == *c))
            .map(|p| (p.cost, shown(p)))
            .collect();
        chart
            .draw_series(LineSeries::new(line.clone(), color.stroke_width(2)))?
            .label(family.name())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        chart.draw_series(
            line.iter()
                .map(|&(x, y)| Circle::new((x, y), 3, color.filled())),
        )?;
    }
    let default = usable.iter().find(|p| p.is_default);
    if let Some(d) = default {
        chart
            .draw_series(std::iter::once(Circle::new(
                (d.cost, shown(d)),
                7,
                BLACK.stroke_width(2),
            )))?
            .label("default (60 Hz, 4 it, q1)")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, BLACK.stroke_width(2)));
    }
    chart
        .draw_series(LineSeries::new(
            vec![(1.0, floor / 2.0), (1.0, y1 * 2.0)],
            BLACK.stroke_width(1),
        ))?
        .label("real time (cost = 1)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
