//! Twin of shaders/flood_maps.wgsl, in the scenario's coordinates.

use super::probes::{probe_height_search, surface_height, HEIGHT_STEPS_PER_H};
use super::water_fraction::map_sums;
use super::RefParticle;
use crate::scenario::{FloodMaps, GaugeSurface, Physics};

pub fn map_cell_centre(maps: &FloodMaps, c: usize) -> [f64; 2] {
    maps.centre(c)
}

fn map_step(ph: &Physics) -> f64 {
    // `MAP_STEPS_PER_H`: the gauges' lattice (`map_foot`).
    ph.h / HEIGHT_STEPS_PER_H
}

/// The lattice point k over cell c.
pub fn map_point(ph: &Physics, maps: &FloodMaps, c: usize, k: usize) -> [f64; 3] {
    let [x, y] = map_cell_centre(maps, c);
    [x, y, maps.ground[c] + k as f64 * map_step(ph)]
}

/// The foot of cell c's lattice: its centre on the ground. A map cell's column is a depth
/// gauge's line (the same lattice of h/4 from the foot), so the twin of its search and depth is
/// the gauges' (`probes::probe_height_search`, `probes::surface_height`).
fn map_foot(ph: &Physics, maps: &FloodMaps, c: usize) -> ([f64; 3], GaugeSurface) {
    (map_point(ph, maps, c, 0), GaugeSurface::WaterFraction)
}

/// The highest lattice index k over cell c (at most `top`) where ψ ≥ ½; None where there is
/// none.
pub fn map_surface_search(
    ph: &Physics,
    parts: &[RefParticle],
    maps: &FloodMaps,
    c: usize,
    top: f64,
) -> Option<usize> {
    probe_height_search(ph, parts, map_foot(ph, maps, c), top)
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
    found.map(|k| surface_height(ph, parts, map_foot(ph, maps, c), k, top))
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
