//! Twin of shaders/interaction.wgsl, brute force over all pairs (no cell list), f64.

use super::{
    dot, kernel, laminar_nu, pressure, sub, RefParticle, Space, EXCLUDED, FLUID, GHOST_FREE_SLIP,
    GHOST_NO_SLIP, INLET, REPULSIVE, WALL,
};
use crate::scenario::{
    ContactGroup, DeltaSphForm, MirrorPlane, Physics, RepulsiveForm, Viscosity, WallParams,
};

/// ρ_i − ρ_j less, with Fourtakas et al. (2019), its hydrostatic part ρ0((1 + ρ0 g·x_ij/B)^(1/γ)
/// − 1), g without its components along periodic axes, for fluid particles x_ij apart: what
/// δ-SPH diffuses (`diffused_density` in interaction.wgsl).
pub fn diffused_density(
    ph: &Physics,
    space: &Space,
    rho_i: f64,
    rho_j: f64,
    x_ij: [f64; 3],
) -> f64 {
    match ph.delta_sph_form {
        DeltaSphForm::MolteniColagrossi => rho_i - rho_j,
        DeltaSphForm::Fourtakas => {
            let g = [0, 1, 2].map(|a| {
                if space.periodic[a] {
                    0.0
                } else {
                    ph.gravity[a]
                }
            });
            let rho_h_ij =
                ph.rho0 * ((1.0 + ph.rho0 * dot(g, x_ij) / ph.tait_b()).powf(1.0 / ph.gamma) - 1.0);
            rho_i - rho_j - rho_h_ij
        }
    }
}

/// Continuity, eq. 1 (`continuity_rate`): m_j v_ij·∇_i W_ij times ρ_i/ρ_j across materials.
pub fn continuity_rate(ph: &Physics, v_ij: [f64; 3], dw_ij: [f64; 3], rho_ratio: f64) -> f64 {
    ph.particle_mass * dot(v_ij, dw_ij) * rho_ratio
}

/// δ-SPH density diffusion, eq. 20 (Molteni & Colagrossi 2009; `delta_sph_molteni2009`), of
/// the density difference `psi` ([`diffused_density`]).
pub fn delta_sph_molteni2009(ph: &Physics, psi: f64, f_ij: f64, r2: f64, rho_j: f64) -> f64 {
    let h = ph.h;
    ph.delta_sph * h * ph.c0 * 2.0 * psi * f_ij * r2 / (r2 + 0.01 * h * h) * ph.particle_mass
        / rho_j
}

/// Monaghan's artificial viscosity Π_ij, eq. 18 (Monaghan 1992;
/// `artificial_viscosity_monaghan1992`), with coefficient `alpha`.
pub fn artificial_viscosity_monaghan1992(
    ph: &Physics,
    alpha: f64,
    w_ij: [f64; 3],
    x_ij: [f64; 3],
    rho_i: f64,
    rho_j: f64,
) -> f64 {
    let (h, r2) = (ph.h, dot(x_ij, x_ij));
    let vx = dot(w_ij, x_ij);
    if vx < 0.0 {
        let mu = h * vx / (r2 + 0.01 * h * h);
        -alpha * ph.c0 * mu / (0.5 * (rho_i + rho_j))
    } else {
        0.0
    }
}

/// Laminar viscosity, eq. 19 (Morris et al. 1997 in Lo & Shao 2002's form;
/// `laminar_viscosity_morris1997`), kinematic viscosity `nu`.
pub fn laminar_viscosity_morris1997(
    ph: &Physics,
    nu: f64,
    w_ij: [f64; 3],
    r2: f64,
    f_ij: f64,
    rho_i: f64,
    rho_j: f64,
) -> [f64; 3] {
    let h = ph.h;
    let c = ph.particle_mass * 4.0 * nu * r2 * f_ij / ((rho_i + rho_j) * (r2 + 0.01 * h * h));
    w_ij.map(|w| c * w)
}

/// Momentum, eq. 2 with σ = −P I (`pressure_acceleration`): −m_j b_ij ∇_i W_ij, b_ij =
/// P_i/ρ_i² + P_j/ρ_j² + Π_ij.
pub fn pressure_acceleration(ph: &Physics, b_ij: f64, dw_ij: [f64; 3]) -> [f64; 3] {
    dw_ij.map(|d| -(ph.particle_mass * b_ij * d))
}

/// Energy, eq. 3 (`specific_energy_rate`): ½ m_j ((P_i/ρ_i² + P_j/ρ_j²) v_ij + Π_ij w_ij)·∇W.
pub fn specific_energy_rate(
    ph: &Physics,
    pressure_term: f64,
    pi_ij: f64,
    v_ij: [f64; 3],
    w_ij: [f64; 3],
    dw_ij: [f64; 3],
) -> f64 {
    0.5 * ph.particle_mass * (pressure_term * dot(v_ij, dw_ij) + pi_ij * dot(w_ij, dw_ij))
}

/// (dv/dt, dρ/dt) and de/dt on fluid particle i from a pressure-carrying neighbour at x_ij
/// whose velocity is `v_cont` in continuity and pressure work, `v_visc` in viscosity;
/// δ-SPH diffuses `psi` ([`diffused_density`], 0 for pairs without it) (`pair_rates`).
#[allow(clippy::too_many_arguments)]
pub fn pair_rates(
    ph: &Physics,
    pi: &RefParticle,
    x_ij: [f64; 3],
    v_cont: [f64; 3],
    v_visc: [f64; 3],
    rho_j: f64,
    psi: f64,
    rho_ratio: f64,
) -> ([f64; 4], f64) {
    let r2 = dot(x_ij, x_ij);
    let f_ij = kernel::f(ph.kernel, ph.dim, ph.h, r2.sqrt());
    let dw = x_ij.map(|x| x * f_ij);
    let v_ij = sub(pi.vel, v_cont);
    let w_ij = sub(pi.vel, v_visc);
    let drho =
        continuity_rate(ph, v_ij, dw, rho_ratio) + delta_sph_molteni2009(ph, psi, f_ij, r2, rho_j);
    let (pi_ij, viscous) = match ph.viscosity {
        Viscosity::Artificial { alpha } => (
            artificial_viscosity_monaghan1992(ph, alpha, w_ij, x_ij, pi.rho, rho_j),
            [0.0; 3],
        ),
        Viscosity::Laminar { .. } => {
            let nu = laminar_nu(ph).expect("laminar viscosity has a nu");
            (
                0.0,
                laminar_viscosity_morris1997(ph, nu, w_ij, r2, f_ij, pi.rho, rho_j),
            )
        }
    };
    let p = pressure(ph, pi.rho) / (pi.rho * pi.rho) + pressure(ph, rho_j) / (rho_j * rho_j);
    let pressure = pressure_acceleration(ph, p + pi_ij, dw);
    let acc = [0, 1, 2].map(|a| viscous[a] + pressure[a]);
    let de = specific_energy_rate(ph, p, pi_ij, v_ij, w_ij, dw);
    ([acc[0], acc[1], acc[2], drho], de)
}

/// Force per unit mass of a repulsive boundary particle at x_ij: Lennard-Jones
/// D((r0/r)^12 − (r0/r)^4) x/r² for r < r0 (Monaghan 1994), or Monaghan & Kajtar (2009)
/// (K/β) x/r² Φ(r/h) with Φ(q) = (1.77/32)(1 + 5q/2 + 2q²)(2 − q)^5 for q < 2.
pub fn repulsion(ph: &Physics, walls: &WallParams, x_ij: [f64; 3]) -> [f64; 3] {
    let r2 = dot(x_ij, x_ij);
    if r2 <= 0.0 {
        return [0.0; 3];
    }
    let f = match walls.repulsive_form {
        RepulsiveForm::MonaghanKajtar => {
            let q = r2.sqrt() / ph.h;
            if q >= 2.0 {
                return [0.0; 3];
            }
            let phi = 1.77 / 32.0 * (1.0 + 2.5 * q + 2.0 * q * q) * (2.0 - q).powi(5);
            walls.repulsive_k / walls.repulsive_beta * phi / r2
        }
        RepulsiveForm::LennardJones => {
            let r0 = walls.repulsive_r0;
            if r2 >= r0 * r0 {
                return [0.0; 3];
            }
            let q2 = r0 * r0 / r2;
            walls.repulsive_d * (q2.powi(6) - q2.powi(2)) / r2
        }
    };
    x_ij.map(|x| f * x)
}

/// The contact force per unit mass between particles of which one is a body's or a solid's
/// (as `contact` in interaction.wgsl): the repulsive law F_n at x_ij with regularised Coulomb
/// friction, F_n − μ|F_n| v_t/sqrt(|v_t|² + ε²), v_t the part of v_ij across x_ij, μ the pair's
/// (`WallParams::friction_between`).
pub fn contact(
    ph: &Physics,
    walls: &WallParams,
    mu: f64,
    x_ij: [f64; 3],
    v_ij: [f64; 3],
) -> [f64; 3] {
    let f_n = repulsion(ph, walls, x_ij);
    let r2 = dot(x_ij, x_ij);
    if mu == 0.0 || r2 <= 0.0 {
        return f_n;
    }
    let vn = dot(v_ij, x_ij) / r2;
    let v_t = [0, 1, 2].map(|a| v_ij[a] - vn * x_ij[a]);
    let k = mu * dot(f_n, f_n).sqrt()
        / (dot(v_t, v_t) + walls.friction_slip * walls.friction_slip).sqrt();
    [0, 1, 2].map(|a| f_n[a] - k * v_t[a])
}

/// The contact group of a boundary particle: its body's, or the fixed walls'.
pub fn contact_group(p: &RefParticle) -> ContactGroup {
    p.body
        .map_or(ContactGroup::Walls, |b| ContactGroup::Body(b as usize))
}

/// The velocity a particle presents in contact: a solid particle's own, a boundary particle's
/// wall velocity (a body's rigid velocity at it; zero for fixed walls).
pub fn contact_velocity(p: &RefParticle) -> [f64; 3] {
    if super::is_solid(p.kind) {
        p.vel
    } else {
        p.wall_vel
    }
}

/// The velocities a fixed ghost presents (as `fixed_ghost_velocity` in interaction.wgsl): its
/// wall's in continuity, and in viscosity 2 v_wall − v_f (no-slip) or v_f (free-slip), v_f the
/// fluid velocity interpolated at it (its `vel`).
fn ghost_velocities(g: &RefParticle) -> ([f64; 3], [f64; 3]) {
    let visc = if g.kind == GHOST_NO_SLIP {
        [0, 1, 2].map(|a| 2.0 * g.wall_vel[a] - g.vel[a])
    } else {
        g.vel
    };
    (g.wall_vel, visc)
}

fn add(a: &mut [f64; 4], b: [f64; 4]) {
    for k in 0..4 {
        a[k] += b[k];
    }
}

/// (dv/dt, dρ/dt) of every particle: fluid gets everything but its elastic-solid neighbours'
/// terms (`elastic::interface_rates`), dynamic walls only dρ/dt from fluid neighbours, fixed
/// ghosts, repulsive and solid particles nothing. Body particles (of any wall treatment), and
/// with `walls.reactions` fixed walls' too, also get the fluid's force, the opposite of what
/// they exert on it; body particles also the contact force of
/// fixed walls' and other bodies' particles (that of elastic solids:
/// `elastic::contact_rates`).
pub fn rates(
    ph: &Physics,
    walls: &WallParams,
    space: &Space,
    parts: &[RefParticle],
) -> Vec<[f64; 4]> {
    interaction(ph, walls, space, parts)
        .into_iter()
        .map(|(r, _)| r)
        .collect()
}

/// As [`rates`], with de/dt of the energy equation (0 for every non-fluid particle): the twin
/// of the `interaction` entry point, by the kind of particle i.
pub fn interaction(
    ph: &Physics,
    walls: &WallParams,
    space: &Space,
    parts: &[RefParticle],
) -> Vec<([f64; 4], f64)> {
    (0..parts.len())
        .map(|i| {
            let pi = &parts[i];
            let on_body = pi.body.is_some() && pi.kind != FLUID && pi.kind != EXCLUDED;
            // Boundary particles that take the fluid's force: bodies', and fixed walls' when
            // wall-pressure probes read it.
            let reacts = on_body
                || (walls.reactions
                    && !matches!(pi.kind, FLUID | EXCLUDED | INLET)
                    && !super::is_solid(pi.kind));
            if pi.kind == WALL || reacts {
                (
                    boundary_rates(ph, walls, space, parts, i, reacts, on_body),
                    0.0,
                )
            } else if pi.kind == FLUID {
                fluid_rates(ph, walls, space, parts, i)
            } else {
                ([0.0; 4], 0.0)
            }
        })
        .collect()
}

/// The rates of boundary particle i (`boundary_rates`): a dynamic wall's dρ/dt from the fluid,
/// the reaction to the fluid's force, a body particle's contact with walls and other bodies.
pub(crate) fn boundary_rates(
    ph: &Physics,
    walls: &WallParams,
    space: &Space,
    parts: &[RefParticle],
    i: usize,
    reacts: bool,
    on_body: bool,
) -> [f64; 4] {
    let (pi, h) = (&parts[i], ph.h);
    let support2 = 4.0 * h * h;
    let mut r = [0.0; 4];
    // A fixed wall's particle under a wall-pressure sensor takes the force of the
    // fluid on the sensor's face only (`WallParams::sensors`).
    let sensor = if reacts && !on_body {
        walls.sensor_of(pi.pos, h).map(|k| &walls.sensors[k])
    } else {
        None
    };
    // A body's ghost reacts with the velocity the fluid sees in viscosity.
    let pb = match pi.kind {
        GHOST_NO_SLIP | GHOST_FREE_SLIP => RefParticle {
            vel: ghost_velocities(pi).1,
            ..*pi
        },
        _ => *pi,
    };
    for (j, pj) in parts.iter().enumerate() {
        let x_ij = space.sub(pi.pos, pj.pos);
        let r2 = dot(x_ij, x_ij);
        if j == i || r2 >= support2 {
            continue;
        }
        if pj.kind == FLUID {
            let loads = sensor.is_none_or(|s| s.faces(pj.pos));
            if reacts && pi.kind == REPULSIVE {
                // The reaction to the fluid's repulsion, −F(x_ji) = F(x_ij).
                if loads {
                    let f = repulsion(ph, walls, x_ij);
                    add(&mut r, [f[0], f[1], f[2], 0.0]);
                }
            } else if reacts {
                // The fluid's force on it too (and a dynamic particle's dρ/dt).
                let mut pr = pair_rates(ph, &pb, x_ij, pj.vel, pj.vel, pj.rho, 0.0, 1.0).0;
                if pi.kind != WALL {
                    pr[3] = 0.0;
                }
                if !loads {
                    pr[..3].fill(0.0);
                }
                add(&mut r, pr);
            } else {
                let f_ij = kernel::f(ph.kernel, ph.dim, h, r2.sqrt());
                r[3] += ph.particle_mass * dot(sub(pi.vel, pj.vel), x_ij.map(|x| x * f_ij));
            }
        } else if pi.body.is_some()
            && pj.kind != EXCLUDED
            && pj.kind != INLET
            && !super::is_solid(pj.kind)
            && pj.body != pi.body
            && !(pi.body_kinematic && (pj.body.is_none() || pj.body_kinematic))
        {
            // Contact with a fixed wall or another body (with elastic solids:
            // `elastic::contact_rates`), but not between two solids whose motion
            // is prescribed.
            let v_ij = sub(contact_velocity(pi), contact_velocity(pj));
            let mu = walls.friction_between(contact_group(pi), contact_group(pj));
            let f = contact(ph, walls, mu, x_ij, v_ij);
            add(&mut r, [f[0], f[1], f[2], 0.0]);
        }
    }
    r
}

/// The rates and de/dt of fluid particle i (`fluid_rates`): every pressure-carrying neighbour,
/// repulsive walls, the mirror images and gravity (elastic solids: `elastic::interface_rates`).
pub(crate) fn fluid_rates(
    ph: &Physics,
    walls: &WallParams,
    space: &Space,
    parts: &[RefParticle],
    i: usize,
) -> ([f64; 4], f64) {
    let pi = &parts[i];
    let support2 = 4.0 * ph.h * ph.h;
    let mut r = [0.0; 4];
    let mut de = 0.0;
    for (j, pj) in parts.iter().enumerate() {
        let x_ij = space.sub(pi.pos, pj.pos);
        let r2 = dot(x_ij, x_ij);
        if j == i || r2 >= support2 {
            continue;
        }
        if pj.kind == REPULSIVE {
            let f = repulsion(ph, walls, x_ij);
            add(&mut r, [f[0], f[1], f[2], 0.0]);
            continue;
        }
        if super::is_solid(pj.kind) {
            // Fluid–solid pairs: super::elastic::interface_rates.
            continue;
        }
        let ghost = pj.kind == GHOST_NO_SLIP || pj.kind == GHOST_FREE_SLIP;
        let ratio = if ghost { pi.rho / pj.rho } else { 1.0 };
        // Ghosts hold the interpolated fluid velocity: the wall's velocity in continuity,
        // the no-slip or free-slip ghost velocity in viscosity.
        let (v_cont, v_visc) = if ghost {
            ghost_velocities(pj)
        } else {
            (pj.vel, pj.vel)
        };
        let psi = if pj.kind == FLUID {
            diffused_density(ph, space, pi.rho, pj.rho, x_ij)
        } else {
            0.0
        };
        let (pr, pe) = pair_rates(ph, pi, x_ij, v_cont, v_visc, pj.rho, psi, ratio);
        add(&mut r, pr);
        de += pe;
    }
    let (mr, me) = mirror_rates(ph, walls, space, parts, pi);
    add(&mut r, mr);
    de += me;
    for a in 0..3 {
        r[a] += ph.gravity[a];
    }
    (r, de)
}

/// The mirror images of the fluid across each plane near fluid particle `pi`, and across pairs
/// (edges) and triples (3D vertices) of them (`mirror_rates`).
pub(crate) fn mirror_rates(
    ph: &Physics,
    walls: &WallParams,
    space: &Space,
    parts: &[RefParticle],
    pi: &RefParticle,
) -> ([f64; 4], f64) {
    let support2 = 4.0 * ph.h * ph.h;
    let (mut r, mut de) = ([0.0; 4], 0.0);
    let near: Vec<&MirrorPlane> = walls
        .mirror_planes
        .iter()
        .filter(|p| dot(sub(pi.pos, p.point), p.normal) < 2.0 * ph.h)
        .collect();
    let mut chains: Vec<Vec<&MirrorPlane>> = near.iter().map(|p| vec![*p]).collect();
    for a in 0..near.len() {
        for b in a + 1..near.len() {
            chains.push(vec![near[a], near[b]]);
            for c in b + 1..near.len() {
                chains.push(vec![near[a], near[b], near[c]]);
            }
        }
    }
    for chain in chains {
        for pj in parts.iter().filter(|p| p.kind == FLUID) {
            let (mut x_g, mut v_cont, mut v_visc) = (pj.pos, pj.vel, pj.vel);
            let reflect = |v: [f64; 3], n: [f64; 3]| {
                let vn = dot(v, n);
                [0, 1, 2].map(|a| v[a] - 2.0 * vn * n[a])
            };
            for plane in chain.iter().rev() {
                let n = plane.normal;
                let d = dot(sub(x_g, plane.point), n);
                x_g = [0, 1, 2].map(|a| x_g[a] - 2.0 * d * n[a]);
                v_cont = reflect(v_cont, n);
                v_visc = if plane.no_slip {
                    v_visc.map(|v| -v)
                } else {
                    reflect(v_visc, n)
                };
            }
            let x_ig = sub(pi.pos, x_g);
            if dot(x_ig, x_ig) < support2 {
                // The ghost's hydrostatic part is that of its fluid particle, at x_j.
                let psi = diffused_density(ph, space, pi.rho, pj.rho, space.sub(pi.pos, pj.pos));
                let (pr, pe) = pair_rates(ph, pi, x_ig, v_cont, v_visc, pj.rho, psi, 1.0);
                add(&mut r, pr);
                de += pe;
            }
        }
    }
    (r, de)
}
