//! The plot of a traced homing (`motionctl trace --plot`): velocity against
//! position, the way Logix homing manuals draw homing sequences — each leg a
//! line, the home event and the switch and marker edges marked.

use crate::{canvas, failed};
use motion_report::TraceRow;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
type Drawn = Result<(), DrawingAreaErrorKind<std::io::Error>>;

const PHASE_COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];
const COMMAND_GREY: RGBColor = RGBColor(170, 170, 170);

/// What the plot spans: the positions and velocities of the feedback, and
/// the margins around them.
struct Area {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    padx: f64,
    pady: f64,
}

impl Area {
    /// `None` when no row has feedback.
    fn of(rows: &[TraceRow]) -> Option<Self> {
        let pts = rows.iter().filter_map(|r| Some((r.position?, r.velocity?)));
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, 0.0f64, 0.0f64);
        let mut any = false;
        for (x, y) in pts {
            any = true;
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        if !any {
            return None;
        }
        // The velocity axis spans what the sequence commanded (with a margin):
        // a cycle in which the I/O process skipped commands shows as a spike of
        // the actual velocity, drawn clipped at the edge rather than squashing
        // the legs the plot is about.
        let (c0, c1) = rows
            .iter()
            .filter_map(|r| r.cmd_velocity)
            .fold((0.0f64, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
        if c1 > c0 {
            let m = 0.3 * (c1 - c0);
            y0 = y0.max(c0 - m);
            y1 = y1.min(c1 + m);
        }
        let padx = ((x1 - x0) * 0.05).max(1e-3);
        let pady = ((y1 - y0) * 0.1).max(1e-3);
        Some(Self {
            x0,
            x1,
            y0,
            y1,
            padx,
            pady,
        })
    }

    /// The lowest and highest velocity drawn.
    fn bottom(&self) -> f64 {
        self.y0 - self.pady
    }
    fn top(&self) -> f64 {
        self.y1 + self.pady
    }
}

/// Draws `rows` of axis `axis` into `path` (SVG).
pub fn draw(rows: &[TraceRow], axis: &str, path: &Path) -> Result<(), String> {
    let area = Area::of(rows).ok_or("the trace has no feedback to plot")?;
    let e = |x: &dyn std::fmt::Display| failed(path, x);
    let root = canvas(path, (1000, 500))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{axis}: velocity against position during homing"),
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(
            (area.x0 - area.padx)..(area.x1 + area.padx),
            area.bottom()..area.top(),
        )
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("raw position (units)")
        .y_desc("velocity (units/s)")
        .draw()
        .map_err(|x| e(&x))?;
    draw_command(&mut chart, rows).map_err(|x| e(&x))?;
    draw_legs(&mut chart, rows, &area).map_err(|x| e(&x))?;
    draw_edges(&mut chart, rows, &area).map_err(|x| e(&x))?;
    draw_event(&mut chart, rows, &area).map_err(|x| e(&x))?;
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))?;
    Ok(())
}

/// The commanded profile, thin and grey, under the actual motion.
fn draw_command(chart: &mut Chart<'_, '_>, rows: &[TraceRow]) -> Drawn {
    let cmd: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| Some((r.cmd_position?, r.cmd_velocity?)))
        .collect();
    chart
        .draw_series(LineSeries::new(cmd, COMMAND_GREY.stroke_width(1)))?
        .label("command")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], COMMAND_GREY));
    Ok(())
}

/// One line per leg (consecutive rows of the same phase), one colour and
/// one legend entry per phase.
fn draw_legs(chart: &mut Chart<'_, '_>, rows: &[TraceRow], area: &Area) -> Drawn {
    let mut seen = Vec::new();
    let mut start = 0;
    while start < rows.len() {
        let phase = rows[start].phase;
        let mut end = start;
        while end < rows.len() && rows[end].phase == phase {
            end += 1;
        }
        let leg: Vec<(f64, f64)> = rows[start..end]
            .iter()
            .chain(rows.get(end))
            .filter_map(|r| Some((r.position?, r.velocity?.clamp(area.bottom(), area.top()))))
            .collect();
        let k = match seen.iter().position(|p| *p == phase) {
            Some(k) => k,
            None => {
                seen.push(phase);
                seen.len() - 1
            }
        };
        let colour = PHASE_COLOURS[k % PHASE_COLOURS.len()];
        let s = chart.draw_series(LineSeries::new(leg, colour.stroke_width(2)))?;
        if k + 1 == seen.len() {
            s.label(rows[start].phase_name()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        }
        start = end;
    }
    Ok(())
}

/// Ticks under the curve where the switch changes and where a marker passes.
fn draw_edges(chart: &mut Chart<'_, '_>, rows: &[TraceRow], area: &Area) -> Drawn {
    let mut marks: Vec<(f64, RGBColor)> = Vec::new();
    for w in rows.windows(2) {
        if let Some(p) = w[1].position {
            if w[0].switch != w[1].switch {
                marks.push((p, RGBColor(120, 120, 120)));
            }
            if w[1].marker && !w[0].marker {
                marks.push((p, RGBColor(0, 150, 0)));
            }
        }
    }
    for (x, colour) in marks {
        chart.draw_series(LineSeries::new(
            vec![
                (x, area.y0 - area.pady * 0.5),
                (x, area.y0 - area.pady * 0.1),
            ],
            colour.stroke_width(2),
        ))?;
    }
    Ok(())
}

/// The home event: a red line across the plot, with its position in the legend.
fn draw_event(chart: &mut Chart<'_, '_>, rows: &[TraceRow], area: &Area) -> Drawn {
    if let Some(ev) = rows.iter().find_map(|r| r.event_raw) {
        chart
            .draw_series(LineSeries::new(
                vec![(ev, area.bottom()), (ev, area.top())],
                RED.stroke_width(1),
            ))?
            .label(format!("home event {ev:.4}"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_report::trace::{parse_csv, HEADER};

    #[test]
    fn parses_and_draws() {
        let mut csv = String::from(HEADER);
        for k in 0..200 {
            let x = k as f64 * 0.01;
            let phase = if k < 100 { "seek" } else { "return" };
            let v = if k < 100 { 1.0 } else { -0.2 };
            let sw = u8::from((50..150).contains(&k));
            let ev = u8::from(k == 150);
            csv += &format!(
                "{},{phase},{x},{v},{x},{v},1.0,{sw},0,1,{ev},{},0,0\n",
                k as f64 * 0.001,
                if ev == 1 { "1.5" } else { "" }
            );
        }
        let rows = parse_csv(&csv);
        assert_eq!(rows.len(), 200);
        assert_eq!(rows.iter().filter_map(|r| r.event_raw).next(), Some(1.5));
        let out = std::env::temp_dir().join(format!("plot-{}.svg", std::process::id()));
        draw(&rows, "X", &out).unwrap();
        let svg = std::fs::read_to_string(&out).unwrap();
        assert!(svg.contains("home event 1.5000"));
        assert!(svg.contains("seek") && svg.contains("return"));
        std::fs::remove_file(out).unwrap();
    }
}
