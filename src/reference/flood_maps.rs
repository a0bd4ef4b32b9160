//! Twin of shaders/flood_maps.wgsl, in the scenario's coordinates.

use super::{dot, kernel, sub, RefParticle, EXCLUDED, FLUID, INLET};
use crate::scenario::{FloodMaps, Physics};

/// Lattice points per h over a map cell (`MAP_STEPS_PER_H`).
pub const MAP_STEPS_PER_H: f64 = 4.0;
/// The walls' share of the kernel beyond which ψ is not formed (`MAP_MAX_SOLID_SHARE`).
pub const MAP_MAX_SOLID_SHARE: f64 = 0.9;

/// The fluid's and the walls' shares of the kernel at a point, and the fluid's Σ v W V in plan.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MapSums {
    pub fluid: f64,
    pub solid: f64,
    pub momentum: [f64; 2],
}

pub fn map_sums(ph: &Physics, parts: &[RefParticle], x: [f64; 3]) -> MapSums {
    let mut s = MapSums::default();
    for p in parts {
        let d = sub(x, p.pos);
        let r2 = dot(d, d);
        if r2 >= 4.0 * ph.h * ph.h || p.kind == EXCLUDED || p.kind == INLET {
            continue;
        }
        let w = kernel::w(ph.kernel, ph.dim, ph.h, r2.sqrt());
        if p.kind == FLUID {
            let wv = w * ph.particle_mass / p.rho;
            s.fluid += wv;
            s.momentum[0] += wv * p.vel[0];
            s.momentum[1] += wv * p.vel[1];
        } else {
            s.solid += w * ph.particle_mass / ph.rho0;
        }
    }
    s
}

/// ψ = φ_f / (1 − φ_s), 0 inside the walls.
pub fn water_fraction(s: MapSums) -> f64 {
    if s.solid > MAP_MAX_SOLID_SHARE {
        return 0.0;
    }
    s.fluid / (1.0 - s.solid)
}

pub fn map_cell_centre(maps: &FloodMaps, c: usize) -> [f64; 2] {
    maps.centre(c)
}

fn map_step(ph: &Physics) -> f64 {
    ph.h / MAP_STEPS_PER_H
}

/// The lattice point k over cell c.
pub fn map_point(ph: &Physics, maps: &FloodMaps, c: usize, k: usize) -> [f64; 3] {
    let [x, y] = map_cell_centre(maps, c);
    [x, y, maps.ground[c] + k as f64 * map_step(ph)]
}

/// The highest lattice index over cell c at or below `top`.
pub fn map_top_index(ph: &Physics, maps: &FloodMaps, c: usize, top: f64) -> usize {
    ((top - maps.ground[c]) / map_step(ph)).floor().max(0.0) as usize
}

/// The highest lattice index k over cell c (at most `top`) where ψ ≥ ½; None where there is
/// none. By its definition: a walk down from the highest point a fluid particle's support
/// reaches (the GPU spreads the same search over the particles).
pub fn map_surface_search(
    ph: &Physics,
    parts: &[RefParticle],
    maps: &FloodMaps,
    c: usize,
    top: f64,
) -> Option<usize> {
    let [cx, cy] = map_cell_centre(maps, c);
    let reach = (parts.iter())
        .filter(|p| p.kind == FLUID)
        .filter(|p| (p.pos[0] - cx).powi(2) + (p.pos[1] - cy).powi(2) < 4.0 * ph.h * ph.h)
        .map(|p| p.pos[2] + 2.0 * ph.h)
        .fold(f64::NEG_INFINITY, f64::max);
    if reach < maps.ground[c] {
        return None;
    }
    let k_reach = ((reach - maps.ground[c]) / map_step(ph)).floor() as usize + 1;
    (0..=k_reach.min(map_top_index(ph, maps, c, top)))
        .rev()
        .find(|&k| water_fraction(map_sums(ph, parts, map_point(ph, maps, c, k))) >= 0.5)
}

/// The depth over cell c of the surface found at lattice index `found` (None: a dry cell),
/// interpolated linearly in ψ towards the point above, at most `top`.
pub fn map_depth(
    ph: &Physics,
    parts: &[RefParticle],
    maps: &FloodMaps,
    c: usize,
    found: Option<usize>,
    top: f64,
) -> Option<f64> {
    let k = found?;
    let psi_at = |k| water_fraction(map_sums(ph, parts, map_point(ph, maps, c, k)));
    let (psi, psi_above) = (psi_at(k), psi_at(k + 1));
    let t = ((psi - 0.5) / (psi - psi_above).max(1e-6)).clamp(0.0, 1.0);
    let z = (maps.ground[c] + (k as f64 + t) * map_step(ph)).min(top);
    Some(z - maps.ground[c])
}

/// The fluid's plan velocity at x, Shepard-interpolated (0 where no fluid is near).
pub fn map_velocity(ph: &Physics, parts: &[RefParticle], x: [f64; 3]) -> [f64; 2] {
    let s = map_sums(ph, parts, x);
    if s.fluid <= 1e-6 {
        return [0.0; 2];
    }
    s.momentum.map(|m| m / s.fluid)
}

/// A map cell's record (`MapCell`): the last sample's depth and velocity, the maxima over the
/// wet samples, the time of arrival (None before) and the wet samples' count.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellRecord {
    pub depth: f64,
    pub velocity: [f64; 2],
    pub max_depth: f64,
    pub max_speed: f64,
    pub max_hazard: f64,
    pub arrival: Option<f64>,
    pub wet_samples: u32,
}

/// The record after a sample of depth `depth` (None: dry) and plan velocity `vel` at `time`.
pub fn map_accumulate(
    cell: CellRecord,
    depth: Option<f64>,
    vel: [f64; 2],
    time: f64,
    wet_depth: f64,
) -> CellRecord {
    let Some(depth) = depth else {
        return CellRecord {
            depth: 0.0,
            velocity: [0.0; 2],
            ..cell
        };
    };
    let speed = (vel[0] * vel[0] + vel[1] * vel[1]).sqrt();
    CellRecord {
        depth,
        velocity: vel,
        max_depth: cell.max_depth.max(depth),
        max_speed: cell.max_speed.max(speed),
        max_hazard: cell.max_hazard.max(depth * speed),
        arrival: cell.arrival.or((depth >= wet_depth).then_some(time)),
        wet_samples: cell.wet_samples + 1,
    }
}

/// One sample of cell c at `time`: its depth, the velocity at mid-depth, the record updated.
pub fn map_sample(
    ph: &Physics,
    parts: &[RefParticle],
    maps: &FloodMaps,
    c: usize,
    top: f64,
    cell: CellRecord,
    time: f64,
) -> CellRecord {
    let found = map_surface_search(ph, parts, maps, c, top);
    let depth = map_depth(ph, parts, maps, c, found, top);
    let vel = depth.map_or([0.0; 2], |d| {
        let [x, y] = map_cell_centre(maps, c);
        map_velocity(ph, parts, [x, y, maps.ground[c] + 0.5 * d])
    });
    map_accumulate(cell, depth, vel, time, maps.wet_depth)
}
