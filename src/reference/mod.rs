//! The CPU (f64) twin of `src/sph` and `shaders/`, with the same stage names. Brute force and
//! plain: it exists to test the GPU kernels, not to run cases.

// Component loops written as in the equations read better than iterator chains here.
#![allow(clippy::needless_range_loop)]

pub mod bodies;
pub mod cell_list;
pub mod density_filter;
pub mod elastic;
pub mod flood_maps;
pub mod ghost;
pub mod integrate;
pub mod interaction;
pub mod mls;
pub mod open_boundaries;
pub mod probes;
pub mod total_lagrangian;
pub mod water_fraction;

use crate::kernel;
use crate::scenario::{Kind, Physics, Viscosity};

/// A particle as the reference sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefParticle {
    pub pos: [f64; 3],
    pub vel: [f64; 3],
    pub rho: f64,
    /// 0 fluid, 1 wall (as in the GPU code word).
    pub kind: u32,
    /// The moving body the particle belongs to, if any.
    pub body: Option<u32>,
    /// Whether that body moves as prescribed whatever its load (fixed, sine, series, the moving
    /// tank): its contact with fixed walls and other such bodies is left out (interaction.wgsl,
    /// `contact_counts`).
    pub body_kinematic: bool,
    /// The velocity of the solid a boundary particle belongs to, at the particle: a body's
    /// rigid velocity, zero for fixed walls (and unused for fluid). A fixed ghost's `vel` is
    /// the fluid velocity interpolated at it; this is the wall it stands for.
    pub wall_vel: [f64; 3],
    /// The acceleration of that solid at the particle (zero for fixed walls): a body's fixed
    /// ghosts carry the fluid pressure along g − wall_acc.
    pub wall_acc: [f64; 3],
}

/// The particle kinds as the GPU's code word holds them (`Kind`), and the excluded mark.
pub const FLUID: u32 = Kind::Fluid as u32;
pub const WALL: u32 = Kind::Wall as u32;
pub const GHOST_NO_SLIP: u32 = Kind::GhostNoSlip as u32;
pub const GHOST_FREE_SLIP: u32 = Kind::GhostFreeSlip as u32;
pub const REPULSIVE: u32 = Kind::Repulsive as u32;
pub const SOLID: u32 = Kind::Solid as u32;
pub const SOLID_CLAMPED: u32 = Kind::SolidClamped as u32;
pub const INLET: u32 = Kind::Inlet as u32;
pub const EXCLUDED: u32 = crate::layout::KIND_EXCLUDED;

/// An elastic solid's particle, free or clamped.
pub fn is_solid(kind: u32) -> bool {
    kind == SOLID || kind == SOLID_CLAMPED
}

/// Tait equation of state, P = B((ρ/ρ0)^γ − 1).
pub fn pressure(ph: &Physics, rho: f64) -> f64 {
    crate::eos::Tait::of(ph).pressure(rho)
}

/// c = c0 (ρ/ρ0)^((γ−1)/2).
pub fn sound_speed(ph: &Physics, rho: f64) -> f64 {
    ph.c0 * (rho / ph.rho0).powf(0.5 * (ph.gamma - 1.0))
}

pub fn laminar_nu(ph: &Physics) -> Option<f64> {
    match ph.viscosity {
        Viscosity::Laminar { nu } => Some(nu),
        Viscosity::Artificial { .. } => None,
    }
}

/// Where particles live: the domain extent and its periodic axes (minimum-image distances).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Space {
    pub extent: [f64; 3],
    pub periodic: [bool; 3],
}

impl Space {
    /// No periodic axis.
    pub const OPEN: Space = Space {
        extent: [0.0; 3],
        periodic: [false; 3],
    };

    pub fn of(sc: &crate::scenario::Scenario) -> Space {
        Space {
            extent: [0, 1, 2].map(|a| sc.domain.max[a] - sc.domain.min[a]),
            periodic: sc.periodic,
        }
    }

    /// a − b, the nearest image on periodic axes.
    pub fn sub(&self, a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|k| {
            let d = a[k] - b[k];
            if self.periodic[k] {
                d - self.extent[k] * (d / self.extent[k]).round()
            } else {
                d
            }
        })
    }
}

pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
