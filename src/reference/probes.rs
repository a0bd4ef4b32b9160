//! Twin of shaders/probes.wgsl.

use super::water_fraction::{map_sums, water_fraction};
use super::{dot, kernel, pressure, sub, RefParticle, EXCLUDED, FLUID, INLET};
use crate::scenario::{GaugeSurface, Physics, WallParams, WallPatch};

/// (Σ W V, Σ P W V) over fluid particles at x.
fn sums(ph: &Physics, parts: &[RefParticle], x: [f64; 3]) -> (f64, f64) {
    let mut vol = 0.0;
    let mut pw = 0.0;
    for p in parts.iter().filter(|p| p.kind == FLUID) {
        let d = sub(x, p.pos);
        let r2 = dot(d, d);
        if r2 < 4.0 * ph.h * ph.h {
            let wv = kernel::w(ph.kernel, ph.dim, ph.h, r2.sqrt()) * ph.particle_mass / p.rho;
            vol += wv;
            pw += pressure(ph, p.rho) * wv;
        }
    }
    (vol, pw)
}

/// Shepard-interpolated pressure; 0 where Σ W V < 0.1.
pub fn probe_pressure(ph: &Physics, parts: &[RefParticle], x: [f64; 3]) -> f64 {
    let (vol, pw) = sums(ph, parts, x);
    if vol < 0.1 {
        0.0
    } else {
        pw / vol
    }
}

/// The kernel's 1D form (Wendland C2, ∫ w dd = 1, support 2h) of the distance `d` to a
/// discharge section.
pub fn section_weight(ph: &Physics, d: f64) -> f64 {
    let q = d.abs() / ph.h;
    if q >= 2.0 {
        return 0.0;
    }
    let a = 1.0 - 0.5 * q;
    5.0 / (8.0 * ph.h) * a.powi(3) * (1.5 * q + 1.0)
}

/// A fluid particle's share of the discharge through the section from `from` to `to`
/// (`crate::scenario::ProbeKind::Discharge`): V (u·n) w(d) where its place along the section
/// lies within it; 0 for any other particle.
pub fn discharge_contribution(ph: &Physics, p: &RefParticle, from: [f64; 3], to: [f64; 3]) -> f64 {
    if p.kind != FLUID {
        return 0.0;
    }
    let (n, length) = crate::scenario::ProbeKind::section_normal(from, to);
    let rel = sub(p.pos, from);
    let along = dot(rel, [-n[1], n[0], 0.0]);
    if !(0.0..=length).contains(&along) {
        return 0.0;
    }
    ph.particle_mass / p.rho * dot(p.vel, n) * section_weight(ph, dot(rel, n))
}

/// The discharge through the section from `from` to `to` [m³/s; 2D m²/s].
pub fn probe_discharge(ph: &Physics, parts: &[RefParticle], from: [f64; 3], to: [f64; 3]) -> f64 {
    (parts.iter())
        .map(|p| discharge_contribution(ph, p, from, to))
        .sum()
}

/// Lattice points per h on a gauge's line (`HEIGHT_STEPS_PER_H` in probes.wgsl).
pub const HEIGHT_STEPS_PER_H: f64 = 4.0;

/// The gauge's lattice point k on the vertical line through `base`: base + k·h/4.
fn height_point(ph: &Physics, base: [f64; 3], k: usize) -> [f64; 3] {
    let up = ph.dim as usize - 1;
    let mut x = base;
    x[up] += k as f64 * ph.h / HEIGHT_STEPS_PER_H;
    x
}

/// What a gauge's surface is where half of (probes.wgsl): Σ W V over the fluid (a wave gauge)
/// or the water's share ψ of what the walls leave of the kernel (a depth gauge).
pub fn gauge_fraction(
    ph: &Physics,
    parts: &[RefParticle],
    surface: GaugeSurface,
    x: [f64; 3],
) -> f64 {
    match surface {
        GaugeSurface::FluidHalf => sums(ph, parts, x).0,
        GaugeSurface::WaterFraction => water_fraction(map_sums(ph, parts, x)),
    }
}

/// The highest lattice index k whose point lies on the line through `base` between it and
/// `top` (the domain top) and where `surface`'s fraction reaches ½; None where there is none
/// (a dry gauge). By its definition: a walk down the lattice from the highest point a fluid
/// particle's support reaches (the GPU spreads the same search over the particles, probes.wgsl).
pub fn probe_height_search(
    ph: &Physics,
    parts: &[RefParticle],
    (base, surface): ([f64; 3], GaugeSurface),
    top: f64,
) -> Option<usize> {
    let up = ph.dim as usize - 1;
    let step = ph.h / HEIGHT_STEPS_PER_H;
    let k_top = ((top - base[up]) / step).floor().max(0.0) as usize;
    let reach = parts
        .iter()
        .filter(|p| p.kind == FLUID)
        .filter(|p| {
            let mut d = sub(p.pos, base);
            d[up] = 0.0;
            dot(d, d) < 4.0 * ph.h * ph.h
        })
        .map(|p| p.pos[up] + 2.0 * ph.h)
        .fold(f64::NEG_INFINITY, f64::max);
    if reach < base[up] {
        return None;
    }
    let k_reach = (((reach - base[up]) / step).floor() as usize + 1).min(k_top);
    (0..=k_reach)
        .rev()
        .find(|&k| gauge_fraction(ph, parts, surface, height_point(ph, base, k)) >= 0.5)
}

/// Height above `base` of the surface on the vertical line through it: the point
/// `probe_height_search` finds, interpolated linearly towards the lattice point above where
/// `surface`'s fraction is ½, at most `top`; 0 where none is found.
pub fn probe_height(
    ph: &Physics,
    parts: &[RefParticle],
    gauge: ([f64; 3], GaugeSurface),
    top: f64,
) -> f64 {
    probe_height_search(ph, parts, gauge, top)
        .map_or(0.0, |k| surface_height(ph, parts, gauge, k, top))
}

/// The height above `base` of the surface found at lattice index `k`: interpolated linearly
/// towards the point above where `surface`'s fraction is ½, at most `top`.
pub fn surface_height(
    ph: &Physics,
    parts: &[RefParticle],
    (base, surface): ([f64; 3], GaugeSurface),
    k: usize,
    top: f64,
) -> f64 {
    let up = ph.dim as usize - 1;
    let (x, above) = (height_point(ph, base, k), height_point(ph, base, k + 1));
    let v = gauge_fraction(ph, parts, surface, x);
    let v_above = gauge_fraction(ph, parts, surface, above);
    let t = ((v - 0.5) / (v - v_above).max(1e-6)).clamp(0.0, 1.0);
    (x[up] + (above[up] - x[up]) * t).min(top) - base[up]
}

/// max over fluid of (x − origin)·axis (axis normalised).
pub fn probe_front(parts: &[RefParticle], origin: [f64; 3], axis: [f64; 3]) -> f64 {
    let n = dot(axis, axis).sqrt();
    parts
        .iter()
        .filter(|p| p.kind == FLUID)
        .map(|p| dot(sub(p.pos, origin), axis) / n)
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Continuous front (probes.wgsl, `probe_front_walk`): the largest reach ≥ 0 of the fluid in
/// the first run of wet bins of `width` along `axis` from `origin` (`n_bins` of them); NaN
/// without fluid in the bins.
pub fn probe_front_continuous(
    parts: &[RefParticle],
    origin: [f64; 3],
    axis: [f64; 3],
    width: f64,
    n_bins: usize,
) -> f64 {
    let n = dot(axis, axis).sqrt();
    let reaches: Vec<f64> = (parts.iter())
        .filter(|p| p.kind == FLUID)
        .map(|p| dot(sub(p.pos, origin), axis) / n)
        .filter(|&r| r >= 0.0 && r < n_bins as f64 * width)
        .collect();
    let mut wet = vec![false; n_bins];
    for r in &reaches {
        wet[(r / width).floor() as usize] = true;
    }
    let Some(first) = wet.iter().position(|&w| w) else {
        return f64::NAN;
    };
    let end = (first..n_bins).find(|&b| !wet[b]).unwrap_or(n_bins);
    (reaches.iter())
        .filter(|&&r| ((r / width).floor() as usize) < end)
        .fold(f64::NAN, |m, &r| m.max(r))
}

/// Pressure on a wall patch: −m Σ_j a_j·n / area over the patch's boundary particles j
/// (`WallPatch`), a_j their rates from `interaction::rates` with `walls.reactions`; a fixed
/// wall's particle that belongs to a sensor of another face (`WallParams::sensor_of`) is left
/// out.
pub fn wall_pressure(
    ph: &Physics,
    walls: &WallParams,
    parts: &[RefParticle],
    rates: &[[f64; 4]],
    patch: &WallPatch,
) -> f64 {
    let elsewhere = |p: &RefParticle| {
        p.body.is_none()
            && walls
                .sensor_of(p.pos, ph.h)
                .is_some_and(|k| !walls.sensors[k].same_face(patch))
    };
    let sum: f64 = parts
        .iter()
        .zip(rates)
        .filter(|(p, _)| !matches!(p.kind, FLUID | EXCLUDED | INLET) && !super::is_solid(p.kind))
        .filter(|(p, _)| patch.holds(p.pos, ph.h) && !elsewhere(p))
        .map(|(_, r)| (0..3).map(|a| r[a] * patch.normal[a]).sum::<f64>())
        .sum();
    -ph.particle_mass * sum / patch.area
}

#[cfg(test)]
mod tests {
    use super::*;

    fn physics() -> Physics {
        let text = include_str!("../../cases/dam_break_2d.toml");
        crate::case::load_str(text, "x.toml", &[]).unwrap().physics
    }

    #[test]
    fn the_section_weight_is_a_unit_pulse_of_the_kernels_support() {
        let ph = &physics();
        let n = 4000;
        let step = 4.0 * ph.h / n as f64;
        let area: f64 = (0..n)
            .map(|i| section_weight(ph, -2.0 * ph.h + (i as f64 + 0.5) * step) * step)
            .sum();
        assert!((area - 1.0).abs() < 1e-6, "{area}");
        assert_eq!(section_weight(ph, 2.0 * ph.h), 0.0);
    }

    /// A layer of water `depth` deep on a lattice of spacing dx, streaming at U through a
    /// vertical section across it: Q = U depth per metre of width (to the lattice sum of w,
    /// which is 1 within 1e-3 for h = 1.3 dx); the opposite way, −Q; along the section, 0.
    #[test]
    fn a_uniform_stream_carries_its_speed_times_its_depth() {
        let ph = &physics();
        let dx = ph.dx;
        let (u, rows) = (0.8, 20);
        let stream = |vel: [f64; 3]| -> Vec<RefParticle> {
            (0..120)
                .flat_map(|i| (0..rows).map(move |j| (i, j)))
                .map(|(i, j)| RefParticle {
                    pos: [(i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx, 0.0],
                    vel,
                    rho: ph.rho0,
                    kind: FLUID,
                    body: None,
                    body_kinematic: false,
                    wall_vel: [0.0; 3],
                    wall_acc: [0.0; 3],
                })
                .collect()
        };
        let depth = rows as f64 * dx;
        // From the bed up: n = (t_y, −t_x) = (1, 0), downstream.
        let (from, to) = ([0.3, 0.0, 0.0], [0.3, 1.0, 0.0]);
        let q = probe_discharge(ph, &stream([u, 0.0, 0.0]), from, to);
        assert!(
            (q - u * depth).abs() < 1e-3 * u * depth,
            "{q} against {}",
            u * depth
        );
        let back = probe_discharge(ph, &stream([u, 0.0, 0.0]), to, from);
        assert!((back + q).abs() < 1e-12);
        assert_eq!(probe_discharge(ph, &stream([0.0, u, 0.0]), from, to), 0.0);
    }
}
