//! `motion-plot`: the workspace's SVG plots, drawn with `plotters` (so no
//! SVG is written by hand anywhere):
//!
//! * [`trace`] — a traced homing, velocity against position
//!   (`motionctl trace --plot`);
//! * [`latency`] — latency histograms in the style of the OSADL / LinuxCNC
//!   plots (the jitter bench's `.svg`, the README's figure).

pub mod latency;
pub mod trace;

pub use plotters::style::RGBColor;

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// A white SVG canvas of `size` pixels that will be written to `path`.
fn canvas(path: &Path, size: (u32, u32)) -> Result<DrawingArea<SVGBackend<'_>, Shift>, String> {
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| failed(path, e))?;
    Ok(root)
}

/// How a drawing error reads.
fn failed(path: &Path, e: impl std::fmt::Display) -> String {
    format!("cannot draw {}: {e}", path.display())
}
