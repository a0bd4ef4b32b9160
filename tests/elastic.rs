//! Layer 1 for elastic solids: the GPU elastic pass (dρ/dt, dv/dt, dτ/dt) against the f64
//! reference (src/reference/elastic.rs) on jittered solid particle sets with random
//! velocities, densities and stresses, two bodies of different materials (no pairs across
//! them) and a clamped strip, 2D and 3D. The outputs are poisoned with NaN before the kernel runs, so a solid particle the
//! kernel skips fails.

// Component loops written as in the equations read better than iterator chains here.
#![allow(clippy::needless_range_loop)]

use crate::common::*;
use wgsph::layout::{SymRate, ID_MASK, KIND_SHIFT};
use wgsph::reference::elastic::{self, SolidRef};
use wgsph::reference::{is_solid, RefParticle, Space};
use wgsph::scenario::*;
use wgsph::sph::Solver;

fn material() -> ElasticMaterial {
    ElasticMaterial {
        density: 1000.0,
        youngs_modulus: 2.0e6,
        poisson_ratio: 0.3975,
        alpha: 0.5,
        artificial_stress: 0.3,
        formulation: SolidFormulation::UpdatedLagrangian,
    }
}

/// A second material beside `mat`, of its formulation: denser, stiffer, another Poisson ratio
/// and (updated-Lagrangian) other artificial viscosity and stress, so that a kernel that reads
/// the wrong body's material fails.
fn other_material(mat: ElasticMaterial) -> ElasticMaterial {
    let ul = mat.formulation == SolidFormulation::UpdatedLagrangian;
    ElasticMaterial {
        density: 1.7 * mat.density,
        youngs_modulus: 3.0 * mat.youngs_modulus,
        poisson_ratio: 0.3,
        alpha: if ul { 0.2 } else { 0.0 },
        artificial_stress: if ul { 0.15 } else { 0.0 },
        formulation: mat.formulation,
    }
}

/// A jittered solid with random velocities (two bodies side by side, the lower of `mat`, the
/// upper of `other_material(mat)`; a clamped strip): of the updated-Lagrangian formulation also
/// with random stresses and densities (and g along −y); of the total-Lagrangian one at rest
/// density and stress free (its state is F).
fn random_solid(dim: u32, kernel: KernelKind, seed: u64, mat: ElasticMaterial) -> Scenario {
    let ul = mat.formulation == SolidFormulation::UpdatedLagrangian;
    let mats = [mat, other_material(mat)];
    let dx = 0.01;
    let mut ph = physics(dim, dx, 20.0);
    ph.kernel = kernel;
    if ul {
        ph.gravity = [0.0, -9.81, 0.0];
    }
    let mut rng = Rng(seed);
    let side = if dim == 2 { 0.16 } else { 0.08 };
    let (min, max) = if dim == 2 {
        ([0.1, 0.1, 0.0], [0.1 + side, 0.1 + side, 0.0])
    } else {
        ([0.1; 3], [0.1 + side; 3])
    };
    let mut parts = Vec::new();
    let mut body = Vec::new();
    let mut tau0 = Vec::new();
    for p in lattice(dim, dx, min, max) {
        let (mut pos, vel) = rng.jittered(dim, p, 0.2, dx);
        let mut t = [0.0; 6];
        // Two bodies side by side: no pair across the line y = centre. The upper one sits
        // 0.5 dx higher, so that no two particles across are within the contact law's reach
        // r0 = dx (1.1 dx apart at least) but all are within the kernel's 2h.
        let upper = p[1] > min[1] + 0.5 * side;
        let mut rho = mats[upper as usize].density;
        if ul {
            for c in 0..6 {
                // 2D: only xx, yy, zz, xy.
                if dim == 3 || c < 4 {
                    t[c] = rng.range(-2.0e4, 2.0e4);
                }
            }
            rho *= 1.0 + rng.range(-0.01, 0.01);
        }
        let clamped = p[0] < min[0] + 2.0 * dx;
        if upper {
            pos[1] += 0.5 * dx;
        }
        parts.push(Particle {
            pos,
            vel: if clamped { [0.0; 3] } else { vel },
            rho,
            kind: if clamped {
                Kind::SolidClamped
            } else {
                Kind::Solid
            },
        });
        body.push(upper as u32);
        tau0.push(t);
    }
    with_solids(ph, parts, mats.to_vec(), body, tau0)
}

/// The test scenario of `parts` in the domain these tests use (0.4 m square in 2D, 0.3 m cube
/// in 3D), with the solid state of every particle.
fn with_solids(
    ph: Physics,
    parts: Vec<Particle>,
    materials: Vec<ElasticMaterial>,
    body: Vec<u32>,
    tau0: Vec<[f64; 6]>,
) -> Scenario {
    let max = if ph.dim == 2 {
        [0.4, 0.4, 0.0]
    } else {
        [0.3; 3]
    };
    let mut sc = scenario(ph, parts, Domain { min: [0.0; 3], max }, vec![]);
    sc.solids = Some(Solids {
        materials,
        body,
        tau0,
    });
    sc
}

/// Per-solid-particle values (id order, as `read_solid` gives them) in the GPU order of the
/// particle arrays; `other` for the particles that are not solid.
fn in_gpu_order<T: Copy>(solver: &Solver, by_id: &[T], other: T) -> Vec<T> {
    let (_, _, code) = solver.read_raw().unwrap();
    let base = solver.solid_id_base();
    code.iter()
        .map(|&c| {
            if is_solid(c >> KIND_SHIFT) {
                by_id[((c & ID_MASK) - base) as usize]
            } else {
                other
            }
        })
        .collect()
}

/// dτ/dt of the last evaluation in the GPU order of the particle arrays (zero for the others).
fn stress_rates(solver: &Solver) -> Vec<SymRate> {
    in_gpu_order(
        solver,
        &solver.read_stress_rates().unwrap(),
        SymRate::default(),
    )
}

/// The solid state of the GPU arrays (GPU order) as reference input.
fn solid_refs(solver: &Solver) -> Vec<SolidRef> {
    let by_id: Vec<SolidRef> = solver
        .read_solid()
        .unwrap()
        .iter()
        .map(|s| SolidRef {
            tau: [
                s.tau_a[0], s.tau_a[1], s.tau_a[2], s.tau_a[3], s.tau_b[0], s.tau_b[1],
            ]
            .map(|x| x as f64),
            body: s.body,
        })
        .collect();
    let none = SolidRef {
        tau: [0.0; 6],
        body: 0,
    };
    in_gpu_order(solver, &by_id, none)
}

/// The solver of `sc` with its particles and solid state as reference input (GPU order), and
/// the rates of a re-run of the interaction and solid passes (outputs poisoned first).
fn rerun(sc: &Scenario) -> (Solver, Vec<RefParticle>, Vec<SolidRef>, Vec<[f32; 4]>) {
    let solver = Solver::new(gpu(), sc).unwrap();
    let parts = gpu_particles(&solver);
    let solid = solid_refs(&solver);
    let rates = solver.rerun_interaction(true).unwrap();
    (solver, parts, solid, rates)
}

fn rms(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x * x, n + 1));
    (s / n as f64).sqrt()
}

/// The largest differences of the GPU's updated-Lagrangian rates from the reference's over the
/// particles `ids` (GPU order), relative to the reference's RMS of each: dv/dt, dρ/dt, dτ/dt.
struct UlErrors {
    acc: f64,
    rho: f64,
    tau: f64,
    acc_rms: f64,
    rho_rms: f64,
    tau_rms: f64,
}

fn ul_errors(
    ids: &[usize],
    gpu_rate: &[[f32; 4]],
    gpu_dtau: &[SymRate],
    cpu: &[Option<elastic::ElasticRates>],
) -> UlErrors {
    let cpu_of = |i: usize| cpu[i].as_ref().expect("an updated-Lagrangian particle");
    let mut e = UlErrors {
        acc: 0.0,
        rho: 0.0,
        tau: 0.0,
        acc_rms: rms(ids.iter().flat_map(|&i| cpu_of(i).rate[..3].to_vec())),
        rho_rms: rms(ids.iter().map(|&i| cpu_of(i).rate[3])),
        tau_rms: rms(ids.iter().flat_map(|&i| cpu_of(i).dtau.to_vec())),
    };
    for &i in ids {
        let (g, c, t) = (gpu_rate[i], cpu_of(i), gpu_dtau[i]);
        let g6 = [t.a[0], t.a[1], t.a[2], t.a[3], t.b[0], t.b[1]];
        assert!(
            g.iter().chain(&g6).all(|x| x.is_finite()),
            "particle {i}: non-finite GPU rate {g:?} {g6:?}"
        );
        for a in 0..3 {
            e.acc = e.acc.max((g[a] as f64 - c.rate[a]).abs() / e.acc_rms);
        }
        e.rho = e.rho.max((g[3] as f64 - c.rate[3]).abs() / e.rho_rms);
        for k in 0..6 {
            e.tau = e.tau.max((g6[k] as f64 - c.dtau[k]).abs() / e.tau_rms);
        }
    }
    e
}

/// The current positions of the TL particles (ids `range`) by TL index, and the GPU slot of
/// each, from the particles `parts` and their `codes` (GPU order).
fn by_tl_index(
    parts: &[RefParticle],
    codes: &[u32],
    range: &std::ops::Range<usize>,
) -> (Vec<[f64; 3]>, Vec<usize>) {
    let mut x = vec![[0.0; 3]; range.len()];
    let mut slot = vec![usize::MAX; range.len()];
    for (i, c) in codes.iter().enumerate() {
        let id = (c & ID_MASK) as usize;
        if range.contains(&id) {
            x[id - range.start] = parts[i].pos;
            slot[id - range.start] = i;
        }
    }
    (x, slot)
}

/// The largest difference of the TL particles' GPU dv/dt (at GPU slots `slot`, by TL index)
/// from the reference's `cpu`, relative to the reference's RMS (returned second); their dρ/dt
/// must be 0.
fn tl_accel_error(gpu_rate: &[[f32; 4]], slot: &[usize], cpu: &[[f64; 3]], dim: u32) -> (f64, f64) {
    let d = dim as usize;
    let acc_rms = rms(cpu.iter().flat_map(|a| a[..d].to_vec()));
    let mut err = 0.0f64;
    for (k, &i) in slot.iter().enumerate() {
        let g = gpu_rate[i];
        assert!(
            g.iter().all(|v| v.is_finite()) && g[3] == 0.0,
            "TL particle {k}: GPU rate {g:?}"
        );
        for a in 0..3 {
            err = err.max((g[a] as f64 - cpu[k][a]).abs() / acc_rms);
        }
    }
    (err, acc_rms)
}

/// The largest difference of the TL particles' output Cauchy stress (τ and p of
/// `read_particles`) from the reference's σ (`want`, by TL index), relative to the particle's own
/// largest component and at least the RMS (one random particle is squeezed to J ≈ 0.02, σ ≈ 30
/// × the RMS), and the largest |ρ J/ρs − 1| of their output density.
fn tl_output_errors(
    out: &wgsph::sph::Particles,
    range: &std::ops::Range<usize>,
    want: &[([[f64; 3]; 3], f64)],
    rho_s: impl Fn(usize) -> f64,
) -> (f64, f64) {
    let stress = out
        .stress
        .as_ref()
        .expect("TL particles output their stress");
    let sigma_rms = rms(want.iter().flat_map(|(s, _)| s.iter().flatten().copied()));
    let (mut e_sigma, mut e_rho) = (0.0f64, 0.0f64);
    for (i, &id) in out.id.iter().enumerate() {
        if !range.contains(&(id as usize)) {
            continue;
        }
        let k = id as usize - range.start;
        let (s, j) = &want[k];
        let scale = s.iter().flatten().fold(sigma_rms, |m, v| m.max(v.abs()));
        let (t, p) = (stress[i], out.pressure[i] as f64);
        let got = [
            [t[0] as f64 - p, t[3] as f64, t[4] as f64],
            [t[3] as f64, t[1] as f64 - p, t[5] as f64],
            [t[4] as f64, t[5] as f64, t[2] as f64 - p],
        ];
        for a in 0..3 {
            for b in 0..3 {
                assert!(got[a][b].is_finite(), "TL particle {k}: σ {got:?}");
                e_sigma = e_sigma.max((got[a][b] - s[a][b]).abs() / scale);
            }
        }
        e_rho = e_rho.max((out.rho[i] as f64 * j / rho_s(k) - 1.0).abs());
    }
    (e_sigma, e_rho)
}

#[test]
fn elastic_rates_match_reference() {
    for (dim, kernel) in [
        (2, KernelKind::WendlandC2),
        (2, KernelKind::CubicSpline),
        (3, KernelKind::WendlandC2),
    ] {
        let sc = random_solid(dim, kernel, 11 + dim as u64, material());
        let (solver, parts, solid, gpu_rate) = rerun(&sc);
        let gpu_dtau = stress_rates(&solver);
        let mats = &sc.solids.as_ref().unwrap().materials;
        let cpu = elastic::elastic_rates(&sc.physics, mats, &Space::of(&sc), &parts, &solid);
        let all: Vec<_> = cpu.iter().map(|c| c.as_ref().expect("all solid")).collect();
        let acc_rms = rms(all.iter().flat_map(|c| c.rate[..3].to_vec()));
        // The artificial stress (ε = 0.3) must be a visible part of what is compared: the
        // random stresses have tensile principal parts.
        let mut without = mats.clone();
        for m in &mut without {
            m.artificial_stress = 0.0;
        }
        let cpu0 = elastic::elastic_rates(&sc.physics, &without, &Space::of(&sc), &parts, &solid);
        let as_rms = rms(all.iter().zip(&cpu0).flat_map(|(c, c0)| {
            let c0 = c0.expect("all solid");
            (0..3).map(move |a| c.rate[a] - c0.rate[a])
        }));
        assert!(
            as_rms > 0.05 * acc_rms,
            "{dim}D: the artificial stress is {as_rms:.2e} of an RMS acceleration {acc_rms:.2e}"
        );
        let ids: Vec<usize> = (0..parts.len()).collect();
        let e = ul_errors(&ids, &gpu_rate, &gpu_dtau, &cpu);
        let (e_acc, e_rho, e_tau) = (e.acc, e.rho, e.tau);
        let (rho_rms, tau_rms) = (e.rho_rms, e.tau_rms);
        println!(
            "{dim}D {kernel:?}, {} particles: dv/dt error {e_acc:.1e} of RMS {acc_rms:.3e} \
             (artificial stress {as_rms:.3e}), dρ/dt {e_rho:.1e} of {rho_rms:.3e}, dτ/dt {e_tau:.1e} of {tau_rms:.3e}",
            parts.len()
        );
        assert!(e_acc < 2e-4, "acceleration error {e_acc}");
        assert!(e_rho < 2e-4, "density-rate error {e_rho}");
        assert!(e_tau < 2e-4, "stress-rate error {e_tau}");
    }
}

/// Two elastic bodies side by side on a floor of dynamic wall particles, beside a rigid body
/// (dynamic particles, free), each 0.8 dx (±0.1 dx of jitter) from the next: within the
/// repulsive law's reach r0 = dx. The solids are of two materials, both denser than the
/// fluid's particle mass that body particles carry, so every contact weight differs from 1.
fn solids_in_contact(dim: u32, seed: u64) -> Scenario {
    let dx = 0.01;
    let mut ph = physics(dim, dx, 20.0);
    ph.gravity = [0.0; 3];
    let up = dim as usize - 1;
    let mut rng = Rng(seed);
    let mats = [
        ElasticMaterial {
            density: 2500.0,
            ..material()
        },
        other_material(ElasticMaterial {
            density: 2500.0,
            ..material()
        }),
    ];
    // Boxes along x from `x0` to `x1`, `y0` to `y0 + height` in the up direction; 0.06 deep in 3D.
    let block = |x0: f64, x1: f64, y0: f64, height: f64| {
        let (mut lo, mut hi) = ([0.1; 3], [0.16; 3]);
        lo[0] = x0;
        hi[0] = x1;
        lo[up] = y0;
        hi[up] = y0 + height;
        if dim == 2 {
            lo[2] = 0.0;
            hi[2] = 0.0;
        }
        lattice(dim, dx, lo, hi)
    };
    let floor_top = 0.03;
    let mut parts: Vec<Particle> = block(0.06, 0.3, floor_top - 3.0 * dx, 3.0 * dx)
        .into_iter()
        .map(|pos| Particle {
            pos,
            vel: [0.0; 3],
            rho: 1000.0,
            kind: Kind::Wall,
        })
        .collect();
    let mut body = vec![0; parts.len()];
    let mut tau0 = vec![[0.0; 6]; parts.len()];
    // Solid 0 from x = 0.1, solid 1 from 0.8 dx after it, the rigid body 0.8 dx after that.
    let y0 = floor_top - 0.2 * dx;
    let x1 = 0.1 + 6.0 * dx - 0.2 * dx;
    for (k, (a, b)) in [(0.1, 0.1 + 6.0 * dx), (x1, x1 + 6.0 * dx)]
        .into_iter()
        .enumerate()
    {
        for p in block(a, b, y0, 6.0 * dx) {
            let (pos, vel) = rng.jittered(dim, p, 0.1, dx);
            parts.push(Particle {
                pos,
                vel,
                rho: mats[k].density,
                kind: Kind::Solid,
            });
            body.push(k as u32);
            tau0.push([0.0; 6]);
        }
    }
    let x2 = x1 + 6.0 * dx - 0.2 * dx;
    let start = parts.len();
    let rigid = block(x2, x2 + 4.0 * dx, y0, 6.0 * dx);
    let n = rigid.len() as f64;
    let mut center = [0.0; 3];
    for p in &rigid {
        for a in 0..3 {
            center[a] += p[a] / n;
        }
    }
    for pos in rigid {
        parts.push(Particle {
            pos,
            vel: [0.0; 3],
            rho: 1000.0,
            kind: Kind::Wall,
        });
    }
    body.resize(parts.len(), 0);
    tau0.resize(parts.len(), [0.0; 6]);
    let mass = 1000.0 * dx.powi(dim as i32) * n;
    let mut sc = with_solids(ph, parts, mats.to_vec(), body, tau0);
    sc.bodies = vec![Body {
        name: "rigid".into(),
        particles: start..sc.particles.len(),
        mass,
        center,
        inertia: [
            [mass * 1e-3, 0.0, 0.0],
            [0.0, mass * 1e-3, 0.0],
            [0.0, 0.0, mass * 1e-3],
        ],
        motion: Motion::Free {
            velocity: [0.0; 3],
            omega: [0.0; 3],
            release_s: 0.0,
        },
    }];
    sc
}

/// Layer 1 for contact: elastic particles against a floor, another elastic body and a rigid
/// body, 2D and 3D. Each particle's GPU rate (the interaction pass with its contact terms, then
/// the elastic pass) against the reference's solid rates plus `elastic::contact_rates` for
/// solid particles and `interaction::rates` (with the solids' reaction) for the rigid body's.
/// Rows in contact and rows without are compared each against their own RMS (the repulsive law
/// is much stronger than the elastic forces here).
/// Run with one μ for all contact, then with `[[friction]]` pairs of their own μ (the table the
/// GPU looks the pair's μ up in).
#[test]
fn solid_contact_matches_reference() {
    use wgsph::scenario::{ContactGroup, FrictionPair};
    let pair = |a, b, coefficient| FrictionPair {
        between: [a, b],
        coefficient,
    };
    let tables = [
        vec![],
        vec![
            pair(ContactGroup::Solid(0), ContactGroup::Walls, 0.9),
            pair(ContactGroup::Solid(1), ContactGroup::Solid(0), 0.0),
            pair(ContactGroup::Body(0), ContactGroup::Solid(1), 0.2),
        ],
    ];
    for (dim, pairs) in [2, 3]
        .into_iter()
        .flat_map(|d| tables.iter().map(move |t| (d, t)))
    {
        let mut sc = solids_in_contact(dim, 40 + dim as u64);
        // With friction (random velocities of ±0.5 m/s slide the solids against everything).
        sc.walls.friction = 0.5;
        sc.walls.friction_pairs = pairs.clone();
        let dim_label = format!("{dim}D, {} pairs", pairs.len());
        let ph = &sc.physics;
        let mats = &sc.solids.as_ref().unwrap().materials;
        let (_solver, parts, solid, gpu_rate) = rerun(&sc);
        let space = Space::of(&sc);
        let solids = elastic::elastic_rates(ph, mats, &space, &parts, &solid);
        let contact = elastic::contact_rates(ph, mats, &sc.walls, &space, &parts, &solid);
        let frictionless = WallParams {
            friction: 0.0,
            friction_pairs: Vec::new(),
            ..sc.walls.clone()
        };
        let contact0 = elastic::contact_rates(ph, mats, &frictionless, &space, &parts, &solid);
        let boundary = wgsph::reference::interaction::rates(ph, &sc.walls, &space, &parts);
        let mut groups: [Vec<(usize, [f64; 3])>; 4] = Default::default();
        for i in 0..parts.len() {
            let (want, group) = if is_solid(parts[i].kind) {
                let s = solids[i].expect("solid").rate;
                let c = contact[i];
                let touching = c.iter().any(|x| *x != 0.0);
                ([0, 1, 2].map(|a| s[a] + c[a]), touching as usize)
            } else if parts[i].body.is_some() {
                let (b, c) = (boundary[i], contact[i]);
                let want = [0, 1, 2].map(|a| b[a] + c[a]);
                (want, 2 + want.iter().any(|x| *x != 0.0) as usize)
            } else {
                continue;
            };
            groups[group].push((i, want));
        }
        for (name, rows) in ["solid", "solid in contact", "rigid", "rigid in contact"]
            .iter()
            .zip(&groups)
        {
            if *name == "rigid" {
                // Without fluid the rigid body's only force is contact (floor and solids).
                assert!(rows.iter().all(|(_, w)| *w == [0.0; 3]));
                continue;
            }
            assert!(
                rows.len() >= 5,
                "{dim_label}: only {} {name} rows",
                rows.len()
            );
            let scale = rms(rows.iter().flat_map(|(_, w)| w.to_vec()));
            // The friction's part of the compared rates.
            let (with, without) = (&contact, &contact0);
            let friction = rms(rows
                .iter()
                .flat_map(|&(i, _)| (0..3).map(move |a| with[i][a] - without[i][a])))
                / scale;
            if name.ends_with("in contact") {
                assert!(
                    friction > 0.05,
                    "{dim_label} {name}: friction only {friction}"
                );
            }
            let mut err = 0.0f64;
            for (i, w) in rows {
                let g = gpu_rate[*i];
                assert!(g.iter().all(|x| x.is_finite()), "row {i}: {g:?}");
                for a in 0..3 {
                    err = err.max((g[a] as f64 - w[a]).abs() / scale);
                }
            }
            println!(
                "{dim_label} {name}: {} rows, acceleration error {err:.1e} of RMS {scale:.3e} \
                 (friction {friction:.2} of it)",
                rows.len()
            );
            assert!(err < 2e-4, "{dim_label} {name}: error {err}");
        }
    }
}

/// A solid block under a fluid block, jittered, with random velocities, densities (fluid
/// ρ0 = 1000, solid ρs = 1200: the density-rate correction ρ_i/ρ_j matters) and stresses.
fn fluid_on_solid(dim: u32, kernel: KernelKind, viscosity: Viscosity, seed: u64) -> Scenario {
    let dx = 0.01;
    let mut ph = physics(dim, dx, 20.0);
    ph.kernel = kernel;
    ph.viscosity = viscosity;
    let mat = ElasticMaterial {
        density: 1200.0,
        ..material()
    };
    let mut rng = Rng(seed);
    let up = dim as usize - 1;
    let (lo, hi) = if dim == 2 {
        ([0.1, 0.1, 0.0], [0.26, 0.26, 0.0])
    } else {
        ([0.1; 3], [0.18; 3])
    };
    let split = 0.5 * (lo[up] + hi[up]);
    let mut parts = Vec::new();
    let mut tau0 = Vec::new();
    for p in lattice(dim, dx, lo, hi) {
        let solid = p[up] < split;
        let (pos, vel) = rng.jittered(dim, p, 0.2, dx);
        let mut t = [0.0; 6];
        if solid {
            for (c, tc) in t.iter_mut().enumerate() {
                if dim == 3 || c < 4 {
                    *tc = rng.range(-2.0e4, 2.0e4);
                }
            }
        }
        let clamped = solid && p[0] < lo[0] + 2.0 * dx;
        let (rho0, kind) = match (solid, clamped) {
            (false, _) => (1000.0, Kind::Fluid),
            (true, false) => (mat.density, Kind::Solid),
            (true, true) => (mat.density, Kind::SolidClamped),
        };
        parts.push(Particle {
            pos,
            vel: if clamped { [0.0; 3] } else { vel },
            rho: rho0 * (1.0 + rng.range(-0.01, 0.01)),
            kind,
        });
        tau0.push(t);
    }
    let body = vec![0; parts.len()];
    with_solids(ph, parts, vec![mat], body, tau0)
}

/// Layer 1 for the fluid–solid coupling: every particle's (dv/dt, dρ/dt) on the GPU (the solids'
/// interface pressure P_g interpolated from the fluid, Shepard or MLS; the interaction pass
/// with its fluid–solid pairs; the elastic pass) against the f64 reference's sum of the fluid
/// terms, the interface terms and the solid terms; outputs poisoned first. And the interface
/// conserves momentum: Σ m_i (dv_i/dt − g) over all particles vanishes to f32 rounding (every
/// pair term is equal and opposite).
#[test]
fn fluid_solid_interface_matches_reference() {
    for (dim, kernel, viscosity, correction) in [
        (
            2,
            KernelKind::WendlandC2,
            Viscosity::Artificial { alpha: 0.1 },
            GhostCorrection::Shepard,
        ),
        (
            2,
            KernelKind::CubicSpline,
            Viscosity::Laminar { nu: 1e-3 },
            GhostCorrection::Mls,
        ),
        (
            3,
            KernelKind::WendlandC2,
            Viscosity::Artificial { alpha: 0.1 },
            GhostCorrection::Mls,
        ),
    ] {
        let mut sc = fluid_on_solid(dim, kernel, viscosity, 5 + dim as u64);
        sc.walls.ghost_correction = correction;
        let ph = &sc.physics;
        let mats = &sc.solids.as_ref().unwrap().materials;
        let (_solver, parts, solid, gpu_rate) = rerun(&sc);
        let space = Space::of(&sc);
        let fluid = wgsph::reference::interaction::rates(ph, &sc.walls, &space, &parts);
        let p_g = wgsph::reference::ghost::solid_interface_pressure(ph, &sc.walls, &space, &parts);
        let on_solid: Vec<f64> = (0..parts.len())
            .filter(|&i| is_solid(parts[i].kind))
            .map(|i| p_g[i])
            .collect();
        assert!(
            on_solid.iter().any(|p| p.abs() > 100.0),
            "the interface pressures are all small: {on_solid:?}"
        );
        let interface = elastic::interface_rates(ph, mats, &space, &parts, &solid, &p_g);
        let solids = elastic::elastic_rates(ph, mats, &space, &parts, &solid);
        let cpu: Vec<[f64; 4]> = (0..parts.len())
            .map(|i| {
                let s = solids[i].map_or([0.0; 4], |s| s.rate);
                [0, 1, 2, 3].map(|k| fluid[i][k] + interface[i][k] + s[k])
            })
            .collect();
        let across = interface
            .iter()
            .filter(|r| r.iter().any(|x| *x != 0.0))
            .count();
        assert!(across > 20, "only {across} particles see the interface");
        let acc_rms = rms(cpu.iter().flat_map(|c| c[..3].to_vec()));
        let rho_rms = rms(cpu.iter().map(|c| c[3]));
        let (mut e_acc, mut e_rho) = (0.0f64, 0.0f64);
        for (i, (g, c)) in gpu_rate.iter().zip(&cpu).enumerate() {
            assert!(
                g.iter().all(|x| x.is_finite()),
                "particle {i}: non-finite GPU rate {g:?}"
            );
            for a in 0..3 {
                e_acc = e_acc.max((g[a] as f64 - c[a]).abs() / acc_rms);
            }
            e_rho = e_rho.max((g[3] as f64 - c[3]).abs() / rho_rms);
        }
        // Momentum: Σ m (a − g) against Σ m |a − g|.
        let solid_mass = mats[0].particle_mass(ph.dx, dim);
        let (mut total, mut scale) = ([0.0f64; 3], 0.0f64);
        for (p, g) in parts.iter().zip(&gpu_rate) {
            let m = if p.kind == 0 {
                ph.particle_mass
            } else {
                solid_mass
            };
            for a in 0..3 {
                let f = m * (g[a] as f64 - ph.gravity[a]);
                total[a] += f;
                scale += f.abs();
            }
        }
        let imbalance = total.iter().map(|t| t.abs()).fold(0.0, f64::max) / scale;
        println!(
            "{dim}D {kernel:?} {viscosity:?} {correction:?}, {} particles ({across} at the interface): dv/dt \
             error {e_acc:.1e} of RMS {acc_rms:.3e}, dρ/dt {e_rho:.1e} of {rho_rms:.3e}; \
             momentum imbalance {imbalance:.1e} of Σ m|a − g|",
            parts.len()
        );
        assert!(e_acc < 2e-4, "acceleration error {e_acc}");
        assert!(e_rho < 2e-4, "density-rate error {e_rho}");
        assert!(imbalance < 1e-5, "momentum imbalance {imbalance}");
    }
}

/// A total-Lagrangian solid on a jittered reference lattice (two bodies, a clamped strip).
fn random_tl_solid(dim: u32, kernel: KernelKind, seed: u64) -> Scenario {
    let mat = ElasticMaterial {
        alpha: 0.0,
        artificial_stress: 0.0,
        formulation: SolidFormulation::TotalLagrangian,
        ..material()
    };
    random_solid(dim, kernel, seed, mat)
}

/// Layer 1 for the total-Lagrangian solid: its GPU accelerations against the f64 reference
/// (src/reference/total_lagrangian.rs) after one step of random velocities has displaced the
/// particles from their jittered reference lattice by up to ±0.2 dx (strains of order 0.1, so
/// the geometric nonlinearity counts), 2D and 3D. The rates are poisoned with NaN before the
/// rerun.
#[test]
fn total_lagrangian_rates_match_reference() {
    use wgsph::reference::total_lagrangian;
    for (dim, kernel) in [
        (2, KernelKind::WendlandC2),
        (2, KernelKind::CubicSpline),
        (3, KernelKind::WendlandC2),
    ] {
        let sc = random_tl_solid(dim, kernel, 29 + dim as u64);
        let mut solver = Solver::new(gpu(), &sc).unwrap();
        solver.single_step(0.004).unwrap();
        let (parts, codes) = gpu_particles_and_codes(&solver);
        let gpu_rate = solver.rerun_interaction(true).unwrap();
        let (range, setup) = wgsph::sph::total_lagrangian::setup(&sc).unwrap();
        let (x, slot) = by_tl_index(&parts, &codes, &range);
        let mats = &sc.solids.as_ref().unwrap().materials;
        let cpu = total_lagrangian::accelerations(&setup, &sc.physics, mats, &x);
        let mut moved = 0.0f64;
        for (k, p) in sc.particles[range.clone()].iter().enumerate() {
            for a in 0..dim as usize {
                moved = moved.max((x[k][a] - p.pos[a]).abs());
            }
        }
        let (err, acc_rms) = tl_accel_error(&gpu_rate, &slot, &cpu, dim);
        println!(
            "TL {dim}D {kernel:?}, {} particles, {} pairs, largest displacement {:.2} dx: dv/dt \
             error {err:.1e} of RMS {acc_rms:.3e}",
            setup.len(),
            setup.pairs.len(),
            moved / sc.physics.dx
        );
        assert!(err < 5e-5, "acceleration error {err}");

        // The particle outputs: Cauchy stress σ = P Fᵀ/J as τ and p, and ρ = ρs/J.
        let want = total_lagrangian::cauchy(&setup, &sc.physics, mats, &x);
        let out = solver.read_particles().unwrap();
        let (e_sigma, e_rho) = tl_output_errors(&out, &range, &want, |k| {
            mats[setup.body[k] as usize].density
        });
        let sigma_rms = rms(want.iter().flat_map(|(s, _)| s.iter().flatten().copied()));
        println!(
            "TL {dim}D {kernel:?}: output σ error {e_sigma:.1e} (RMS {sigma_rms:.3e} Pa), \
             ρ J/ρs − 1 up to {e_rho:.1e}"
        );
        assert!(e_sigma < 1e-4, "output stress error {e_sigma}");
        assert!(e_rho < 1e-4, "output density error {e_rho}");
    }
}

/// Layer 1 for a case of both formulations: the lower body updated-Lagrangian (random τ and
/// ρ), the upper total-Lagrangian, 2D and 3D; the updated-Lagrangian body's ids come first, so
/// the TL particles are a run of solid slots that does not start at the first. After one step
/// of random velocities, each body's rates against its own reference: dv/dt, dρ/dt and dτ/dt of
/// the updated-Lagrangian particles (src/reference/elastic.rs), dv/dt of the total-Lagrangian
/// ones (src/reference/total_lagrangian.rs) with dρ/dt = 0, and the TL particles' τ, which
/// elastic.wgsl's predictor and corrector must leave alone, still zero; the particle outputs
/// (τ as stored, and the TL particles' Cauchy stress and density). Rates poisoned first.
#[test]
fn solids_of_both_formulations_match_their_references() {
    use wgsph::reference::total_lagrangian;
    for dim in [2, 3] {
        let mut sc = random_solid(dim, KernelKind::WendlandC2, 53 + dim as u64, material());
        let solids = sc.solids.as_mut().unwrap();
        let tl = ElasticMaterial {
            alpha: 0.0,
            artificial_stress: 0.0,
            formulation: SolidFormulation::TotalLagrangian,
            ..solids.materials[1]
        };
        solids.materials[1] = tl;
        // Another half dx up, so that the step does not bring the bodies within the contact
        // law's reach (these references leave contact out): at least 1.6 dx apart, less the
        // step's 0.1 dx a side, and still within the kernel's 2h.
        for i in 0..sc.particles.len() {
            if solids.body[i] == 1 {
                solids.tau0[i] = [0.0; 6];
                sc.particles[i].rho = tl.density;
                sc.particles[i].pos[1] += 0.5 * sc.physics.dx;
            }
        }
        // The solver takes the TL particles as one run of ids (the case loader builds them so):
        // in 3D the lattice alternates the bodies layer by layer, so order them by body.
        let mut order: Vec<usize> = (0..sc.particles.len()).collect();
        order.sort_by_key(|&i| solids.body[i]);
        sc.particles = order.iter().map(|&i| sc.particles[i]).collect();
        solids.body = order.iter().map(|&i| solids.body[i]).collect();
        solids.tau0 = order.iter().map(|&i| solids.tau0[i]).collect();
        let mut solver = Solver::new(gpu(), &sc).unwrap();
        solver.single_step(0.002).unwrap();
        let (parts, codes) = gpu_particles_and_codes(&solver);
        let solid = solid_refs(&solver);
        let gpu_rate = solver.rerun_interaction(true).unwrap();
        let gpu_dtau = stress_rates(&solver);
        let mats = &sc.solids.as_ref().unwrap().materials;

        // The updated-Lagrangian body.
        let cpu = elastic::elastic_rates(&sc.physics, mats, &Space::of(&sc), &parts, &solid);
        let ul: Vec<usize> = (0..parts.len()).filter(|&i| cpu[i].is_some()).collect();
        let n_tl = parts
            .iter()
            .zip(&solid)
            .filter(|(p, s)| is_solid(p.kind) && s.body == 1)
            .count();
        assert_eq!(
            ul.len() + n_tl,
            parts.len(),
            "{dim}D: every particle is solid"
        );
        assert!(!ul.is_empty() && n_tl > 0);
        let e = ul_errors(&ul, &gpu_rate, &gpu_dtau, &cpu);

        // The total-Lagrangian body: current positions by TL index, and the GPU slot of each.
        let (range, setup) = wgsph::sph::total_lagrangian::setup(&sc).unwrap();
        assert_eq!(setup.len(), n_tl);
        assert!(range.start > solver.solid_id_base() as usize);
        let (x, slot) = by_tl_index(&parts, &codes, &range);
        let cpu_tl = total_lagrangian::accelerations(&setup, &sc.physics, mats, &x);
        let (e_tl, tl_rms) = tl_accel_error(&gpu_rate, &slot, &cpu_tl, dim);
        let state = solver.read_solid().unwrap();
        let base = solver.solid_id_base() as usize;
        for id in range.clone() {
            let s = state[id - base];
            assert!(
                s.tau_a == [0.0; 4] && s.tau_b == [0.0; 3],
                "TL particle {id}: τ {:?} {:?}",
                s.tau_a,
                s.tau_b
            );
        }
        // The particle outputs: τ as stored for the updated-Lagrangian particles, the Cauchy
        // stress σ = P Fᵀ/J (as τ and p) for the total-Lagrangian ones.
        let want = total_lagrangian::cauchy(&setup, &sc.physics, mats, &x);
        let out = solver.read_particles().unwrap();
        let stress = out
            .stress
            .as_ref()
            .expect("solid particles output their stress");
        for (i, &id) in out.id.iter().enumerate() {
            if !range.contains(&(id as usize)) {
                let s = state[id as usize - base];
                let tau = [
                    s.tau_a[0], s.tau_a[1], s.tau_a[2], s.tau_a[3], s.tau_b[0], s.tau_b[1],
                ];
                assert_eq!(stress[i], tau, "updated-Lagrangian particle {id}: output τ");
            }
        }
        let (e_sigma, e_rho_tl) = tl_output_errors(&out, &range, &want, |k| {
            mats[setup.body[k] as usize].density
        });
        println!(
            "mixed {dim}D: {} updated-Lagrangian particles, dv/dt error {:.1e} of RMS {:.3e}, \
             dρ/dt {:.1e} of {:.3e}, dτ/dt {:.1e} of {:.3e}; {n_tl} total-Lagrangian, dv/dt \
             error {e_tl:.1e} of RMS {tl_rms:.3e}, output σ {e_sigma:.1e}, ρ J/ρs − 1 up to \
             {e_rho_tl:.1e}",
            ul.len(),
            e.acc,
            e.acc_rms,
            e.rho,
            e.rho_rms,
            e.tau,
            e.tau_rms
        );
        assert!(e.acc < 2e-4, "acceleration error {}", e.acc);
        assert!(e.rho < 2e-4, "density-rate error {}", e.rho);
        assert!(e.tau < 2e-4, "stress-rate error {}", e.tau);
        assert!(e_tl < 5e-5, "TL acceleration error {e_tl}");
        assert!(e_sigma < 1e-4, "TL output stress error {e_sigma}");
        assert!(e_rho_tl < 1e-4, "TL output density error {e_rho_tl}");
    }
}

/// Layer 2: the total-Lagrangian solid with integrate.wgsl's predictor–corrector (velocity
/// Verlet for forces of the positions alone) conserves kinetic + elastic energy (the f64
/// reference's discrete energy at the GPU positions), 2D and 3D, random initial velocities on
/// a jittered lattice, no gravity. cfl 0.05: the error is velocity Verlet's O(dt²) oscillation
/// of the highest modes, which random velocities excite (measured largest |E − E0|/E0 in 2D /
/// 3D with the P-wave time step: 1.1e-3 / 1.8e-3 at cfl 0.05, 4.6e-3 / 6.9e-3 at 0.1, 2.2e-2 in
/// 2D at 0.2; with the bulk sound speed in the time step the 2D run blew up at 0.2).
#[test]
fn total_lagrangian_conserves_energy() {
    use wgsph::reference::total_lagrangian;
    for dim in [2, 3] {
        let mut sc = random_tl_solid(dim, KernelKind::WendlandC2, 41 + dim as u64);
        sc.physics.gravity = [0.0; 3];
        sc.time.cfl = 0.05;
        let (range, setup) = wgsph::sph::total_lagrangian::setup(&sc).unwrap();
        let solids = sc.solids.as_ref().unwrap();
        let mats = &solids.materials;
        let total = |pos: &[[f64; 3]], vel: &[[f64; 3]]| -> (f64, f64) {
            let x: Vec<[f64; 3]> = pos[range.clone()].to_vec();
            let ke: f64 = range
                .clone()
                .map(|i| {
                    let (m, v) = (solids.material_of(i), vel[i]);
                    0.5 * m.particle_mass(sc.physics.dx, dim)
                        * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
                })
                .sum();
            (ke, total_lagrangian::energy(&setup, &sc.physics, mats, &x))
        };
        let pos0: Vec<[f64; 3]> = sc.particles.iter().map(|p| p.pos).collect();
        let vel0: Vec<[f64; 3]> = sc.particles.iter().map(|p| p.vel).collect();
        let (k0, u0) = total(&pos0, &vel0);
        let mut solver = Solver::new(gpu(), &sc).unwrap();
        let mut worst = 0.0f64;
        let mut u_max = 0.0f64;
        for k in 1..=4 {
            solver.advance_to(0.002 * k as f64).unwrap();
            let p = solver.read_particles().unwrap();
            let vel: Vec<[f64; 3]> = p.vel.iter().map(|v| v.map(|c| c as f64)).collect();
            let (ke, u) = total(&p.pos, &vel);
            u_max = u_max.max(u);
            worst = worst.max(((ke + u) - (k0 + u0)).abs() / (k0 + u0));
        }
        println!(
            "TL {dim}D: {} steps, E0 = {:.4e} J (elastic {u0:.1e}), largest elastic {u_max:.3e} J, \
             largest |E − E0|/E0 {worst:.1e}",
            solver.steps(),
            k0 + u0
        );
        assert!(u_max > 0.1 * k0, "the solid barely deformed: {u_max:e} J");
        assert!(worst < 5e-3, "energy drift {worst:e}");
    }
}
