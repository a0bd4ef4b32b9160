//! Twin of shaders/interaction.wgsl, brute force over all pairs (no cell list), f64.

use super::{
    dot, kernel, laminar_nu, pressure, sub, RefParticle, Space, EXCLUDED, FLUID, GHOST_FREE_SLIP,
    GHOST_NO_SLIP, INLET, REPULSIVE, WALL,
};
use crate::scenario::{
    ContactGroup, DeltaSphForm, MirrorPlane, Physics, RepulsiveForm, Viscosity, WallParams,
};

struct Pair<'a> {
    ph: &'a Physics,
    eta2: f64,
    alpha: f64,
    nu: Option<f64>,
}

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

impl Pair<'_> {
    /// (dv/dt, dρ/dt) and de/dt on fluid particle i from a pressure-carrying neighbour at x_ij
    /// whose velocity is `v_cont` in continuity and pressure work, `v_visc` in viscosity;
    /// δ-SPH diffuses `psi` ([`diffused_density`], 0 for pairs without it).
    #[allow(clippy::too_many_arguments)]
    fn rates(
        &self,
        pi: &RefParticle,
        x_ij: [f64; 3],
        v_cont: [f64; 3],
        v_visc: [f64; 3],
        rho_j: f64,
        psi: f64,
        rho_ratio: f64,
    ) -> ([f64; 4], f64) {
        let (ph, m, h) = (self.ph, self.ph.particle_mass, self.ph.h);
        let r2 = dot(x_ij, x_ij);
        let f_ij = kernel::f(ph.kernel, ph.dim, h, r2.sqrt());
        let dw = x_ij.map(|x| x * f_ij);
        let v_ij = sub(pi.vel, v_cont);
        let w_ij = sub(pi.vel, v_visc);
        let drho = m * dot(v_ij, dw) * rho_ratio
            + ph.delta_sph * h * ph.c0 * 2.0 * psi * f_ij * r2 / (r2 + self.eta2) * m / rho_j;
        let mut acc = [0.0; 3];
        let mut pi_ij = 0.0;
        match self.nu {
            None => {
                let vx = dot(w_ij, x_ij);
                if vx < 0.0 {
                    let mu = h * vx / (r2 + self.eta2);
                    pi_ij = -self.alpha * ph.c0 * mu / (0.5 * (pi.rho + rho_j));
                }
            }
            Some(nu) => {
                let c = m * 4.0 * nu * r2 * f_ij / ((pi.rho + rho_j) * (r2 + self.eta2));
                for a in 0..3 {
                    acc[a] += c * w_ij[a];
                }
            }
        }
        let p = pressure(ph, pi.rho) / (pi.rho * pi.rho) + pressure(ph, rho_j) / (rho_j * rho_j);
        for a in 0..3 {
            acc[a] -= m * (p + pi_ij) * dw[a];
        }
        let de = 0.5 * m * (p * dot(v_ij, dw) + pi_ij * dot(w_ij, dw));
        ([acc[0], acc[1], acc[2], drho], de)
    }
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
    if super::elastic::is_solid(p.kind) {
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
    rates_and_energy(ph, walls, space, parts)
        .into_iter()
        .map(|(r, _)| r)
        .collect()
}

/// As [`rates`], with de/dt of the energy equation (0 for every non-fluid particle).
pub fn rates_and_energy(
    ph: &Physics,
    walls: &WallParams,
    space: &Space,
    parts: &[RefParticle],
) -> Vec<([f64; 4], f64)> {
    let h = ph.h;
    let pair = Pair {
        ph,
        eta2: 0.01 * h * h,
        alpha: match ph.viscosity {
            Viscosity::Artificial { alpha } => alpha,
            Viscosity::Laminar { .. } => 0.0,
        },
        nu: laminar_nu(ph),
    };
    let support2 = 4.0 * h * h;
    parts
        .iter()
        .enumerate()
        .map(|(i, pi)| {
            let mut r = [0.0; 4];
            let on_body = pi.body.is_some() && pi.kind != FLUID && pi.kind != EXCLUDED;
            // Boundary particles that take the fluid's force: bodies', and fixed walls' when
            // wall-pressure probes read it.
            let reacts = on_body
                || (walls.reactions
                    && !matches!(pi.kind, FLUID | EXCLUDED | INLET)
                    && !super::elastic::is_solid(pi.kind));
            if pi.kind == WALL || reacts {
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
                            let mut pr = pair.rates(&pb, x_ij, pj.vel, pj.vel, pj.rho, 0.0, 1.0).0;
                            if pi.kind != WALL {
                                pr[3] = 0.0;
                            }
                            if !loads {
                                pr[..3].fill(0.0);
                            }
                            add(&mut r, pr);
                        } else {
                            let f_ij = kernel::f(ph.kernel, ph.dim, h, r2.sqrt());
                            r[3] +=
                                ph.particle_mass * dot(sub(pi.vel, pj.vel), x_ij.map(|x| x * f_ij));
                        }
                    } else if pi.body.is_some()
                        && pj.kind != EXCLUDED
                        && pj.kind != INLET
                        && !super::elastic::is_solid(pj.kind)
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
                return (r, 0.0);
            }
            if pi.kind != FLUID {
                return (r, 0.0);
            }
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
                if super::elastic::is_solid(pj.kind) {
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
                let (pr, pe) = pair.rates(pi, x_ij, v_cont, v_visc, pj.rho, psi, ratio);
                add(&mut r, pr);
                de += pe;
            }
            // Mirror images of the fluid across each plane near i, and across pairs (edges)
            // and triples (3D vertices) of them.
            let near: Vec<&MirrorPlane> = walls
                .mirror_planes
                .iter()
                .filter(|p| dot(sub(pi.pos, p.point), p.normal) < 2.0 * h)
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
                        let psi =
                            diffused_density(ph, space, pi.rho, pj.rho, space.sub(pi.pos, pj.pos));
                        let (pr, pe) = pair.rates(pi, x_ig, v_cont, v_visc, pj.rho, psi, 1.0);
                        add(&mut r, pr);
                        de += pe;
                    }
                }
            }
            for a in 0..3 {
                r[a] += ph.gravity[a];
            }
            (r, de)
        })
        .collect()
}
