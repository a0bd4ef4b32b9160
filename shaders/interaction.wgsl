// The neighbour sum of weakly-compressible SPH, one invocation per particle in cell order
// (gather, no atomics): rate = (dv/dt, dρ/dt), and de/dt when ENERGY. Equations as numbered in
// docs/equations.md; why each term is written so: docs/design/interaction.md.
//   continuity, eq. 1 (Monaghan 1992), with δ-SPH between fluid particles, eq. 20 (Molteni &
//     Colagrossi 2009; Fourtakas et al. 2019), and the seed's density-rate correction for
//     fluid–ghost and fluid–solid pairs, eq. 14;
//   momentum, eq. 2 with σ = −P I, with artificial viscosity, eq. 18 (Monaghan 1992), or
//     laminar viscosity, eq. 19 (Morris et al. 1997; Lo & Shao 2002); energy, eq. 3;
//   walls: dynamic particles, eq. 22 (Crespo et al. 2007); fixed ghosts, eqs. 13 and 15 (values
//     from ghost.wgsl); repulsive particles, eq. 23 (Monaghan 1994; Monaghan & Kajtar 2009);
//     mirror planes, eq. 12; fluid–solid pairs, eq. 28 (the seed's third ghost kind);
//   the reaction of the fluid's force on body particles (and fixed-wall particles, when
//     WALL_REACTIONS), which bodies.wgsl sums for eqs. 5–6; contact with friction, eq. 24.

@group(0) @binding(1) var<storage, read> pos: array<Pos>;
@group(0) @binding(2) var<storage, read> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> code: array<u32>;
@group(0) @binding(4) var<storage, read> cell_start: array<u32>;
@group(0) @binding(5) var<storage, read_write> rate: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> energy_rate: array<f32>;
@group(0) @binding(9) var<storage, read> solid: array<SolidState>;

// The state of particle i that every pair term needs.
struct Particle {
    v: vec3<f32>,
    rho: f32,
    p_over_rho2: f32,
}

struct PairRates {
    rate: vec4<f32>,    // (dv/dt, dρ/dt)
    de: f32,            // de/dt
}

// The hydrostatic strain of a pair is ε_ij = k·x_ij with k = ρ0 g_h/B, g_h gravity without its
// periodic components; `hydrostatic_series` = (ρ0/γ, (1/γ − 1)/2, (1/γ − 2)/3) are the
// coefficients of its expansion. Both are set once per invocation, when HYDROSTATIC_DIFFUSION.
var<private> hydrostatic_k: vec3<f32>;
var<private> hydrostatic_series: vec3<f32>;

fn set_hydrostatic_coefficients() {
    hydrostatic_k = select(params.gravity, vec3<f32>(0.0), periodic_axes()) * (params.rho0 / params.tait_b);
    let a = 1.0 / params.gamma;
    hydrostatic_series = vec3<f32>(params.rho0 * a, 0.5 * (a - 1.0), (a - 2.0) / 3.0);
}

// ρ_i − ρ_j less its hydrostatic part ρ^H_i − ρ^H_j (docs/equations.md eq. 20) for the fluid particles i
// and j at x_ij = x_i − x_j apart: what δ-SPH diffuses. ρ^H_ij = ρ0((1 + ε)^(1/γ) − 1) is
// summed to third order in ε: |ε| ≤ 2γ g h/c0² is about 0.01 in a case whose c0 keeps it weakly
// compressible, so the rest, 0.03 ρ0 ε⁴, is far below f32 rounding, and unlike pow(1 + ε, 1/γ) − 1
// the series does not lose ε's low bits to the 1 (nor cost a pow per pair).
fn diffused_density(rho_i: f32, rho_j: f32, x_ij: vec3<f32>) -> f32 {
    if (!HYDROSTATIC_DIFFUSION) {
        return rho_i - rho_j;
    }
    let e = dot(hydrostatic_k, x_ij);
    let c = hydrostatic_series;
    let rho_h_ij = c.x * e * (1.0 + c.y * e * (1.0 + c.z * e));
    return rho_i - rho_j - rho_h_ij;
}

// The terms of a pair, each one equation (docs/equations.md); `pair_rates` adds them up in the
// order that fixes their f32 rounding, shared by the f64 twin (src/reference/interaction.rs).

// Continuity, eq. 1: m_j v_ij·∇_i W_ij, times ρ_i/ρ_j across materials (eq. 14).
fn continuity_rate(v_ij: vec3<f32>, dw_ij: vec3<f32>, rho_ratio: f32) -> f32 {
    return params.mass * dot(v_ij, dw_ij) * rho_ratio;
}

// δ-SPH density diffusion, eq. 20 (Molteni & Colagrossi 2009): 2 δ h c0 ψ_ij F_ij r²/(r² + η²)
// m_j/ρ_j, ψ the density difference `diffused_density` gives (Fourtakas et al. 2019's without
// its hydrostatic part).
fn delta_sph_molteni2009(psi: f32, f_ij: f32, r2: f32, rho_j: f32) -> f32 {
    return params.delta_coef * 2.0 * psi * f_ij * r2 / (r2 + params.eta2) * params.mass / rho_j;
}

// Monaghan's artificial viscosity Π_ij, eq. 18 (Monaghan 1992), of an approaching pair.
fn artificial_viscosity_monaghan1992(w_ij: vec3<f32>, x_ij: vec3<f32>, r2: f32, rho_i: f32, rho_j: f32) -> f32 {
    let vx = dot(w_ij, x_ij);
    if (vx < 0.0) {
        let mu = params.h * vx / (r2 + params.eta2);
        return -params.alpha * params.c0 * mu / (0.5 * (rho_i + rho_j));
    }
    return 0.0;
}

// Laminar viscosity, eq. 19 (Morris et al. 1997, in Lo & Shao 2002's form).
fn laminar_viscosity_morris1997(w_ij: vec3<f32>, r2: f32, f_ij: f32, rho_i: f32, rho_j: f32) -> vec3<f32> {
    return params.mass * 4.0 * params.nu * r2 * f_ij / ((rho_i + rho_j) * (r2 + params.eta2)) * w_ij;
}

// Momentum, eq. 2 with σ = −P I: −m_j (P_i/ρ_i² + P_j/ρ_j² + Π_ij) ∇_i W_ij; `b_ij` is the
// bracket.
fn pressure_acceleration(b_ij: f32, dw_ij: vec3<f32>) -> vec3<f32> {
    return -(params.mass * b_ij * dw_ij);
}

// Energy, eq. 3: ½ m_j ((P_i/ρ_i² + P_j/ρ_j²) v_ij + Π_ij w_ij)·∇_i W_ij, the specific internal
// energy's rate.
fn specific_energy_rate(pressure_term: f32, pi_ij: f32, v_ij: vec3<f32>, w_ij: vec3<f32>, dw_ij: vec3<f32>) -> f32 {
    return 0.5 * params.mass * (pressure_term * dot(v_ij, dw_ij) + pi_ij * dot(w_ij, dw_ij));
}

// Contribution to fluid particle i of a pressure-carrying neighbour j (fluid, dynamic wall,
// ghost or mirror image) at x_ij = x_i − x_j, diffusing the density difference `psi`
// (`diffused_density`, 0 for pairs without δ-SPH). A wall neighbour has two velocities: `v_cont`
// for continuity and pressure work (the wall's own, free-slip for mirror images) and `v_visc`
// for the viscous terms (the no-slip or free-slip ghost velocity), as in Adami, Hu & Adams
// (2012); with the no-slip velocity in continuity too, a fast tangential surge drains the
// density next to the wall and sucks fluid through it.
fn pair_rates(pi: Particle, x_ij: vec3<f32>, r2: f32, v_cont: vec3<f32>, v_visc: vec3<f32>, rho_j: f32, psi: f32, rho_ratio: f32) -> PairRates {
    let v_ij = pi.v - v_cont;
    let w_ij = pi.v - v_visc;
    let f_ij = kernel_f(sqrt(r2) / params.h);
    let dw_ij = x_ij * f_ij;
    let drho = continuity_rate(v_ij, dw_ij, rho_ratio) + delta_sph_molteni2009(psi, f_ij, r2, rho_j);
    var acc = vec3<f32>(0.0);
    var pi_ij = 0.0;
    if (VISCOSITY == VISCOSITY_ARTIFICIAL) {
        pi_ij = artificial_viscosity_monaghan1992(w_ij, x_ij, r2, pi.rho, rho_j);
    } else {
        acc += laminar_viscosity_morris1997(w_ij, r2, f_ij, pi.rho, rho_j);
    }
    let pressure_term = pi.p_over_rho2 + pressure_of(rho_j) / (rho_j * rho_j);
    acc += pressure_acceleration(pressure_term + pi_ij, dw_ij);
    var de = 0.0;
    if (ENERGY) {
        de = specific_energy_rate(pressure_term, pi_ij, v_ij, w_ij, dw_ij);
    }
    return PairRates(vec4<f32>(acc, drho), de);
}

// (dv/dt, dρ/dt) on i from a neighbour j of the other material (fluid–solid), docs/equations.md eq. 28:
// b_i, b_j are P/ρ² of each (P_g for the solid), m_j the neighbour's mass.
fn interface_rates(b_i: f32, v_i: vec3<f32>, rho_i: f32, b_j: f32, v_j: vec3<f32>, rho_j: f32, m_j: f32, x_ij: vec3<f32>, r2: f32) -> vec4<f32> {
    let f_ij = kernel_f(sqrt(r2) / params.h);
    let dw_ij = x_ij * f_ij;
    let v_ij = v_i - v_j;
    let drho = m_j * dot(v_ij, dw_ij) * rho_i / rho_j;
    var acc = -m_j * (b_i + b_j) * dw_ij;
    if (VISCOSITY == VISCOSITY_ARTIFICIAL) {
        let vx = dot(v_ij, x_ij);
        if (vx < 0.0) {
            let mu = params.h * vx / (r2 + params.eta2);
            acc += m_j * params.alpha * params.c0 * mu / (0.5 * (rho_i + rho_j)) * dw_ij;
        }
    } else {
        acc += m_j * 4.0 * params.nu * r2 * f_ij / ((rho_i + rho_j) * (r2 + params.eta2)) * v_ij;
    }
    return vec4<f32>(acc, drho);
}

// Contact between particles of masses m_a and m_b that are not both fixed: a solid particle
// (its material's mass m_s) with a moving body's particle, which carries the fluid's mass m_f
// (bodies.wgsl sums m_f × its rate), or with a particle of another elastic body. The pair force
// is 2 m_a m_b/(m_a + m_b) times the law per unit mass, equal and opposite (1 × the law between
// equal masses); this is the acceleration factor of the side whose partner has mass `m_other`.
fn contact_weight(m_self: f32, m_other: f32) -> f32 {
    return 2.0 * m_other / (m_self + m_other);
}

// Acceleration of solid particle i by everything outside its own elastic body: the fluid's load
// (interface_rates) and contact (the repulsive law of the walls with friction, `contact`) with boundary
// particles (fixed walls, as for fluid; moving bodies' particles of any wall treatment, with
// contact_weight) and with the particles of other elastic bodies (contact_weight of the two
// materials' masses).
fn solid_loads(i: u32) -> vec3<f32> {
    let p_i = pos[i];
    let vr_i = velrho[i];
    let s_i = solid[solid_slot(i)];
    let m_i = material_of(s_i).mass;
    let v_i = vr_i.xyz;
    let b_i = s_i.interface_p / (vr_i.w * vr_i.w);
    let body_i = s_i.body;
    let group_i = params.friction_first_solid + body_i;
    let support2 = 4.0 * params.h * params.h;
    var r = vec3<f32>(0.0);
    var ranges: NeighbourRanges;
    let n_ranges = neighbour_ranges(p_i, &ranges);
    for (var s = 0u; s < n_ranges; s++) {
        for (var j = ranges[s].x; j < ranges[s].y; j++) {
            let kind_j = code_kind(code[j]);
            // Inlet buffers are open flow, not walls: no contact.
            if (kind_j == KIND_EXCLUDED || kind_j == KIND_INLET || j == i) {
                continue;
            }
            let x_ij = rel_pos(p_i, pos[j]);
            let r2 = dot(x_ij, x_ij);
            if (r2 >= support2) {
                continue;
            }
            if (kind_j == KIND_FLUID) {
                let vr_j = velrho[j];
                r += interface_rates(b_i, vr_i.xyz, vr_i.w, pressure_of(vr_j.w) / (vr_j.w * vr_j.w), vr_j.xyz, vr_j.w, params.mass, x_ij, r2).xyz;
            } else if (!is_solid(kind_j)) {
                var k = 1.0;
                if (is_body_particle(particle_id(j))) {
                    k = contact_weight(m_i, params.mass);
                }
                let mu = friction_between(group_i, boundary_group(particle_id(j)));
                r += k * contact(x_ij, r2, v_i - contact_velocity(j), mu);
            } else {
                let s_j = solid[solid_slot(j)];
                if (s_j.body != body_i) {
                    let mu = friction_between(group_i, params.friction_first_solid + s_j.body);
                    r += contact_weight(m_i, material_of(s_j).mass) * contact(x_ij, r2, v_i - velrho[j].xyz, mu);
                }
            }
        }
    }
    return r;
}

// Contact between particles of which at least one is a body's or a solid's (against walls,
// bodies and solids; fluid against repulsive walls keeps `repulsion` alone), per unit mass:
// the repulsive law as the normal force F_n, with regularised Coulomb friction,
//   F = F_n − μ |F_n| v_t / sqrt(|v_t|² + ε²),
// v_t the part of the relative velocity v_ij = v_i − v_j across x_ij (the velocities of
// `contact_velocity`), ε = params.friction_slip. Equal and opposite for a pair (x_ji = −x_ij,
// v_ji = −v_ij); friction acts only where the normal force does (r < r0 for Lennard-Jones). μ is
// the pair's (`friction_between`).
fn contact(x_ij: vec3<f32>, r2: f32, v_ij: vec3<f32>, mu: f32) -> vec3<f32> {
    let f_n = repulsion(x_ij, r2);
    if (mu == 0.0 || r2 <= 0.0) {
        return f_n;
    }
    let n = x_ij * inverseSqrt(r2);
    let v_t = v_ij - dot(v_ij, n) * n;
    let e = params.friction_slip;
    return f_n - (mu * length(f_n) * inverseSqrt(dot(v_t, v_t) + e * e)) * v_t;
}

// The Coulomb μ between contact groups a and b (0 the fixed walls, 1 + body for a body's
// particles, friction_first_solid + body for a solid's): the `[[friction]]` table's entry, or
// the walls' μ when the case has no pairs.
fn friction_between(a: u32, b: u32) -> f32 {
    if (params.friction_groups == 0u) {
        return params.friction;
    }
    let k = a * params.friction_groups + b;
    return params.friction_table[k / 4u][k % 4u];
}

// The contact group of the boundary particle with id `id`: its body's, or the fixed walls'.
fn boundary_group(id: u32) -> u32 {
    if (is_body_particle(id)) {
        return 1u + tables.body_particles[id - params.body_id_base].body;
    }
    return 0u;
}

// The velocity particle j presents in contact: a solid particle's own, a body particle's rigid
// velocity u_c + ω × r (a fixed ghost stores the fluid's), zero for fixed walls.
fn contact_velocity(j: u32) -> vec3<f32> {
    if (is_solid(code_kind(code[j]))) {
        return velrho[j].xyz;
    }
    let id = particle_id(j);
    if (is_body_particle(id)) {
        let bp = tables.body_particles[id - params.body_id_base];
        return body_wall_motion(tables.bodies[bp.body], bp.r).velocity;
    }
    return vec3<f32>(0.0);
}

// Force (per unit mass) of a repulsive boundary particle at x_ij: Lennard-Jones (Monaghan 1994)
// or Monaghan & Kajtar (2009, eq. 3.1 with equal masses): (K/β) x/r² Φ(r/h), Φ the Wendland C4
// shape (1.77/32)(1 + 5q/2 + 2q²)(2 − q)^5, q < 2.
fn repulsion(x_ij: vec3<f32>, r2: f32) -> vec3<f32> {
    if (params.repulsive_form == REPULSIVE_MONAGHAN_KAJTAR) {
        let q = sqrt(r2) / params.h;
        if (q >= 2.0 || r2 <= 0.0) {
            return vec3<f32>(0.0);
        }
        let t = 2.0 - q;
        let phi = 1.77 / 32.0 * (1.0 + 2.5 * q + 2.0 * q * q) * t * t * t * t * t;
        return params.repulsive_k_over_beta * phi / r2 * x_ij;
    }
    let r0 = params.repulsive_r0;
    if (r2 >= r0 * r0 || r2 <= 0.0) {
        return vec3<f32>(0.0);
    }
    let q2 = r0 * r0 / r2;
    let q4 = q2 * q2;
    let q12 = q4 * q4 * q4;
    return params.repulsive_d * (q12 - q4) / r2 * x_ij;
}

// The two velocities of a fixed ghost (see pair_rates): `cont`, the wall's own, for continuity;
// `visc`, the no-slip 2 v_wall − v_f or free-slip v_f, for viscosity; v_f is the fluid velocity
// interpolated at the ghost (stored in its velrho by ghost.wgsl). v_wall is zero for the ghosts
// of fixed walls and the rigid velocity u_c + ω × (R r) of the body for a body's ghosts (the
// seed's second ghost kind; bodies.wgsl's placement, from the pose of this step).
struct GhostVelocity {
    cont: vec3<f32>,
    visc: vec3<f32>,
}

fn fixed_ghost_velocity(kind: u32, id: u32, v_f: vec3<f32>) -> GhostVelocity {
    var v_wall = vec3<f32>(0.0);
    if (is_body_particle(id)) {
        let bp = tables.body_particles[id - params.body_id_base];
        v_wall = body_wall_motion(tables.bodies[bp.body], bp.r).velocity;
    }
    return GhostVelocity(v_wall, select(v_f, 2.0 * v_wall - v_f, kind == KIND_GHOST_NO_SLIP));
}

const NO_PLANE: u32 = 0xFFFFFFFFu;
const NO_BODY: u32 = 0xFFFFFFFFu;

// Whether boundary particle `id_j` belongs to a fixed wall or to a body other than `body_i`
// (contact between a body and itself is not a thing).
fn other_solid(body_i: u32, id_j: u32) -> bool {
    return !is_body_particle(id_j) || tables.body_particles[id_j - params.body_id_base].body != body_i;
}

// Whether body `b` moves as the case prescribes whatever its load (`kind = "fixed"`, `"sine"`
// or `"series"`, the moving tank too).
fn body_kinematic(b: u32) -> bool {
    return (tables.bodies[b].flags & BODY_KINEMATIC) != 0u;
}

// Whether the contact of a body particle (of a kinematic body: `kinematic_i`) with the wall or
// other body's particle `id_j` counts: not when neither side's motion answers the force (a
// fixed building on the street, a paddle sliding on the floor, another prescribed body), where
// it would only add their standing contact to the load written for the body.
fn contact_counts(kinematic_i: bool, id_j: u32) -> bool {
    return !kinematic_i || (is_body_particle(id_j) && !body_kinematic(tables.body_particles[id_j - params.body_id_base].body));
}

// Velocity of a ghost across `plane`: normal part reversed (free-slip) or all (no-slip).
fn ghost_velocity(v: vec3<f32>, plane: MirrorPlane) -> vec3<f32> {
    return select(reflect_vec(v, plane.normal), -v, plane.no_slip != 0u);
}

// Ghosts seen by i through the chain of planes chain[0], …, chain[n − 1] (one plane; two at an
// edge, the corner image without which fluid leaks out of corners; three at a 3D vertex).
// `image` is i reflected through the chain the opposite way, R_n … R_1 x_i, so that the ghosts
// of i's neighbourhood, R_1 … R_n x_j, are the fluid particles near `image`, transformed back.
// A ghost carries its fluid particle's density, and with it that particle's hydrostatic part:
// δ-SPH takes that out at the particle's own position, `p_i` − x_j (the dynamic density is
// mirrored, so a tank at rest has nothing to diffuse).
fn image_rates(pi: Particle, p_i: Pos, image: vec3<f32>, chain: vec3<u32>, n: u32) -> PairRates {
    var out = PairRates(vec4<f32>(0.0), 0.0);
    let support2 = 4.0 * params.h * params.h;
    let at = pos_of_point(image);
    // The fluid of each slot around, which comes first in it (shaders/lib/neighbours.wgsl).
    var rows: NeighbourRanges;
    var w = slot_walk(at, &rows, false);
    for (; walk_on(&w, &rows); w.j++) {
        let j = w.j;
        let x = rel_pos(at, pos[j]);
        let r2 = dot(x, x);
        if (r2 >= support2) {
            continue;
        }
        var x_ig = x;
        var v_cont = velrho[j].xyz;
        var v_visc = v_cont;
        for (var c = n; c > 0u; c--) {
            let plane = tables.mirror_planes[chain[c - 1u]];
            x_ig = reflect_vec(x_ig, plane.normal);
            v_cont = reflect_vec(v_cont, plane.normal);
            v_visc = ghost_velocity(v_visc, plane);
        }
        let psi = diffused_density(pi.rho, velrho[j].w, rel_pos(p_i, pos[j]));
        let pr = pair_rates(pi, x_ig, r2, v_cont, v_visc, velrho[j].w, psi, 1.0);
        out.rate += pr.rate;
        out.de += pr.de;
    }
    return out;
}

fn add_rates(a: PairRates, b: PairRates) -> PairRates {
    return PairRates(a.rate + b.rate, a.de + b.de);
}

// Sum over the mirror images across the planes within 2h of i, and across every pair and
// triple of them (edges and 3D vertices).
fn mirror_rates(i: u32, pi: Particle) -> PairRates {
    var out = PairRates(vec4<f32>(0.0), 0.0);
    let xi = domain_pos(pos[i]);
    let reach = 2.0 * params.h;
    for (var k1 = 0u; k1 < params.n_mirror_planes; k1++) {
        let p1 = tables.mirror_planes[k1];
        if (dot(xi - p1.point, p1.normal) >= reach) {
            continue;
        }
        let once = reflect_point(xi, p1);
        out = add_rates(out, image_rates(pi, pos[i], once, vec3<u32>(k1, 0u, 0u), 1u));
        for (var k2 = k1 + 1u; k2 < params.n_mirror_planes; k2++) {
            let p2 = tables.mirror_planes[k2];
            if (dot(xi - p2.point, p2.normal) >= reach) {
                continue;
            }
            let twice = reflect_point(once, p2);
            out = add_rates(out, image_rates(pi, pos[i], twice, vec3<u32>(k1, k2, 0u), 2u));
            for (var k3 = k2 + 1u; k3 < params.n_mirror_planes; k3++) {
                let p3 = tables.mirror_planes[k3];
                if (dot(xi - p3.point, p3.normal) < reach) {
                    out = add_rates(out, image_rates(pi, pos[i], reflect_point(twice, p3), vec3<u32>(k1, k2, k3), 3u));
                }
            }
        }
    }
    return out;
}

// dρ/dt of a fixed dynamic wall particle, eq. 22: continuity from the fluid alone. A slot holds
// its fluid first (shaders/lib/neighbours.wgsl), so the walk leaves each slot at its first
// particle of another kind and never tests the walls around.
fn wall_continuity(i: u32) -> f32 {
    let p_i = pos[i];
    let v_i = velrho[i].xyz;
    let support2 = 4.0 * params.h * params.h;
    var drho = 0.0;
    var rows: NeighbourRanges;
    var w = slot_walk(p_i, &rows, false);
    for (; walk_on(&w, &rows); w.j++) {
        let j = w.j;
        let x_ij = rel_pos(p_i, pos[j]);
        let r2 = dot(x_ij, x_ij);
        if (r2 < support2) {
            drho += params.mass * dot(v_i - velrho[j].xyz, x_ij * kernel_f(sqrt(r2) / params.h));
        }
    }
    return drho;
}

// The rates of a boundary particle i that takes the fluid's force (a body's particle of any
// wall treatment, a fixed wall's with WALL_REACTIONS): a dynamic one's dρ/dt from the fluid
// (eq. 22), the reaction to the fluid's force (for bodies.wgsl's load and the wall
// sensors) and a body particle's contact with walls, other bodies and solids (eq. 24). A fixed
// wall's particle has no contact, so it leaves each slot at the slot's last fluid particle,
// as `wall_continuity` does.
fn boundary_rates(i: u32, kind_i: u32, on_body: bool) -> vec4<f32> {
    let id_i = particle_id(i);
    var body_i = NO_BODY;
    var kinematic_i = false;
    if (on_body) {
        body_i = tables.body_particles[id_i - params.body_id_base].body;
        kinematic_i = body_kinematic(body_i);
    }
    let p_i = pos[i];
    let vr_i = velrho[i];
    var v_i = vr_i.xyz;
    if (is_ghost(kind_i)) {
        // A body's ghost takes its reaction with the velocity the fluid sees in viscosity.
        v_i = fixed_ghost_velocity(kind_i, id_i, v_i).visc;
    }
    let pi = Particle(v_i, vr_i.w, pressure_of(vr_i.w) / (vr_i.w * vr_i.w));
    let support2 = 4.0 * params.h * params.h;
    // Under a sensor on a fixed wall, only the fluid over the sensor's face loads i.
    var sensor = NO_SENSOR;
    var x_i = vec3<f32>(0.0);
    if (WALL_REACTIONS && !on_body) {
        x_i = domain_pos(p_i);
        sensor = owning_sensor(x_i);
    }
    // The rigid velocity a body particle presents in contact (friction only).
    var v_contact_i = vec3<f32>(0.0);
    if (on_body && (params.friction != 0.0 || params.friction_groups != 0u)) {
        v_contact_i = contact_velocity(i);
    }
    var r = vec4<f32>(0.0);
    var rows: NeighbourRanges;
    var w = slot_walk(p_i, &rows, on_body);
    for (; walk_on(&w, &rows); w.j++) {
        let j = w.j;
        let x_ij = rel_pos(p_i, pos[j]);
        let r2 = dot(x_ij, x_ij);
        if (r2 >= support2 || j == i) {
            continue;
        }
        let kind_j = code_kind(code[j]);
        if (kind_j == KIND_FLUID) {
            let vr_j = velrho[j];
            let loads = sensor == NO_SENSOR || faces_sensor(tables.wall_sensors[sensor], x_i - x_ij);
            if (is_repulsive(kind_i)) {
                // The reaction to the fluid's repulsion, −F(x_ji) = F(x_ij).
                if (loads) {
                    r += vec4<f32>(repulsion(x_ij, r2), 0.0);
                }
            } else {
                // The reaction to the fluid's pressure and viscous force; a dynamic
                // wall or body particle also its dρ/dt (ghosts have none).
                let pr = pair_rates(pi, x_ij, r2, vr_j.xyz, vr_j.xyz, vr_j.w, 0.0, 1.0).rate;
                let force = select(vec3<f32>(0.0), pr.xyz, loads);
                r += vec4<f32>(force, select(0.0, pr.w, kind_i == KIND_WALL));
            }
        } else if (body_i != NO_BODY && kind_j != KIND_EXCLUDED && is_solid(kind_j)) {
            // Contact with an elastic solid.
            let s_j = solid[solid_slot(j)];
            let mu = friction_between(1u + body_i, params.friction_first_solid + s_j.body);
            r += vec4<f32>(contact_weight(params.mass, material_of(s_j).mass) * contact(x_ij, r2, v_contact_i - velrho[j].xyz, mu), 0.0);
        } else if (body_i != NO_BODY && kind_j != KIND_EXCLUDED && kind_j != KIND_INLET && other_solid(body_i, particle_id(j)) && contact_counts(kinematic_i, particle_id(j))) {
            // Contact with a fixed wall or another body.
            let mu = friction_between(1u + body_i, boundary_group(particle_id(j)));
            r += vec4<f32>(contact(x_ij, r2, v_contact_i - contact_velocity(j), mu), 0.0);
        }
    }
    return r;
}

// The rates of fluid particle i: continuity and momentum from every pressure-carrying neighbour
// (`pair_rates`), repulsive walls (eq. 23), elastic solids (eq. 28) and mirror images (eq. 12),
// gravity, and with ENERGY de/dt (written here).
fn fluid_rates(i: u32, ranges: ptr<function, NeighbourRanges>, n_ranges: u32) -> vec4<f32> {
    let p_i = pos[i];
    let vr_i = velrho[i];
    let pi = Particle(vr_i.xyz, vr_i.w, pressure_of(vr_i.w) / (vr_i.w * vr_i.w));
    let support2 = 4.0 * params.h * params.h;
    var r = vec4<f32>(0.0);
    var de = 0.0;
    for (var s = 0u; s < n_ranges; s++) {
        for (var j = (*ranges)[s].x; j < (*ranges)[s].y; j++) {
            let x_ij = rel_pos(p_i, pos[j]);
            let r2 = dot(x_ij, x_ij);
            if (r2 >= support2 || j == i) {
                continue;
            }
            let kind_j = code_kind(code[j]);
            if (is_repulsive(kind_j)) {
                r += vec4<f32>(repulsion(x_ij, r2), 0.0);
                continue;
            }
            if (is_solid(kind_j)) {
                let vr_j = velrho[j];
                let s_j = solid[solid_slot(j)];
                let b_j = s_j.interface_p / (vr_j.w * vr_j.w);
                r += interface_rates(pi.p_over_rho2, pi.v, pi.rho, b_j, vr_j.xyz, vr_j.w, material_of(s_j).mass, x_ij, r2);
                continue;
            }
            let vr_j = velrho[j];
            let ghost = is_ghost(kind_j);
            // A ghost stores the fluid velocity interpolated at its position (ghost.wgsl):
            // continuity sees the wall's velocity, viscosity the no-slip or free-slip ghost.
            var v_cont = vr_j.xyz;
            var v_visc = vr_j.xyz;
            if (ghost) {
                let gv = fixed_ghost_velocity(kind_j, particle_id(j), vr_j.xyz);
                v_cont = gv.cont;
                v_visc = gv.visc;
            }
            var psi = 0.0;
            if (kind_j == KIND_FLUID) {
                psi = diffused_density(pi.rho, vr_j.w, x_ij);
            }
            let pr = pair_rates(pi, x_ij, r2, v_cont, v_visc, vr_j.w, psi, select(1.0, pi.rho / vr_j.w, ghost));
            r += pr.rate;
            de += pr.de;
        }
    }
    if (MIRRORS && params.n_mirror_planes > 0u) {
        let m = mirror_rates(i, pi);
        r += m.rate;
        de += m.de;
    }
    r += vec4<f32>(params.gravity, 0.0);
    if (ENERGY) {
        energy_rate[i] = de;
    }
    return r;
}

// The rates of particle i, by its kind: solids (their loads from outside their body; their own
// stress in elastic.wgsl), fluid, and boundary particles that take rates; every other particle
// gets zero.
fn interact(i: u32) {
    let kind_i = code_kind(code[i]);
    if (ENERGY) {
        energy_rate[i] = 0.0;
    }
    if (HYDROSTATIC_DIFFUSION) {
        set_hydrostatic_coefficients();
    }
    if (is_solid(kind_i)) {
        // A lone elastic body (sph::initial::Present) has nothing outside it to load it.
        var loads = vec3<f32>(0.0);
        if (!LONE_SOLID) {
            loads = solid_loads(i);
        }
        rate[i] = vec4<f32>(loads, 0.0);
        return;
    }
    if (kind_i == KIND_FLUID) {
        var ranges: NeighbourRanges;
        let n_ranges = neighbour_ranges(pos[i], &ranges);
        rate[i] = fluid_rates(i, &ranges, n_ranges);
        return;
    }
    let on_body = kind_i != KIND_EXCLUDED && is_body_particle(particle_id(i));
    // Boundary particles that take the fluid's force: bodies', and fixed walls' for probes.
    let reacts = on_body || (WALL_REACTIONS && kind_i != KIND_EXCLUDED && kind_i != KIND_INLET);
    if (!reacts) {
        var drho = 0.0;
        if (kind_i == KIND_WALL) {
            drho = wall_continuity(i);
        }
        rate[i] = vec4<f32>(0.0, 0.0, 0.0, drho);
        return;
    }
    rate[i] = boundary_rates(i, kind_i, on_body);
}

@compute @workgroup_size(WG)
fn interaction(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = spread_index(gid, nwg);
    if (i < params.n_particles) {
        interact(i);
    }
}

// A subdomain's slab, for the overlapped step's two halves (docs/scaling.md): the particles
// that read nothing the exchange brings, summed while it travels, and the rest after it.
@group(0) @binding(10) var<uniform> halo_ctl: HaloCtl;

// What the first half writes into the `.w` of a rate it leaves to the second: about −3.4e38,
// finite, so that no device's moves of a NaN change it; a rate that is this by chance is only
// summed again, the same.
const LEFT_FOR_AFTER: u32 = 0xff7fbeefu;

fn before_arrival(i: u32) -> bool {
    return reads_no_arrival(slab_layer(pos[i], halo_ctl.axis), halo_ctl);
}

var<workgroup> group_reads_arrival: atomic<u32>;

// The first half sums a workgroup's particles only where none of them reads an arrival: a
// workgroup of both kinds (where the sorted order crosses the layers by a cut) would run its
// neighbour loops in both halves, its lanes half idle in each, so all of it is left for after.
@compute @workgroup_size(WG)
fn interaction_interior(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = spread_index(gid, nwg);
    let n = params.n_particles;
    if (i < n && !before_arrival(i)) {
        atomicStore(&group_reads_arrival, 1u);
    }
    workgroupBarrier();
    let leave = atomicLoad(&group_reads_arrival) != 0u;
    if (i >= n) {
        return;
    }
    if (leave) {
        rate[i] = vec4<f32>(bitcast<f32>(LEFT_FOR_AFTER));
    } else {
        interact(i);
    }
}

@compute @workgroup_size(WG)
fn interaction_boundary(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = spread_index(gid, nwg);
    if (i < params.n_particles && (bitcast<u32>(rate[i].w) == LEFT_FOR_AFTER || !before_arrival(i))) {
        interact(i);
    }
}
