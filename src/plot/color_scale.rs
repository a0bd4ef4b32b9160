//! The colour scale of particle pictures: which value colours a fluid particle
//! ([`SnapshotField`]), the run's fixed scale onto viridis ([`ColorScale`]), the colours of
//! walls, NaN and the background, and the colour bar beside a picture ([`draw_colorbar`]).
//! Shared by the plane snapshots (`snapshot.rs`) and the perspective view (`perspective.rs`).

use std::fmt;
use std::str::FromStr;

use anyhow::{bail, Result};
use plotters::prelude::*;

use crate::output::Snapshot;
use crate::scenario::{Kind, Scenario};

/// Pixels of the layout (see [`SnapshotView::render`]).
pub(super) const MARGIN: u32 = 12;
pub(super) const X_LABEL_AREA: u32 = 50;
/// Colour bar strip, its labels and its title.
pub(super) const COLORBAR_WIDTH: u32 = 130;
/// Bands of the colour bar.
pub(super) const COLORBAR_BANDS: usize = 128;

/// The per-particle value that sets a fluid particle's colour.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SnapshotField {
    #[default]
    Pressure,
    /// |v|.
    Speed,
}

impl SnapshotField {
    /// Colour bar label, with the unit.
    pub fn label(self) -> &'static str {
        match self {
            SnapshotField::Pressure => "pressure [Pa]",
            SnapshotField::Speed => "speed [m/s]",
        }
    }

    /// The value of particle `i` of `snap`.
    pub(super) fn value(self, snap: &Snapshot, i: usize) -> f64 {
        match self {
            SnapshotField::Pressure => snap.pressure[i] as f64,
            SnapshotField::Speed => {
                let v = snap.vel[i].map(|c| c as f64);
                (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
            }
        }
    }
}

impl FromStr for SnapshotField {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "pressure" => Ok(SnapshotField::Pressure),
            "speed" => Ok(SnapshotField::Speed),
            _ => Err(format!("{s:?}: expected pressure or speed")),
        }
    }
}

impl fmt::Display for SnapshotField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SnapshotField::Pressure => "pressure",
            SnapshotField::Speed => "speed",
        })
    }
}

/// Boundary particles of every kind.
pub const WALL_COLOR: RGBColor = RGBColor(150, 150, 150);
/// A fluid particle whose value is NaN (viridis has no red).
pub const NAN_COLOR: RGBColor = RGBColor(255, 0, 0);
pub const BACKGROUND: RGBColor = WHITE;

/// Values from `min` to `max` mapped linearly onto viridis; values outside take the end colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColorScale {
    min: f64,
    max: f64,
}

impl ColorScale {
    /// Errors unless both ends are finite and `max > min`.
    pub fn new(min: f64, max: f64) -> Result<Self> {
        if !(min.is_finite() && max.is_finite() && max > min) {
            bail!("colour scale [{min}, {max}]: the ends must be finite and increasing");
        }
        Ok(ColorScale { min, max })
    }

    /// The fixed scale of a run, from its initial state rather than any frame so that every
    /// frame uses the same colours: pressure from 0 to the hydrostatic ρ0 g H at the bottom of
    /// the deepest water H (the initial fluid's vertical extent); speed from 0 to the dam-break
    /// front speed 2 sqrt(g H). Faster flow and impact peaks take the top colour. Without
    /// gravity the reference speed is c0/10 (weakly compressible SPH sizes c0 to ten times the
    /// largest expected speed) and the pressure its dynamic pressure ρ0 (c0/10)².
    pub fn for_scenario(sc: &Scenario, field: SnapshotField) -> Result<Self> {
        let ph = &sc.physics;
        let up = ph.dim as usize - 1;
        let (lo, hi) = sc
            .particles
            .iter()
            .filter(|p| p.kind == Kind::Fluid)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.pos[up]), hi.max(p.pos[up]))
            });
        let depth = if hi >= lo { hi - lo + ph.dx } else { 0.0 };
        let g = ph.gravity.iter().map(|g| g * g).sum::<f64>().sqrt();
        let (speed, pressure) = if g * depth > 0.0 {
            (2.0 * (g * depth).sqrt(), ph.rho0 * g * depth)
        } else {
            let u = 0.1 * ph.c0;
            (u, ph.rho0 * u * u)
        };
        match field {
            SnapshotField::Pressure => ColorScale::new(0.0, pressure),
            SnapshotField::Speed => ColorScale::new(0.0, speed),
        }
    }

    pub fn range(&self) -> (f64, f64) {
        (self.min, self.max)
    }

    pub fn color(&self, value: f64) -> RGBColor {
        if value.is_nan() {
            return NAN_COLOR;
        }
        let t = ((value - self.min) / (self.max - self.min)).clamp(0.0, 1.0);
        ColorMap::<RGBColor, f64>::get_color(&ViridisRGB, t)
    }
}

/// The plotting area of a picture of an `lx` × `ly` extent, px: its longer side `long_side`,
/// the other in proportion (square cells look square) but at least `min_side`.
pub(super) fn plot_area(lx: f64, ly: f64, long_side: f64, min_side: f64) -> (f64, f64) {
    if lx >= ly {
        (long_side, (long_side * ly / lx).max(min_side))
    } else {
        ((long_side * lx / ly).max(min_side), long_side)
    }
}

/// The colour bar of `scale` in `area`, labelled `label` (what it shows, with its unit).
pub(super) fn draw_colorbar<'a>(
    area: &DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>,
    scale: &ColorScale,
    label: &str,
) -> std::result::Result<(), Box<dyn std::error::Error + 'a>> {
    let (lo, hi) = scale.range();
    let mut bar = ChartBuilder::on(area)
        .margin(MARGIN)
        .margin_left(4)
        .x_label_area_size(X_LABEL_AREA)
        .right_y_label_area_size(COLORBAR_WIDTH - 4 - MARGIN - 24)
        .build_cartesian_2d(0.0..1.0, lo..hi)?;
    // Decimals enough for ticks about a tenth of the range apart: "4500", "2.50", "0.0150".
    let decimals = (2.0 - (hi - lo).log10().floor()).clamp(0.0, 9.0) as usize;
    bar.configure_mesh()
        .disable_x_mesh()
        .disable_y_mesh()
        .disable_x_axis()
        .y_label_formatter(&|v| format!("{v:.decimals$}"))
        .y_desc(label)
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .draw()?;
    let step = (hi - lo) / COLORBAR_BANDS as f64;
    bar.draw_series((0..COLORBAR_BANDS).map(|k| {
        let v0 = lo + k as f64 * step;
        Rectangle::new(
            [(0.0, v0), (1.0, v0 + step)],
            scale.color(v0 + 0.5 * step).filled(),
        )
    }))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn field_parses() {
        assert_eq!("speed".parse(), Ok(SnapshotField::Speed));
        assert_eq!("pressure".parse(), Ok(SnapshotField::Pressure));
        let e = "density".parse::<SnapshotField>().unwrap_err();
        assert!(e.contains("pressure or speed"), "{e}");
        assert_eq!(SnapshotField::Speed.to_string(), "speed");
    }

    #[test]
    fn color_scale_maps_onto_viridis_and_clamps() {
        let s = ColorScale::new(0.0, 1000.0).unwrap();
        let low = s.color(0.0);
        let high = s.color(1000.0);
        // Viridis: dark purple to yellow.
        assert_eq!(low, RGBColor(68, 1, 84));
        assert!(high.0 > 200 && high.1 > 200 && high.2 < 80, "{high:?}");
        assert_eq!(s.color(-50.0), low);
        assert_eq!(s.color(5e6), high);
        assert_eq!(s.color(f64::INFINITY), high);
        assert_eq!(s.color(f64::NAN), NAN_COLOR);
        let mid = s.color(500.0);
        assert!(mid != low && mid != high);
        assert_eq!(mid, ColorMap::<RGBColor, f64>::get_color(&ViridisRGB, 0.5));
        assert!(ColorScale::new(1.0, 1.0).is_err());
        assert!(ColorScale::new(0.0, f64::NAN).is_err());
        assert!(ColorScale::new(2.0, 1.0).is_err());
    }

    #[test]
    fn scale_of_a_scenario_is_hydrostatic() {
        let sc = crate::case::load(Path::new("cases/hydrostatic_2d.toml"), &[]).unwrap();
        // Water 0.5 m deep (particle centres 0.01 ... 0.49 m, plus dx).
        let p = ColorScale::for_scenario(&sc, SnapshotField::Pressure).unwrap();
        let rho_g_h = 1000.0 * 9.81 * 0.5;
        assert!((p.range().1 - rho_g_h).abs() < 1e-6 * rho_g_h, "{p:?}");
        assert_eq!(p.range().0, 0.0);
        let v = ColorScale::for_scenario(&sc, SnapshotField::Speed).unwrap();
        assert!(
            (v.range().1 - 2.0 * (9.81f64 * 0.5).sqrt()).abs() < 1e-9,
            "{v:?}"
        );
    }
}
