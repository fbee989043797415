//! Pictures of a run (plotters, SVG backend):
//! - `trajectory.svg`: the world (roads, cross-country areas and tracks,
//!   obstacles at time 0, start and goal) and the path driven, coloured by
//!   the samples' label (the system state, or the controller in charge);
//! - `timeline.svg`: the label track, speed (commanded and actual) and
//!   steering angle (commanded and actual) over time.
//!
//! Colours are assigned to labels in order of first appearance, so a run
//! gives the same picture every time.

use crate::metrics::{Metrics, Sample};
use crate::world::{EdgeKind, World};
use plotters::prelude::*;
use std::path::Path;

/// A picture could not be drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotError(pub String);

impl std::fmt::Display for PlotError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "plot: {}", self.0)
    }
}

impl std::error::Error for PlotError {}

/// A plotting backend's error as a [`PlotError`].
pub fn err<E: std::fmt::Debug>(e: E) -> PlotError {
    PlotError(format!("{e:?}"))
}

const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The labels in order of first appearance.
fn labels(samples: &[Sample]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for s in samples {
        if !out.contains(&s.label) {
            out.push(s.label.clone());
        }
    }
    out
}

fn colour(labels: &[String], label: &str) -> RGBColor {
    let i = labels.iter().position(|l| l == label).unwrap_or(0);
    PALETTE[i % PALETTE.len()]
}

/// Runs of consecutive samples with one label: (label, first, last) indices,
/// the last overlapping the next run's first so the path has no gap.
fn runs(samples: &[Sample]) -> Vec<(String, usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=samples.len() {
        if i == samples.len() || samples[i].label != samples[start].label {
            out.push((samples[start].label.clone(), start, i.min(samples.len() - 1)));
            start = i;
        }
    }
    out
}

/// `trajectory.svg`: the world and the path coloured by label.
pub fn trajectory_svg(world: &World, samples: &[Sample], title: &str) -> Result<String, PlotError> {
    let (lo, hi) = world.bounds();
    let (mut lo, mut hi) = (lo, hi);
    for s in samples {
        lo = crate::geom::v2(lo.x.min(s.x - 2.0), lo.y.min(s.y - 2.0));
        hi = crate::geom::v2(hi.x.max(s.x + 2.0), hi.y.max(s.y + 2.0));
    }
    let (w_m, h_m) = ((hi.x - lo.x).max(1.0), (hi.y - lo.y).max(1.0));
    // Equal scales on both axes: the plot area (the picture less the
    // margins, the label areas and the caption) keeps the world's aspect.
    let width = 1200u32;
    let (extra_w, extra_h) = (65u32, 85u32);
    let scale = (width - extra_w) as f64 / w_m;
    let height = ((h_m * scale) as u32 + extra_h).clamp(260, 1400);
    let scale = scale.min((height - extra_h) as f64 / h_m);
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(45)
            .build_cartesian_2d(
                lo.x..lo.x + (width - extra_w) as f64 / scale,
                lo.y..lo.y + (height - extra_h) as f64 / scale,
            )
            .map_err(err)?;
        chart.configure_mesh().x_desc("x (m)").y_desc("y (m)").light_line_style(WHITE).draw().map_err(err)?;
        for a in &world.areas {
            let pts: Vec<(f64, f64)> = a.polygon.iter().map(|p| (p.x, p.y)).collect();
            chart.draw_series(std::iter::once(Polygon::new(pts, RGBColor(214, 230, 190).filled()))).map_err(err)?;
        }
        let road_px = ((world.roads.half_width() * 2.0 * scale) as u32).max(2);
        for e in world.roads.graph.edge_weights() {
            let pts: Vec<(f64, f64)> = e.piece.sample(1.0).iter().map(|p| (p.x, p.y)).collect();
            match e.kind {
                EdgeKind::Road => {
                    chart
                        .draw_series(LineSeries::new(pts.clone(), RGBColor(200, 200, 200).stroke_width(road_px)))
                        .map_err(err)?;
                    chart.draw_series(LineSeries::new(pts, RGBColor(255, 255, 255).stroke_width(1))).map_err(err)?;
                }
                EdgeKind::CrossCountry => {
                    chart
                        .draw_series(DashedLineSeries::new(pts, 6, 4, RGBColor(150, 110, 60).stroke_width(1)))
                        .map_err(err)?;
                }
            }
        }
        let mut views = Vec::new();
        world.obstacles_at(0.0, &mut views);
        for o in &views {
            let pts: Vec<(f64, f64)> = o.polygon.iter().map(|p| (p.x, p.y)).collect();
            let c = if o.height > world.vehicle.clearance { RGBColor(60, 60, 60) } else { RGBColor(170, 170, 170) };
            chart.draw_series(std::iter::once(Polygon::new(pts, c.filled()))).map_err(err)?;
        }
        let labs = labels(samples);
        let mut legend_done: Vec<String> = Vec::new();
        for (label, a, b) in runs(samples) {
            let c = colour(&labs, &label);
            let pts: Vec<(f64, f64)> = samples[a..=b].iter().map(|s| (s.x, s.y)).collect();
            let series = chart.draw_series(LineSeries::new(pts, c.stroke_width(2))).map_err(err)?;
            if !legend_done.contains(&label) {
                series
                    .label(label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(3)));
                legend_done.push(label);
            }
        }
        let start = (world.start.x, world.start.y);
        let goal = (world.goal.position.x, world.goal.position.y);
        chart
            .draw_series(std::iter::once(Circle::new(start, 5, BLACK.filled())))
            .map_err(err)?
            .label("start")
            .legend(|(x, y)| Circle::new((x + 10, y), 4, BLACK.filled()));
        chart
            .draw_series(std::iter::once(TriangleMarker::new(goal, 8, RED.filled())))
            .map_err(err)?
            .label("goal")
            .legend(|(x, y)| TriangleMarker::new((x + 10, y), 6, RED.filled()));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(buf)
}

/// `timeline.svg`: the label track, speed and steering over time.
pub fn timeline_svg(samples: &[Sample], title: &str) -> Result<String, PlotError> {
    let t_end = samples.last().map_or(1.0, |s| s.t.max(1.0));
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (1200, 720)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
        let (track, rest) = root.split_vertically(110);
        let (speed, steer) = rest.split_vertically(290);
        let labs = labels(samples);
        // The label track.
        let mut chart = ChartBuilder::on(&track)
            .margin(10)
            .x_label_area_size(20)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t_end, 0.0..1.0)
            .map_err(err)?;
        chart.configure_mesh().disable_y_mesh().disable_y_axis().light_line_style(WHITE).draw().map_err(err)?;
        for (label, a, b) in runs(samples) {
            let c = colour(&labs, &label);
            let (t0, t1) = (samples[a].t, samples[b].t.max(samples[a].t + 1e-3));
            chart.draw_series(std::iter::once(Rectangle::new([(t0, 0.0), (t1, 1.0)], c.filled()))).map_err(err)?;
            let px_per_s = 1100.0 / t_end;
            if (t1 - t0) * px_per_s > 8.0 * label.len() as f64 {
                chart
                    .draw_series(std::iter::once(Text::new(
                        label.clone(),
                        (t0 + 0.3 / px_per_s * 10.0, 0.7),
                        ("sans-serif", 13).into_font().color(&WHITE),
                    )))
                    .map_err(err)?;
            }
        }
        // Speed.
        let vmax = samples.iter().map(|s| s.v.max(s.v_cmd)).fold(0.5, f64::max) * 1.1;
        let mut chart = ChartBuilder::on(&speed)
            .margin(10)
            .x_label_area_size(25)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t_end, 0.0..vmax)
            .map_err(err)?;
        chart.configure_mesh().y_desc("speed (m/s)").draw().map_err(err)?;
        chart
            .draw_series(LineSeries::new(samples.iter().map(|s| (s.t, s.v_cmd)), PALETTE[0].stroke_width(1)))
            .map_err(err)?
            .label("command")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], PALETTE[0].stroke_width(2)));
        chart
            .draw_series(LineSeries::new(samples.iter().map(|s| (s.t, s.v)), PALETTE[3].stroke_width(2)))
            .map_err(err)?
            .label("actual")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], PALETTE[3].stroke_width(2)));
        chart.configure_series_labels().background_style(WHITE.mix(0.85)).border_style(BLACK).draw().map_err(err)?;
        // Steering.
        let gmax = samples.iter().map(|s| s.steer.abs().max(s.steer_cmd.abs())).fold(0.05, f64::max) * 1.1;
        let mut chart = ChartBuilder::on(&steer)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t_end, -gmax..gmax)
            .map_err(err)?;
        chart.configure_mesh().x_desc("time (s)").y_desc("steering γ (rad)").draw().map_err(err)?;
        chart
            .draw_series(LineSeries::new(samples.iter().map(|s| (s.t, s.steer_cmd)), PALETTE[0].stroke_width(1)))
            .map_err(err)?
            .label("command")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], PALETTE[0].stroke_width(2)));
        chart
            .draw_series(LineSeries::new(samples.iter().map(|s| (s.t, s.steer)), PALETTE[3].stroke_width(2)))
            .map_err(err)?
            .label("actual")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], PALETTE[3].stroke_width(2)));
        chart.configure_series_labels().background_style(WHITE.mix(0.85)).border_style(BLACK).draw().map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(buf)
}

/// Writes `metrics.json`, `trajectory.svg` and `timeline.svg` of a run into
/// a directory (created if needed).
pub fn write_run(dir: &Path, world: &World, metrics: &Metrics) -> Result<(), PlotError> {
    std::fs::create_dir_all(dir).map_err(|e| PlotError(format!("{}: {e}", dir.display())))?;
    let title = format!("{} — {}", metrics.scenario, metrics.controller);
    let write = |name: &str, text: &str| {
        std::fs::write(dir.join(name), text).map_err(|e| PlotError(format!("{}: {e}", dir.join(name).display())))
    };
    write("metrics.json", &metrics.to_json())?;
    write("trajectory.svg", &trajectory_svg(world, &metrics.samples, &title)?)?;
    write("timeline.svg", &timeline_svg(&metrics.samples, &title)?)?;
    Ok(())
}
