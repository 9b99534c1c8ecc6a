//! The plot of a traced homing: velocity against position, the way the seed
//! documents draw homing sequences — each leg a line, the home event and the
//! switch and marker edges marked — drawn with `plotters` into an SVG.

use plotters::prelude::*;
use std::path::Path;

/// One row of the trace CSV (`motion-supervisor`'s `trace_csv` columns).
#[derive(Clone, Debug, Default)]
pub struct Row {
    pub t: f64,
    pub phase: String,
    pub cmd_position: Option<f64>,
    pub cmd_velocity: Option<f64>,
    pub position: Option<f64>,
    pub velocity: Option<f64>,
    pub switch: bool,
    pub marker: bool,
    pub event_raw: Option<f64>,
}

/// Parses the CSV (header first); malformed lines are skipped.
pub fn parse_csv(text: &str) -> Vec<Row> {
    let num = |s: &str| s.parse::<f64>().ok().filter(|x| x.is_finite());
    text.lines()
        .skip(1)
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f.len() >= 14).then(|| Row {
                t: num(f[0]).unwrap_or(0.0),
                phase: f[1].to_string(),
                cmd_position: num(f[2]),
                cmd_velocity: num(f[3]),
                position: num(f[4]),
                velocity: num(f[5]),
                switch: f[7] == "1",
                marker: f[8] == "1",
                event_raw: if f[10] == "1" { num(f[11]) } else { None },
            })
        })
        .collect()
}

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

/// Draws `rows` of axis `axis` into `path` (SVG).
pub fn draw(rows: &[Row], axis: &str, path: &Path) -> Result<(), String> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| Some((r.position?, r.velocity?)))
        .collect();
    if pts.is_empty() {
        return Err("the trace has no feedback to plot".into());
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, 0.0f64, 0.0f64);
    for &(x, y) in &pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
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
    let e = |e: &dyn std::fmt::Display| format!("cannot draw {}: {e}", path.display());
    let root = SVGBackend::new(path, (1000, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{axis}: velocity against position during homing"),
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x0 - padx)..(x1 + padx), (y0 - pady)..(y1 + pady))
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("raw position (units)")
        .y_desc("velocity (units/s)")
        .draw()
        .map_err(|x| e(&x))?;

    // The commanded profile, thin and grey, under the actual motion.
    let cmd: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| Some((r.cmd_position?, r.cmd_velocity?)))
        .collect();
    chart
        .draw_series(LineSeries::new(
            cmd,
            RGBColor(170, 170, 170).stroke_width(1),
        ))
        .map_err(|x| e(&x))?
        .label("command")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RGBColor(170, 170, 170)));

    // One line per leg (consecutive rows of the same phase).
    let mut seen: Vec<String> = Vec::new();
    let mut start = 0;
    while start < rows.len() {
        let phase = rows[start].phase.clone();
        let mut end = start;
        while end < rows.len() && rows[end].phase == phase {
            end += 1;
        }
        let leg: Vec<(f64, f64)> = rows[start..end.min(rows.len())]
            .iter()
            .chain(rows.get(end))
            .filter_map(|r| Some((r.position?, r.velocity?.clamp(y0 - pady, y1 + pady))))
            .collect();
        let k = match seen.iter().position(|p| *p == phase) {
            Some(k) => k,
            None => {
                seen.push(phase.clone());
                seen.len() - 1
            }
        };
        let colour = PHASE_COLOURS[k % PHASE_COLOURS.len()];
        let s = chart
            .draw_series(LineSeries::new(leg, colour.stroke_width(2)))
            .map_err(|x| e(&x))?;
        if k + 1 == seen.len() {
            s.label(phase.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        }
        start = end;
    }

    // Switch edges (where the logical input changes) and markers.
    let mut marks: Vec<(f64, &str, RGBColor)> = Vec::new();
    for w in rows.windows(2) {
        if let Some(p) = w[1].position {
            if w[0].switch != w[1].switch {
                marks.push((p, "switch", RGBColor(120, 120, 120)));
            }
            if w[1].marker && !w[0].marker {
                marks.push((p, "marker", RGBColor(0, 150, 0)));
            }
        }
    }
    for (x, _, colour) in &marks {
        chart
            .draw_series(LineSeries::new(
                vec![(*x, y0 - pady * 0.5), (*x, y0 - pady * 0.1)],
                colour.stroke_width(2),
            ))
            .map_err(|x| e(&x))?;
    }
    if let Some(ev) = rows.iter().find_map(|r| r.event_raw) {
        chart
            .draw_series(LineSeries::new(
                vec![(ev, y0 - pady), (ev, y1 + pady)],
                RED.stroke_width(1),
            ))
            .map_err(|x| e(&x))?
            .label(format!("home event {ev:.4}"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_draws() {
        let mut csv = String::from("t_s,phase,cmd_position,cmd_velocity,position,velocity,torque,switch,marker,fresh,event,event_raw,err,exerr\n");
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
