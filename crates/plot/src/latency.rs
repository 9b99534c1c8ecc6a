//! The latency histogram plot (the jitter bench's `.svg`, the README's
//! figure) in the style of the OSADL / LinuxCNC latency plots, drawn with
//! plotters: x latency in µs (linear, to the largest value seen), y samples
//! per bin (log), one step line per series, the period marked. When host
//! hiccups of milliseconds stretch the x axis, a second panel zooms in on
//! the body of the distributions (to ~1.5 × the highest p99.9).

use crate::{canvas, failed};
use hdrhistogram::Histogram;
use motion_report::table::thousands;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// One curve: a histogram of latencies in ns.
pub struct Series<'a> {
    pub name: &'a str,
    pub colour: RGBColor,
    pub hist: &'a Histogram<u64>,
}

const W: u32 = 960;
const PANEL_H: u32 = 480;

/// The smallest of 1, 2, 5 × 10^k at or above `x`.
fn nice(x: f64) -> f64 {
    let e = 10f64.powf(x.max(1e-9).log10().floor());
    let m = [1.0, 2.0, 5.0]
        .into_iter()
        .find(|m| m * e >= x * (1.0 - 1e-9));
    m.unwrap_or(10.0) * e
}

/// One panel's x range and bin width, µs.
struct Bins {
    x_max: f64,
    width: f64,
}

impl Bins {
    /// `0..=max_us` (rounded up to a whole bin), at most ~800 bins.
    fn new(max_us: f64) -> Self {
        let width = nice((max_us / 800.0).max(1.0));
        let x_max = ((max_us / width).floor() + 1.0) * width;
        Bins { x_max, width }
    }

    /// Samples per bin, and those beyond the range.
    fn count(&self, h: &Histogram<u64>) -> (Vec<u64>, u64) {
        let mut out = vec![0u64; (self.x_max / self.width).round().max(1.0) as usize];
        let mut beyond = 0;
        for v in h.iter_recorded() {
            // the top of the HdrHistogram bucket: a value recorded on a
            // whole µs (cyclictest) stays in its 1 µs bin
            let i = (v.value_iterated_to() as f64 / 1000.0 / self.width) as usize;
            match out.get_mut(i) {
                Some(n) => *n += v.count_at_value(),
                None => beyond += v.count_at_value(),
            }
        }
        (out, beyond)
    }
}

/// Draws the plot into `path`: `subtitle` lines under the title, the
/// period (`marker_us`) dashed where it lies in range.
pub fn draw(
    path: &Path,
    title: &str,
    subtitle: &[&str],
    series: &[Series],
    marker_us: f64,
) -> Result<(), String> {
    let e = |x: &dyn std::fmt::Display| failed(path, x);
    let q = |h: &Histogram<u64>, q: f64| h.value_at_quantile(q) as f64 / 1000.0;
    let nonempty = || series.iter().filter(|s| !s.hist.is_empty());
    let max_us = nonempty()
        .map(|s| s.hist.max() as f64 / 1000.0)
        .fold(1.0, f64::max);
    let body_us = nonempty().map(|s| q(s.hist, 0.999)).fold(0.0, f64::max);
    // zoom on the body when the tail stretches the x axis
    let zoom_to = (body_us * 1.5).max(50.0);
    let zoom = (zoom_to < max_us * 0.5).then(|| {
        let step = nice(zoom_to / 10.0);
        Bins::new((zoom_to / step).ceil() * step - 1e-6)
    });
    let head = 50 + 20 * (subtitle.len() + series.len()) as u32;
    let size = (W, head + PANEL_H * (1 + u32::from(zoom.is_some())));
    let root = canvas(path, size)?;
    let (centre, font) = (Pos::new(HPos::Center, VPos::Top), |n| {
        ("sans-serif", n).into_font()
    });
    let mut texts = vec![(
        title.to_string(),
        (W as i32 / 2, 10),
        font(17).style(FontStyle::Bold).color(&BLACK).pos(centre),
    )];
    for (i, s) in subtitle.iter().enumerate() {
        let style = font(13).color(&RGBColor(68, 68, 68)).pos(centre);
        texts.push((s.to_string(), (W as i32 / 2, 34 + 20 * i as i32), style));
    }
    for (i, s) in series.iter().enumerate() {
        let (y, h) = (44 + 20 * (subtitle.len() + i) as i32, s.hist);
        let line = PathElement::new([(80, y + 7), (102, y + 7)], s.colour.stroke_width(3));
        root.draw(&line).map_err(|x| e(&x))?;
        let (n, max) = (thousands(h.len()), h.max() as f64 / 1000.0);
        let [p50, p99, p999] = [0.5, 0.99, 0.999].map(|x| q(h, x));
        let label = match h.is_empty() {
            true => format!("{} (no samples)", s.name),
            false => format!(
                "{}: {n} samples, p50 {p50:.1} µs, p99 {p99:.1} µs, p99.9 {p999:.1} µs, max {max:.1} µs",
                s.name
            ),
        };
        texts.push((label, (108, y), font(13).color(&BLACK)));
    }
    for (text, at, style) in texts {
        root.draw(&Text::new(text, at, style)).map_err(|x| e(&x))?;
    }
    let (_, body) = root.split_vertically(head);
    let full = Bins::new(max_us);
    let panels = body.split_evenly((1 + usize::from(zoom.is_some()), 1));
    let heading = ["every sample", "full range (every sample)"][usize::from(zoom.is_some())];
    panel(&panels[0], &full, series, marker_us, heading).map_err(|x| e(&x))?;
    if let Some(z) = &zoom {
        let beyond: Vec<String> = (series.iter())
            .map(|s| format!("{} {}", s.name, thousands(z.count(s.hist).1)))
            .collect();
        let (to, beyond) = (thousands(z.x_max.round() as u64), beyond.join(", "));
        let heading = format!("zoom: 0 – {to} µs; samples beyond: {beyond}");
        panel(&panels[1], z, series, marker_us, &heading).map_err(|x| e(&x))?;
    }
    root.present().map_err(|x| e(&x))
}

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type DrawResult<'a> =
    Result<(), DrawingAreaErrorKind<<SVGBackend<'a> as DrawingBackend>::ErrorType>>;

/// One panel: the series binned by `b`, step lines on a log count axis.
fn panel<'a>(
    area: &Area<'a>,
    b: &Bins,
    series: &[Series],
    marker_us: f64,
    heading: &str,
) -> DrawResult<'a> {
    let counts: Vec<Vec<u64>> = series.iter().map(|s| b.count(s.hist).0).collect();
    let c_max = counts.iter().flatten().copied().max().unwrap_or(1).max(1);
    let y_top = 10f64.powf((c_max as f64).log10().ceil().max(1.0));
    // below 1 sample: empty bins sit on the axis
    let floor = 0.5;
    let mut chart = ChartBuilder::on(area)
        .caption(
            heading,
            ("sans-serif", 14).into_font().style(FontStyle::Bold),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..b.x_max, (floor..y_top).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("latency (µs)")
        .y_desc(format!("samples per {} µs bin (log scale)", b.width))
        .x_label_formatter(&|x| thousands(x.round() as u64))
        .y_label_formatter(&|y| thousands(y.round() as u64))
        .light_line_style(WHITE)
        .draw()?;
    if marker_us > 0.0 && marker_us <= b.x_max {
        let grey = RGBColor(136, 136, 136).into();
        let line = [(marker_us, floor), (marker_us, y_top)];
        chart.draw_series(DashedLineSeries::new(line, 6, 4, grey))?;
        let style = ("sans-serif", 12)
            .into_font()
            .color(&RGBColor(102, 102, 102));
        chart.draw_series([Text::new("period", (marker_us, y_top), style)])?;
    }
    for (s, c) in series.iter().zip(&counts) {
        let mut steps = vec![(0.0, floor)];
        let mut last = floor;
        for (i, &n) in c.iter().enumerate() {
            let y = (n as f64).max(floor);
            if y != last {
                let x = i as f64 * b.width;
                steps.extend([(x, last), (x, y)]);
                last = y;
            }
        }
        steps.extend([(b.x_max, last), (b.x_max, floor)]);
        chart.draw_series(LineSeries::new(steps, s.colour.stroke_width(1)))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn new_hist() -> Histogram<u64> {
        Histogram::new_with_bounds(1, 10_000_000_000, 3).unwrap()
    }

    #[test]
    fn plots_two_series_and_zooms_on_a_far_outlier() {
        let (mut a, mut b) = (new_hist(), new_hist());
        for v in 10..200u64 {
            a.record_n(v * 1000, 1000 / v).unwrap();
            b.record_n(v * 1000 + 500, 2000 / v).unwrap();
        }
        let red = RGBColor(214, 39, 40);
        let p = std::env::temp_dir().join(format!("mb-plot-{}.svg", std::process::id()));
        let plot = |a: &Histogram<u64>| {
            let s = [
                Series {
                    name: "ours",
                    colour: BLUE,
                    hist: a,
                },
                Series {
                    name: "ct",
                    colour: red,
                    hist: &b,
                },
            ];
            draw(&p, "t <1>", &["s & s"], &s, 1000.0).unwrap();
            std::fs::read_to_string(&p).unwrap()
        };
        let svg = plot(&a);
        assert!(
            svg.starts_with("<svg") && svg.contains("t &lt;1&gt;") && svg.contains("s &amp; s")
        );
        assert!(svg.contains("every sample") && !svg.contains("zoom"));
        a.record(15_000_000).unwrap();
        let svg = plot(&a);
        let _ = std::fs::remove_file(&p);
        assert!(
            svg.contains("full range (every sample)")
                && svg.contains("zoom: 0")
                && svg.contains("period")
        );
        assert_eq!((nice(3.0), nice(1.0), nice(11.0)), (5.0, 1.0, 20.0));
    }
}
