//! Error against time on log-log axes, one line per knob, one panel per scene.

use super::sweep::SceneResult;
use plotters::prelude::*;

const KNOBS: [(&str, RGBColor); 7] = [
    ("spp", RGBColor(31, 119, 180)),
    ("depth", RGBColor(255, 127, 14)),
    ("cutoff", RGBColor(44, 160, 44)),
    ("soft", RGBColor(214, 39, 40)),
    ("probe", RGBColor(23, 190, 207)),
    ("tree", RGBColor(148, 103, 189)),
    ("texture", RGBColor(140, 86, 75)),
];

/// The SVG as a string (the caller writes it atomically). Text is left to the SVG
/// viewer's fonts: no system fonts are read here.
pub fn svg(results: &[SceneResult]) -> Result<String, String> {
    let mut out = String::new();
    let panels = results.len().max(1);
    {
        let root =
            SVGBackend::with_string(&mut out, (520 * panels as u32, 420)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let areas = root.split_evenly((1, panels));
        for (area, r) in areas.iter().zip(results) {
            let pts: Vec<(f64, f64)> = r
                .points
                .iter()
                .map(|p| (p.seconds.max(1e-6), p.errors.rmse.max(1e-6)))
                .collect();
            let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, 0.0f64, f64::MAX, 0.0f64);
            for &(x, y) in &pts {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
            if pts.is_empty() {
                (x0, x1, y0, y1) = (1e-3, 1.0, 1e-3, 1.0);
            }
            let mut chart = ChartBuilder::on(area)
                .caption(format!("{}: RMSE vs time", r.scene), ("sans-serif", 16))
                .margin(10)
                .x_label_area_size(35)
                .y_label_area_size(55)
                .build_cartesian_2d(
                    (x0 / 1.5..x1 * 1.5).log_scale(),
                    (y0 / 1.5..y1 * 1.5).log_scale(),
                )
                .map_err(|e| e.to_string())?;
            chart
                .configure_mesh()
                .x_desc("render seconds (median)")
                .y_desc("RMSE (HDR)")
                .x_label_formatter(&|v| format!("{v:.2e}"))
                .y_label_formatter(&|v| format!("{v:.1e}"))
                .draw()
                .map_err(|e| e.to_string())?;
            for (knob, colour) in KNOBS {
                let mut line: Vec<(f64, f64)> = r
                    .points
                    .iter()
                    .filter(|p| p.knob == knob)
                    .map(|p| (p.seconds.max(1e-6), p.errors.rmse.max(1e-6)))
                    .collect();
                if line.is_empty() {
                    continue;
                }
                line.sort_by(|a, b| a.0.total_cmp(&b.0));
                chart
                    .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
                    .map_err(|e| e.to_string())?
                    .label(knob)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                    });
                chart
                    .draw_series(line.into_iter().map(|p| Circle::new(p, 3, colour.filled())))
                    .map_err(|e| e.to_string())?;
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(|e| e.to_string())?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(out)
}
