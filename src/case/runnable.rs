//! The last checks of a built case: what the GPU computes with fits its f32 arithmetic, and the
//! run can be stepped to its end and sampled. The loader checks each field in f64; these are
//! the quantities derived from several (issue 64: cases it accepted "completed" with 0 steps
//! because the time step was 0 in f32 — `time.cfl = 1e-50`, `sound_speed_coef = 1e40`,
//! `nu_m2_s = 1e40`, a free body spinning at 1e308 rad/s — or never advanced, with a probe
//! interval of 1e-300 s).

use super::error::{num, CaseError};
use super::locate::Ctx;
use super::validate::Block;
use super::warnings::round3;
use glam::DVec3;

use crate::scenario::{Kind, Motion, MotionLaw, Scenario, Viscosity};

/// The magnitudes a quantity the GPU multiplies and divides in f32 must lie between: a
/// product or quotient of two such stays a normal f32 (1e±30, inside 1.2e-38 to 3.4e38).
const F32_SAFE: (f64, f64) = (1e-15, 1e15);

/// The most steps a run may need to its end (ten thousand steps a second for 11 days).
const MAX_STEPS: f64 = 1e10;

/// The most probe samples of a run: every probe's rows are held in memory until written.
const MAX_SAMPLES: f64 = 1e7;

/// The shortest probe interval, in time steps: below 1e-4 of a step the solver takes no step
/// to reach a probe time (the last step is never a sliver: `timestep` in integrate.wgsl), so
/// the rows would repeat one state while the clock moved on without the water.
const MIN_PROBE_STEPS: f64 = 1e-3;

/// Where a speed the time step sees comes from, for messages.
struct Fastest {
    speed: f64,
    field: String,
}

/// Checks the built scenario `sc`: its f32 quantities, the speeds its motions reach against
/// the speed of sound, its time step and its schedule. `sound_field`: the field the speed of
/// sound came from (None: solids alone); `blocks`: the fluid blocks (to name a fast one);
/// `tank_moves`: the first body is the tank, which carries the `obstacles` (their paths).
/// Returns the warning of a case with water whose fastest speed is beyond c0/10.
pub(super) fn check(
    ctx: &Ctx<'_>,
    sc: &Scenario,
    sound_field: Option<&str>,
    blocks: &[Block],
    (tank_moves, obstacles): (bool, &[String]),
) -> Result<Option<String>, CaseError> {
    f32_quantities(ctx, sc, sound_field)?;
    // The fastest a particle moves: set at the start (a block, an inlet, a free body's
    // translation and spin) or by a prescribed motion over the run.
    let moving = faster(
        fastest_flow(sc, blocks, tank_moves),
        prescribed_speed(sc, tank_moves, obstacles),
    );
    let mut warning = None;
    if let Some(sound) = sound_field {
        below_sound(ctx, sc, sound, &moving)?;
        let has_water = sc.count(Kind::Fluid) > 0 || !sc.inlets.is_empty();
        warning = has_water
            .then(|| beyond_a_tenth_of_sound(sc, sound, &moving))
            .flatten();
    }
    let (dt, limit) = time_step(ctx, sc, sound_field, moving)?;
    schedule(ctx, sc, dt, &limit)?;
    Ok(warning)
}

/// The fastest speed a particle starts with or a prescribed motion reaches (`moving`) when it
/// is more than c0/10: weakly compressible SPH then compresses the water by more than about
/// (u/c0)² = 1 %. The speeds the flow reaches on its own (a dam break's fall) are not known.
fn beyond_a_tenth_of_sound(sc: &Scenario, sound: &str, moving: &Fastest) -> Option<String> {
    let (u, c0) = (moving.speed, sc.physics.c0);
    (u > 0.1 * c0).then(|| {
        format!(
            "{} sets a speed of {} m/s, more than c0/10 = {} m/s (c0 from {sound}): the water \
             is compressed by about (u/c0)² = {} %, more than weakly compressible SPH allows; \
             fix: raise {sound} so that c0 is at least {} m/s (the time step shrinks with it)",
            moving.field,
            num(round3(u)),
            num(round3(0.1 * c0)),
            num(round3(100.0 * (u / c0).powi(2))),
            num(round3(10.0 * u))
        )
    })
}

/// The fastest a prescribed motion (the tank's, a body's) moves one of its particles over the
/// run: the corners of each body's particles' box, at every 1/2000 of the run (or of a sine's
/// period, when shorter). The tank carries its `obstacles` (their paths), named with it.
fn prescribed_speed(sc: &Scenario, tank_moves: bool, obstacles: &[String]) -> Fastest {
    let mut fastest = Fastest {
        speed: 0.0,
        field: "no motion".into(),
    };
    for (k, b) in sc.bodies.iter().enumerate() {
        let Motion::Prescribed(law) = &b.motion else {
            continue;
        };
        let span = match law.law {
            MotionLaw::Sine { omega, .. } if omega > 0.0 => {
                sc.time.end_s.min(std::f64::consts::TAU / omega)
            }
            _ => sc.time.end_s,
        };
        let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
        for p in &sc.particles[b.particles.clone()] {
            for a in 0..3 {
                (lo[a], hi[a]) = (lo[a].min(p.pos[a]), hi[a].max(p.pos[a]));
            }
        }
        let corners = (0..8).map(|c: usize| {
            DVec3::from_array([0, 1, 2].map(|a| if c >> a & 1 == 1 { hi[a] } else { lo[a] }))
        });
        const SAMPLES: usize = 2000;
        let speed = corners
            .flat_map(|c| (0..=SAMPLES).map(move |s| law.pose(c, span * s as f64 / SAMPLES as f64)))
            .map(|pose| pose.velocity.length())
            .fold(0.0, f64::max);
        let field = match (k, tank_moves) {
            (0, true) if obstacles.is_empty() => "tank.motion".to_string(),
            (0, true) => format!("tank.motion (with {})", obstacles.join(", ")),
            _ => format!("body[{}].motion", k - tank_moves as usize),
        };
        fastest = faster(fastest, Fastest { speed, field });
    }
    fastest
}

/// The water is not so slow to sound that its own weight compresses it, and the fastest
/// particle (`moving`: the flow, a body, what a prescribed motion pushes) moves below the speed
/// of sound c0: at or above it weakly-compressible SPH has no solution, and a run went
/// unstable at once blaming c0's coefficient (issue 64: a tank rolling about a pivot 1 km away,
/// a free body spinning at 1000 rad/s).
fn below_sound(
    ctx: &Ctx<'_>,
    sc: &Scenario,
    sound_field: &str,
    moving: &Fastest,
) -> Result<(), CaseError> {
    let c0 = sc.physics.c0;
    let fall = free_fall_speed(sc);
    if fall >= c0 {
        return Err(ctx.err(
            sound_field,
            None,
            format!(
                "gives a speed of sound c0 = {} m/s, not above sqrt(2 |g| H) = {} m/s (|g| from \
                 physics.gravity_m_s2, H the fluid's height), the speed the water reaches \
                 falling its own height: the hydrostatic pressure alone would compress it by a \
                 fifth or more",
                num(c0),
                num(fall)
            ),
            format!(
                "raise {sound_field} so that c0 is at least {} m/s (10 sqrt(|g| H))",
                num(10.0 * fall / std::f64::consts::SQRT_2)
            ),
        ));
    }
    if moving.speed < c0 {
        return Ok(());
    }
    let field = moving.field.split(" (").next().unwrap_or_default();
    // A coefficient's c0 is coef sqrt(|g| H): a tiny gravity makes it tiny (found by the case
    // fuzzing: sloshing_2d with |g| = 1.5e-13 m/s²).
    let from = match sound_field {
        "physics.sound_speed_coef" => format!(
            "{sound_field} and |physics.gravity_m_s2| = {} m/s²",
            num(sc.physics.gravity.iter().map(|g| g * g).sum::<f64>().sqrt())
        ),
        _ => sound_field.to_string(),
    };
    Err(ctx.err(
        field,
        None,
        format!(
            "{} moves its particles at up to {} m/s, not below the speed of sound c0 = {} m/s \
             (from {from}): weakly compressible SPH needs the flow and the walls to move at \
             about c0 / 10 or less",
            moving.field,
            num(moving.speed),
            num(c0)
        ),
        format!(
            "check the motion (a rotation about a pivot far away sweeps its walls fast), or \
             raise {sound_field} so that c0 is about {} m/s",
            num(10.0 * moving.speed)
        ),
    ))
}

/// ρ0, c0, Tait's B, the particle mass, the kernel's gradient scale 1/h^(d+1), |g|, ν and the
/// density diffusion's δ h c0 within [`F32_SAFE`] (zero where zero switches a term off).
fn f32_quantities(
    ctx: &Ctx<'_>,
    sc: &Scenario,
    sound_field: Option<&str>,
) -> Result<(), CaseError> {
    let ph = &sc.physics;
    let (rho0, gravity) = ("physics.rho0_kg_m3", "physics.gravity_m_s2");
    // c0 = coef sqrt(|g| H) depends on gravity too.
    let sound: &[&str] = match sound_field {
        Some(f @ "physics.sound_speed_coef") => &[f, gravity],
        Some(f) => &[f],
        None => &["[[solid]]'s moduli and density"],
    };
    let with = |more: &[&'static str]| -> Vec<&str> { sound.iter().chain(more).copied().collect() };
    let g = ph.gravity.iter().map(|c| c * c).sum::<f64>().sqrt();
    let nu = match ph.viscosity {
        Viscosity::Laminar { nu } => nu,
        Viscosity::Artificial { .. } => 0.0,
    };
    let quantities: [(&str, f64, bool, Vec<&str>); 8] = [
        ("the density ρ0", ph.rho0, false, vec![rho0]),
        ("the speed of sound c0", ph.c0, false, with(&[])),
        (
            "Tait's stiffness B = ρ0 c0² / γ",
            ph.tait_b(),
            false,
            with(&[rho0, "physics.gamma"]),
        ),
        (
            "the particle mass ρ0 dx^d",
            ph.particle_mass,
            false,
            vec![rho0, "particles.dx_m"],
        ),
        (
            "the kernel gradient's scale 1 / h^(d+1)",
            ph.h.powi(ph.dim as i32 + 1).recip(),
            false,
            vec!["particles.dx_m", "particles.h_over_dx"],
        ),
        ("|g|", g, true, vec![gravity]),
        ("the viscosity ν", nu, true, vec!["physics.nu_m2_s"]),
        (
            "the density diffusion δ h c0",
            ph.delta_sph * ph.h * ph.c0,
            true,
            with(&["physics.delta_sph"]),
        ),
    ];
    for (what, v, may_be_zero, fields) in quantities {
        let (lo, hi) = F32_SAFE;
        if (may_be_zero && v == 0.0) || (v.is_finite() && (lo..=hi).contains(&v.abs())) {
            continue;
        }
        return Err(ctx.err(
            fields[0],
            None,
            format!(
                "gives {what} = {}, which the GPU's f32 arithmetic cannot compute with (it \
                 needs magnitudes between {lo:e} and {hi:e}; from {})",
                num(v),
                fields.join(", ")
            ),
            format!("give {} of realistic size", fields.join(" and ")),
        ));
    }
    Ok(())
}

/// The time step the run starts with, as the GPU's `timestep` chooses it from the case's
/// speeds (the sound speed and the fastest speed the case sets: a block, an inlet, a body
/// turning or moving, a solid's P wave), its acceleration (gravity) and its viscosity; refused
/// when the run would need more than [`MAX_STEPS`] steps to `time.end_s` (or the step is no
/// number at all). The step, and how it came about (for messages).
fn time_step(
    ctx: &Ctx<'_>,
    sc: &Scenario,
    sound_field: Option<&str>,
    flow: Fastest,
) -> Result<(f64, String), CaseError> {
    let ph = &sc.physics;
    let cfl = sc.time.cfl;
    let wave = wave_speed(sc, sound_field);
    let mut dt = cfl * ph.h / (wave.speed + flow.speed);
    let mut limit = format!(
        "time.cfl × h / (c + |u|) = {} × {} m / ({} + {}) m/s, c from {}, |u| from {}",
        num(cfl),
        num(ph.h),
        num(wave.speed),
        num(flow.speed),
        wave.field,
        flow.field
    );
    let g = ph.gravity.iter().map(|c| c * c).sum::<f64>().sqrt();
    if g > 0.0 && cfl * (ph.h / g).sqrt() < dt {
        dt = cfl * (ph.h / g).sqrt();
        limit = "time.cfl × sqrt(h / |g|), |g| from physics.gravity_m_s2".into();
    }
    if let Viscosity::Laminar { nu } = ph.viscosity {
        if 0.125 * ph.h * ph.h / nu < dt {
            dt = 0.125 * ph.h * ph.h / nu;
            limit = "0.125 h² / ν, ν from physics.nu_m2_s".into();
        }
    }
    let steps = sc.time.end_s / dt;
    if dt.is_finite() && dt > 0.0 && steps <= MAX_STEPS {
        return Ok((dt, limit));
    }
    // The field most likely at fault: an odd Courant number or end time before the speeds.
    let field = if !(1e-3..=1.0).contains(&cfl) {
        "time.cfl"
    } else if dt >= 1e-9 {
        "time.end_s"
    } else if limit.starts_with("0.125") {
        "physics.nu_m2_s"
    } else if limit.contains("sqrt(h / |g|)") {
        "physics.gravity_m_s2"
    } else if wave.speed >= flow.speed {
        wave.field.as_str()
    } else {
        flow.field.as_str()
    };
    Err(ctx.err(
        field,
        None,
        format!(
            "the time step would be {} s ({limit}, h from particles.dx_m): the run would need {} \
             steps to time.end_s = {} s, more than the {} a run can take",
            num(dt),
            num(steps),
            num(sc.time.end_s),
            num(MAX_STEPS)
        ),
        "give realistic speeds (c0 about 10 times the fastest flow), time.cfl about 0.2 and \
         time.end_s in seconds",
    ))
}

/// sqrt(2 |g| H), H the fluid's height (its particles', inlets' included): the speed water
/// falling its own height reaches, and the hydrostatic pressure's scale (ρ0 g H = ρ0 (that
/// speed)² / 2).
fn free_fall_speed(sc: &Scenario) -> f64 {
    let v = sc.physics.dim as usize - 1;
    let g = sc.physics.gravity.iter().map(|c| c * c).sum::<f64>().sqrt();
    let water = sc
        .particles
        .iter()
        .filter(|p| matches!(p.kind, Kind::Fluid | Kind::Inlet));
    let (lo, hi) = water.fold((f64::MAX, f64::MIN), |(lo, hi), p| {
        (lo.min(p.pos[v]), hi.max(p.pos[v]))
    });
    (2.0 * g * (hi - lo).max(0.0)).sqrt()
}

/// The fastest wave: the fluid's sound speed, or an elastic solid's P wave.
fn wave_speed(sc: &Scenario, sound_field: Option<&str>) -> Fastest {
    let fluid = Fastest {
        speed: if sound_field.is_some() {
            sc.physics.c0
        } else {
            0.0
        },
        field: match sound_field {
            Some(f @ "physics.sound_speed_coef") => {
                format!("{f} and physics.gravity_m_s2 (c0 = coef sqrt(|g| H))")
            }
            f => f.unwrap_or_default().to_string(),
        },
    };
    let solids = sc
        .solids
        .iter()
        .flat_map(|s| s.materials.iter().enumerate());
    solids
        .map(|(i, m)| Fastest {
            speed: m.p_wave_speed(),
            field: format!("solid[{i}] (its P-wave speed)"),
        })
        .fold(fluid, faster)
}

/// The fastest speed a particle starts with (a block's or solid's velocity, an inlet's, a
/// body's translation and turning), and where it comes from.
fn fastest_flow(sc: &Scenario, blocks: &[Block], tank_moves: bool) -> Fastest {
    let norm = |v: &[f64; 3]| v.iter().map(|c| c * c).sum::<f64>().sqrt();
    let Some((i, p)) =
        (sc.particles.iter().enumerate()).max_by(|a, b| norm(&a.1.vel).total_cmp(&norm(&b.1.vel)))
    else {
        return Fastest {
            speed: 0.0,
            field: "no particle".into(),
        };
    };
    let body = sc.bodies.iter().position(|b| b.particles.contains(&i));
    let field = match (body, p.kind) {
        (Some(0), _) if tank_moves => "tank.motion".to_string(),
        (Some(b), _) => format!("body[{}].motion", b - tank_moves as usize),
        (None, Kind::Solid) => {
            let s = sc.solids.as_ref().map_or(0, |s| s.body[i]);
            format!("solid[{s}].velocity_m_s")
        }
        (None, Kind::Inlet) => "inlet[].velocity_m_s".into(),
        _ => match blocks.iter().position(|b| {
            (0..3).all(|a| b.bx.min[a] - 1e-9 <= p.pos[a] && p.pos[a] <= b.bx.max[a] + 1e-9)
        }) {
            Some(k) => format!("fluid_block[{k}].velocity_m_s"),
            None => "the initial velocities".into(),
        },
    };
    Fastest {
        speed: norm(&p.vel),
        field,
    }
}

fn faster(a: Fastest, b: Fastest) -> Fastest {
    if b.speed > a.speed {
        b
    } else {
        a
    }
}

/// The probe interval: at most [`MAX_SAMPLES`] samples to the end, and not below
/// [`MIN_PROBE_STEPS`] of the time step `dt` the run starts with.
fn schedule(ctx: &Ctx<'_>, sc: &Scenario, dt: f64, limit: &str) -> Result<(), CaseError> {
    let t = &sc.time;
    let samples = t.end_s / t.probe_every_s;
    let fields = "time.probe_every_s is time.output_every_s when it is not given";
    if samples > MAX_SAMPLES {
        return Err(ctx.err(
            "time.probe_every_s",
            Some(num(t.probe_every_s)),
            format!(
                "gives {} probe samples to time.end_s = {} s, more than the {} a run holds \
                 ({fields})",
                num(samples.ceil()),
                num(t.end_s),
                num(MAX_SAMPLES)
            ),
            format!(
                "give time.probe_every_s of at least {} s",
                num(t.end_s / MAX_SAMPLES)
            ),
        ));
    }
    if t.probe_every_s < MIN_PROBE_STEPS * dt {
        return Err(ctx.err(
            "time.probe_every_s",
            Some(num(t.probe_every_s)),
            format!(
                "is below a thousandth of the time step the run starts with ({} s: {limit}): \
                 probe times would pass with no step taken between them, every row the same \
                 state ({fields})",
                num(dt)
            ),
            format!(
                "give time.probe_every_s of at least {} s",
                num(MIN_PROBE_STEPS * dt)
            ),
        ));
    }
    Ok(())
}
