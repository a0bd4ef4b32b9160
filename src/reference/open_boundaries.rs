//! f64 reference of shaders/open_boundaries.wgsl: where a velocity inlet puts its particles,
//! and an extrapolated buffer's density.

use super::{dot, ghost, RefParticle, Space, EXCLUDED, FLUID, INLET};
use crate::scenario::{Inlet, InletPressure, Physics, WallParams};

/// An inlet particle as the inlet pass leaves it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    pub pos: [f64; 3],
    pub vel: [f64; 3],
    pub rho: f64,
    pub kind: u32,
    /// +1 where it was dormant and joined the buffer in this pass, −1 where it left the buffer
    /// to wait again (its column above the level), 0 otherwise: the pass's change of
    /// `inlet_joined`.
    pub joined: i32,
}

/// An inlet's inflow at time `t`: its speed and the distance it has carried the water
/// (`crate::hydrograph`, exact in f64).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inflow {
    pub speed: f64,
    pub distance: f64,
}

pub fn inflow_at(inlet: &Inlet, t: f64) -> Inflow {
    Inflow {
        speed: inlet.inflow.speed(t),
        distance: inlet.inflow.distance(t),
    }
}

/// What the pass makes at time `t` of particle `k` of `inlet`, whose kind is `kind` and density
/// `rho`: `None` where it leaves the particle alone (fluid already, or excluded and not due:
/// still dormant, or past the plane, i.e. fluid that left the domain).
pub fn inlet_flow(
    inlet: &Inlet,
    k: usize,
    kind: u32,
    rho: f64,
    t: f64,
    ph: &Physics,
) -> Option<Placed> {
    let inflow = inflow_at(inlet, t);
    let travel = inlet.travel(k % inlet.columns.len(), t);
    let s = inlet.distance(k, t);
    let pos = inlet.position_at(k, s);
    if !travel.flows {
        // A buffer particle whose column the level left waits where it stands.
        return (kind == INLET).then_some(Placed {
            pos,
            vel: [0.0; 3],
            rho,
            kind: EXCLUDED,
            joined: -1,
        });
    }
    let joined = match kind {
        INLET => 0,
        EXCLUDED if (-inlet.thickness..0.0).contains(&s) => 1,
        _ => return None,
    };
    Some(Placed {
        pos,
        vel: inlet.normal.map(|n| inflow.speed * n),
        // An extrapolated buffer keeps the density its last extrapolation gave it.
        rho: match (inlet.pressure, kind) {
            (InletPressure::Extrapolated, INLET) => rho,
            _ => inlet.density(pos, t, ph),
        },
        kind: if s >= 0.0 { FLUID } else { INLET },
        joined,
    })
}

/// The density of an extrapolated buffer particle at `x` of `inlet` (shaders/open_boundaries.wgsl
/// `inlet_pressure`): the fluid's pressure interpolated at the mirror image across the plane,
/// carried back along gravity, not below zero, by the inverse Tait equation.
pub fn extrapolated_density(
    inlet: &Inlet,
    k: usize,
    x: [f64; 3],
    ph: &Physics,
    walls: &WallParams,
    space: &Space,
    parts: &[RefParticle],
) -> f64 {
    let column = inlet.columns[k % inlet.columns.len()];
    let s = dot(space.sub(x, column), inlet.normal);
    let mirror = [0, 1, 2].map(|a| x[a] - 2.0 * s * inlet.normal[a]);
    let (p_m, _) = ghost::fluid_at(ph, walls, space, parts, mirror, ph.gravity);
    let p = p_m + 2.0 * s * ph.rho0 * dot(ph.gravity, inlet.normal);
    ph.rho0 * (1.0 + p.max(0.0) / ph.tait_b()).powf(1.0 / ph.gamma)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hydrograph::Hydrograph;

    fn inlet() -> Inlet {
        Inlet {
            name: "jet".into(),
            normal: [1.0, 0.0, 0.0],
            inflow: Hydrograph::constant(2.0),
            thickness: 0.04,
            spacing: 0.01,
            columns: vec![[0.1, 0.2, 0.0], [0.1, 0.21, 0.0]],
            particles: 10..30,
            pressure: InletPressure::Zero,
            level: None,
        }
    }

    fn physics() -> Physics {
        let text = include_str!("../../cases/water_injection_2d.toml");
        crate::case::load_str(text, "x.toml", &[]).unwrap().physics
    }

    #[test]
    fn layers_join_the_buffer_as_the_front_layer_leaves_it() {
        let inlet = inlet();
        let ph = &physics();
        // Layers 0..3 are the buffer at t = 0; layer 4 (particles 8, 9) waits.
        assert!((0..8).all(|k| !inlet.dormant(k)));
        assert!((8..20).all(|k| inlet.dormant(k)));
        // At t = 0.003 s every particle has moved 6 mm: layer 0 (s = 1 mm) is fluid, layer 4
        // (s = −39 mm) has joined.
        let t = 0.003;
        let first = inlet_flow(&inlet, 1, INLET, ph.rho0, t, ph).unwrap();
        assert_eq!(first.kind, FLUID);
        assert!((first.pos[0] - 0.101).abs() < 1e-12 && (first.pos[1] - 0.21).abs() < 1e-12);
        assert_eq!(first.vel, [2.0, 0.0, 0.0]);
        let joined = inlet_flow(&inlet, 8, EXCLUDED, ph.rho0, t, ph).unwrap();
        assert!(joined.joined == 1 && joined.kind == INLET);
        assert!((joined.pos[0] - (0.1 - 0.039)).abs() < 1e-12);
        // Layer 5 still waits; a fluid particle is left alone, and so is an excluded one past
        // the plane (it was fluid and left the domain).
        assert_eq!(inlet_flow(&inlet, 10, EXCLUDED, ph.rho0, t, ph), None);
        assert_eq!(inlet_flow(&inlet, 3, FLUID, ph.rho0, t, ph), None);
        assert_eq!(inlet_flow(&inlet, 0, EXCLUDED, ph.rho0, t, ph), None);
        assert_eq!(first.rho, ph.rho0);
    }

    /// An extrapolated buffer keeps the density `inlet_pressure` gave it, also when it crosses
    /// the plane; a particle joining from behind starts at ρ0.
    #[test]
    fn an_extrapolated_buffer_keeps_its_density() {
        let ph = &physics();
        let inlet = Inlet {
            pressure: InletPressure::Extrapolated,
            ..inlet()
        };
        let t = 0.003;
        let crossing = inlet_flow(&inlet, 1, INLET, 1003.5, t, ph).unwrap();
        assert_eq!((crossing.kind, crossing.rho), (FLUID, 1003.5));
        let joined = inlet_flow(&inlet, 8, EXCLUDED, 1003.5, t, ph).unwrap();
        assert_eq!((joined.kind, joined.rho), (INLET, ph.rho0));
    }

    /// An open channel's inflow: the buffer's density follows the hydrostatic pressure below
    /// its top (ρ0 above it).
    #[test]
    fn a_hydrostatic_buffer_carries_the_weight_of_the_water_above() {
        let ph = &physics();
        let inlet = Inlet {
            pressure: InletPressure::Hydrostatic {
                surface: [0.1, 0.215, 0.0],
            },
            ..inlet()
        };
        let p = inlet_flow(&inlet, 0, INLET, ph.rho0, 0.0, ph).unwrap();
        let expected = ph.rho0 * (1.0 + ph.rho0 * 9.81 * 0.015 / ph.tait_b()).powf(1.0 / ph.gamma);
        assert!(
            (p.rho - expected).abs() < 1e-9 * expected,
            "{} {expected}",
            p.rho
        );
        assert!(p.rho > ph.rho0);
        assert_eq!(inlet.density([0.0, 0.3, 0.0], 0.0, ph), ph.rho0);
    }
}
