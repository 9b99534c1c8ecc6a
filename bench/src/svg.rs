//! A latency histogram plot in the style of the OSADL / LinuxCNC latency
//! plots, as hand-written SVG: x = latency in µs (linear, up to the largest
//! value seen), y = samples per bin on a log scale, one step line per series.
//! When the largest values are far out (host hiccups of milliseconds), a
//! second panel zooms in on the body of the distribution (up to ~1.5 × the
//! highest p99.9) with 1 µs bins.

use crate::hist::thousands;
use hdrhistogram::Histogram;
use std::fmt::Write;

pub struct Series<'a> {
    pub name: &'a str,
    pub colour: &'a str,
    /// Values in ns.
    pub hist: &'a Histogram<u64>,
}

const W: f64 = 960.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 30.0;
const PANEL_H: f64 = 400.0;
/// Room under a panel for its tick labels and axis label.
const BELOW: f64 = 50.0;
/// Room above a panel for its heading.
const ABOVE: f64 = 30.0;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The smallest of 1, 2, 5 × 10^k at or above `x`.
fn nice(x: f64) -> f64 {
    let x = x.max(1e-9);
    let e = 10f64.powf(x.log10().floor());
    for m in [1.0, 2.0, 5.0, 10.0] {
        if m * e >= x * (1.0 - 1e-9) {
            return m * e;
        }
    }
    10.0 * e
}

/// One panel's x range and bin width, µs.
struct Range {
    x_max: f64,
    width: f64,
}

impl Range {
    /// `0..=max_us` (rounded up to a whole bin), at most ~800 bins.
    fn new(max_us: f64) -> Self {
        let width = nice((max_us / 800.0).max(1.0));
        Self {
            x_max: ((max_us / width).floor() + 1.0) * width,
            width,
        }
    }

    fn bins(&self) -> usize {
        (self.x_max / self.width).round().max(1.0) as usize
    }

    /// Samples per bin; values beyond the range are left out (returned
    /// separately).
    fn count(&self, h: &Histogram<u64>) -> (Vec<u64>, u64) {
        let n = self.bins();
        let mut out = vec![0u64; n];
        let mut beyond = 0;
        for v in h.iter_recorded() {
            // the top of the HdrHistogram bucket: a value recorded on a whole
            // µs (cyclictest) stays in its 1 µs bin
            let us = v.value_iterated_to() as f64 / 1000.0;
            let i = (us / self.width) as usize;
            if i < n {
                out[i] += v.count_at_value();
            } else {
                beyond += v.count_at_value();
            }
        }
        (out, beyond)
    }
}

/// The plot. `subtitle`: one or more lines under the title. `marker_us`: a
/// dashed vertical line (e.g. the period), drawn where it lies in range.
pub fn latency_plot(
    title: &str,
    subtitle: &[&str],
    series: &[Series],
    marker_us: Option<f64>,
) -> String {
    let nonempty = || series.iter().filter(|s| !s.hist.is_empty());
    let max_us = nonempty()
        .map(|s| s.hist.max() as f64 / 1000.0)
        .fold(1.0, f64::max);
    let body_us = nonempty()
        .map(|s| s.hist.value_at_quantile(0.999) as f64 / 1000.0)
        .fold(0.0, f64::max);
    let full = Range::new(max_us);
    // zoom on the body when the tail stretches the x axis
    let zoom_to = (body_us * 1.5).max(50.0);
    let zoom = (zoom_to < max_us * 0.5).then(|| {
        let step = nice(zoom_to / 10.0);
        Range::new((zoom_to / step).ceil() * step - 1e-6)
    });

    let head = 30.0 + 18.0 * subtitle.len() as f64 + 10.0;
    let legend_h = series.len() as f64 * 20.0 + 12.0;
    let panels = if zoom.is_some() { 2.0 } else { 1.0 };
    let h = head + legend_h + panels * (ABOVE + PANEL_H + BELOW) + 10.0;

    let mut s = String::new();
    let _ = write!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{W}\" height=\"{h}\" \
         viewBox=\"0 0 {W} {h}\" font-family=\"DejaVu Sans, Arial, sans-serif\" font-size=\"12\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"24\" text-anchor=\"middle\" font-size=\"15\" font-weight=\"bold\">{}</text>",
        W / 2.0,
        esc(title)
    );
    for (i, line) in subtitle.iter().enumerate() {
        let _ = writeln!(
            s,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" fill=\"#444\">{}</text>",
            W / 2.0,
            44.0 + 18.0 * i as f64,
            esc(line)
        );
    }

    // legend, above the panels
    let mut ly = head + 14.0;
    for ser in series {
        let hh = ser.hist;
        let label = if hh.is_empty() {
            format!("{} (no samples)", ser.name)
        } else {
            format!(
                "{}: {} samples, p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs, max {:.1} µs",
                ser.name,
                thousands(hh.len()),
                hh.value_at_quantile(0.5) as f64 / 1000.0,
                hh.value_at_quantile(0.99) as f64 / 1000.0,
                hh.value_at_quantile(0.999) as f64 / 1000.0,
                hh.max() as f64 / 1000.0
            )
        };
        let _ = writeln!(
            s,
            "<line x1=\"{LEFT}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{}\" stroke-width=\"3\"/>\
             <text x=\"{:.1}\" y=\"{ly:.1}\">{}</text>",
            ly - 4.0,
            LEFT + 22.0,
            ly - 4.0,
            ser.colour,
            LEFT + 28.0,
            esc(&label)
        );
        ly += 20.0;
    }

    let mut top = head + legend_h + ABOVE;
    let heading = if zoom.is_some() {
        "full range (every sample)"
    } else {
        "every sample"
    };
    panel(&mut s, top, &full, series, marker_us, heading);
    if let Some(z) = &zoom {
        top += PANEL_H + BELOW + ABOVE;
        let beyond: Vec<String> = series
            .iter()
            .map(|ser| format!("{} {}", ser.name, thousands(z.count(ser.hist).1)))
            .collect();
        let heading = format!(
            "zoom: 0 – {} µs; samples beyond: {}",
            thousands(z.x_max.round() as u64),
            beyond.join(", ")
        );
        panel(&mut s, top, z, series, marker_us, &heading);
    }
    s.push_str("</svg>\n");
    s
}

/// One panel with its top edge at `top`.
fn panel(
    s: &mut String,
    top: f64,
    r: &Range,
    series: &[Series],
    marker_us: Option<f64>,
    heading: &str,
) {
    let counts: Vec<Vec<u64>> = series.iter().map(|ser| r.count(ser.hist).0).collect();
    let c_max = counts.iter().flatten().copied().max().unwrap_or(1).max(1);
    let y_top = 10f64.powf((c_max as f64).log10().ceil().max(1.0));
    let y_bottom = 0.5f64; // below 1 sample: empty bins sit on the axis
    let pw = W - LEFT - RIGHT;
    let ph = PANEL_H;
    let x = |us: f64| LEFT + us / r.x_max * pw;
    let y = |c: f64| {
        let c = c.max(y_bottom);
        top + ph * (1.0 - (c.log10() - y_bottom.log10()) / (y_top.log10() - y_bottom.log10()))
    };
    let _ = writeln!(
        s,
        "<text x=\"{LEFT}\" y=\"{:.1}\" font-weight=\"bold\" fill=\"#333\">{}</text>",
        top - 8.0,
        esc(heading)
    );
    // y grid and ticks: decades
    let mut d = 1.0f64;
    while d <= y_top * 1.0001 {
        let yy = y(d);
        let _ = writeln!(
            s,
            "<line x1=\"{LEFT}\" y1=\"{yy:.1}\" x2=\"{:.1}\" y2=\"{yy:.1}\" stroke=\"#ddd\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
            LEFT + pw,
            LEFT - 6.0,
            yy + 4.0,
            thousands(d as u64)
        );
        d *= 10.0;
    }
    // x ticks: ~10
    let step = nice(r.x_max / 10.0);
    let mut t = 0.0;
    while t <= r.x_max + 1e-9 {
        let xx = x(t);
        let _ = writeln!(
            s,
            "<line x1=\"{xx:.1}\" y1=\"{:.1}\" x2=\"{xx:.1}\" y2=\"{:.1}\" stroke=\"#000\"/>\
             <line x1=\"{xx:.1}\" y1=\"{top:.1}\" x2=\"{xx:.1}\" y2=\"{:.1}\" stroke=\"#f0f0f0\"/>\
             <text x=\"{xx:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>",
            top + ph,
            top + ph + 5.0,
            top + ph,
            top + ph + 19.0,
            thousands(t.round() as u64)
        );
        t += step;
    }
    let _ = writeln!(
        s,
        "<rect x=\"{LEFT}\" y=\"{top:.1}\" width=\"{pw}\" height=\"{ph}\" fill=\"none\" stroke=\"#000\"/>"
    );
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">latency (µs)</text>",
        LEFT + pw / 2.0,
        top + ph + 38.0
    );
    let _ = writeln!(
        s,
        "<text transform=\"translate(22 {:.1}) rotate(-90)\" text-anchor=\"middle\">samples per {} µs bin (log scale)</text>",
        top + ph / 2.0,
        r.width
    );
    if let Some(m) = marker_us.filter(|&m| m > 0.0 && m <= r.x_max) {
        let xx = x(m);
        let _ = writeln!(
            s,
            "<line x1=\"{xx:.1}\" y1=\"{top:.1}\" x2=\"{xx:.1}\" y2=\"{:.1}\" stroke=\"#888\" stroke-dasharray=\"6 4\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" fill=\"#666\">period</text>",
            top + ph,
            xx + 4.0,
            top + 14.0
        );
    }
    // series: step lines
    for (ser, c) in series.iter().zip(&counts) {
        let base = y(0.0);
        let mut path = format!("M{:.2},{base:.2}", x(0.0));
        let mut last_y = base;
        for (i, &n) in c.iter().enumerate() {
            let yy = y(n as f64);
            if (yy - last_y).abs() > 0.01 {
                let xi = x(i as f64 * r.width);
                let _ = write!(path, " L{xi:.2},{last_y:.2} L{xi:.2},{yy:.2}");
                last_y = yy;
            }
        }
        let xe = x(r.x_max);
        let _ = write!(path, " L{xe:.2},{last_y:.2} L{xe:.2},{base:.2}");
        let _ = writeln!(
            s,
            "<path d=\"{path}\" fill=\"{}\" fill-opacity=\"0.08\" stroke=\"{}\" stroke-width=\"1.3\"/>",
            ser.colour, ser.colour
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hist::new_hist;

    #[test]
    fn plots_two_series() {
        let mut a = new_hist();
        let mut b = new_hist();
        for v in 10..200u64 {
            a.record_n(v * 1000, 1000 / v).unwrap();
            b.record_n(v * 1000 + 500, 2000 / v).unwrap();
        }
        let svg = latency_plot(
            "t <1>",
            &["s & s"],
            &[
                Series {
                    name: "ours",
                    colour: "#1f77b4",
                    hist: &a,
                },
                Series {
                    name: "cyclictest",
                    colour: "#d62728",
                    hist: &b,
                },
            ],
            Some(1000.0),
        );
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains("t &lt;1&gt;"));
        assert!(svg.contains("s &amp; s"));
        assert_eq!(svg.matches("<path").count(), 2);
        assert!(!svg.contains("zoom"));
        // a far outlier adds the zoomed panel
        a.record(15_000_000).unwrap();
        let svg = latency_plot(
            "t",
            &["s"],
            &[Series {
                name: "ours",
                colour: "#1f77b4",
                hist: &a,
            }],
            Some(1000.0),
        );
        assert_eq!(svg.matches("<path").count(), 2);
        assert!(svg.contains("zoom"));
        assert!(svg.contains("period"));
        assert_eq!(nice(3.0), 5.0);
        assert_eq!(nice(1.0), 1.0);
        assert_eq!(nice(11.0), 20.0);
    }
}
