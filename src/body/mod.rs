//! Host side of moving solids: prescribed motion laws ([`motion`]) and rigid-body dynamics
//! ([`dynamics`]), in f64. The GPU moves the body particles from the poses computed here and
//! sums the fluid's force and torque per body (`src/sph/bodies.rs`); only those small per-body
//! arrays cross the bus each step.

pub mod dynamics;
pub mod motion;

use glam::{DQuat, DVec3};

use crate::scenario::{Body, Motion, Prescribed};
use dynamics::RigidBody;

/// Where a body is and how it moves at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pose {
    /// Centre of mass [m].
    pub center: DVec3,
    /// Rotation from the body's orientation at t = 0.
    pub rotation: DQuat,
    /// Velocity of the centre of mass [m/s].
    pub velocity: DVec3,
    /// Angular velocity, world axes [rad/s].
    pub omega: DVec3,
}

impl Pose {
    /// Velocity of the material point at `x` (u = u_c + ω × (x − x_c)).
    pub fn velocity_at(&self, x: DVec3) -> DVec3 {
        self.velocity + self.omega.cross(x - self.center)
    }

    /// Rotation angle about z (2D bodies), in (−π, π].
    pub fn angle_z(&self) -> f64 {
        let (axis, angle) = self.rotation.to_axis_angle();
        if axis.z < 0.0 {
            -angle
        } else {
            angle
        }
    }
}

/// The force and torque (about the centre of mass) that the fluid and contacts exert on a
/// body, as summed on the GPU; gravity is not included.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Load {
    pub force: DVec3,
    pub torque: DVec3,
}

/// Column names of a body's CSV (`probes/body_<name>.csv`, after `t_s`): the centre of mass,
/// the rotation (2D: angle; 3D: quaternion), their rates, and the fluid + contact load
/// (gravity excluded).
pub fn csv_columns(dim: u32) -> Vec<String> {
    let cols: &[&str] = if dim == 2 {
        &[
            "x_m",
            "y_m",
            "angle_deg",
            "vx_m_s",
            "vy_m_s",
            "omega_rad_s",
            "fx_n",
            "fy_n",
            "torque_nm",
        ]
    } else {
        &[
            "x_m",
            "y_m",
            "z_m",
            "qw",
            "qx",
            "qy",
            "qz",
            "vx_m_s",
            "vy_m_s",
            "vz_m_s",
            "omega_x_rad_s",
            "omega_y_rad_s",
            "omega_z_rad_s",
            "fx_n",
            "fy_n",
            "fz_n",
            "tx_nm",
            "ty_nm",
            "tz_nm",
        ]
    };
    cols.iter().map(|c| c.to_string()).collect()
}

/// One CSV row of a body, in the order of [`csv_columns`]. 2D forces and torques are per
/// metre of depth.
pub fn csv_row(pose: &Pose, load: &Load, dim: u32) -> Vec<f64> {
    let (c, v, w, f, t) = (
        pose.center,
        pose.velocity,
        pose.omega,
        load.force,
        load.torque,
    );
    if dim == 2 {
        vec![
            c.x,
            c.y,
            pose.angle_z().to_degrees(),
            v.x,
            v.y,
            w.z,
            f.x,
            f.y,
            t.z,
        ]
    } else {
        let q = pose.rotation;
        vec![
            c.x, c.y, c.z, q.w, q.x, q.y, q.z, v.x, v.y, v.z, w.x, w.y, w.z, f.x, f.y, f.z, t.x,
            t.y, t.z,
        ]
    }
}

enum State {
    /// A free body, held at rest until t = `release_s`; `held`: in the step being taken (set
    /// by the predictor).
    Free {
        body: RigidBody,
        release_s: f64,
        held: bool,
    },
    Prescribed {
        law: Prescribed,
        center0: DVec3,
        pose: Pose,
    },
}

/// Every body of a run, stepped with the fluid's predictor–corrector.
pub struct BodySet {
    states: Vec<State>,
    loads: Vec<Load>,
    gravity: DVec3,
    /// 2D: poses are kept exactly in the z = 0 plane (a rounding-level z would put particles
    /// outside a 2D domain, whose z extent is 0).
    planar: bool,
}

impl BodySet {
    pub fn new(bodies: &[Body], gravity: [f64; 3], dim: u32) -> Self {
        let states = bodies
            .iter()
            .map(|b| {
                let center0 = DVec3::from_array(b.center);
                match &b.motion {
                    Motion::Free {
                        velocity,
                        omega,
                        release_s,
                    } => State::Free {
                        body: RigidBody::new(b, *velocity, *omega, dim == 2),
                        release_s: *release_s,
                        held: *release_s > 0.0,
                    },
                    Motion::Prescribed(law) => State::Prescribed {
                        pose: law.pose(center0, 0.0),
                        law: law.clone(),
                        center0,
                    },
                }
            })
            .collect();
        Self {
            states,
            loads: vec![Load::default(); bodies.len()],
            gravity: DVec3::from_array(gravity),
            planar: dim == 2,
        }
    }

    pub fn len(&self) -> usize {
        self.states.len()
    }

    pub fn is_empty(&self) -> bool {
        self.states.is_empty()
    }

    /// Predictor: every body moved to `t_next = t + dt` (free bodies with their last
    /// acceleration, prescribed ones by their law; a free body not yet released stays at rest
    /// until the first step that ends after its `release_s`, by more than the 1e-4 dt of
    /// rounding the GPU's clock counts as arrival). Returns the poses the step evaluates at.
    pub fn predict(&mut self, t_next: f64, dt: f64) -> Vec<Pose> {
        let planar = self.planar;
        self.states
            .iter_mut()
            .map(|s| {
                let pose = match s {
                    State::Free {
                        body,
                        release_s,
                        held,
                    } => {
                        *held = t_next <= *release_s + 1e-4 * dt;
                        if !*held {
                            body.predict(dt);
                        }
                        &mut body.pose
                    }
                    State::Prescribed { law, center0, pose } => {
                        *pose = law.pose(*center0, t_next);
                        pose
                    }
                };
                if planar {
                    pose.center.z = 0.0;
                    pose.velocity.z = 0.0;
                    pose.omega = DVec3::new(0.0, 0.0, pose.omega.z);
                }
                *pose
            })
            .collect()
    }

    /// Each body's linear and angular acceleration at `t` (the step's predicted time): a free
    /// body's of the last evaluation (what its predictor moved it with), a prescribed one's by
    /// central differences of its law's velocities (ε = 1e-5 s). What a body's fixed ghosts
    /// carry the fluid pressure along (g − a, Adami, Hu & Adams 2012, eq. 27).
    pub fn accelerations(&self, t: f64) -> Vec<[DVec3; 2]> {
        // (After `predict`, which marks the bodies held in this step.)
        const EPS: f64 = 1e-5;
        self.states
            .iter()
            .map(|s| match s {
                // A held body is at rest, whatever its load would do to it.
                State::Free { held: true, .. } => [DVec3::ZERO; 2],
                State::Free { body, .. } => [body.accel, body.alpha],
                State::Prescribed { law, center0, .. } => {
                    let (a, b) = (law.pose(*center0, t - EPS), law.pose(*center0, t + EPS));
                    [
                        (b.velocity - a.velocity) / (2.0 * EPS),
                        (b.omega - a.omega) / (2.0 * EPS),
                    ]
                }
            })
            .map(|[a, alpha]| {
                if self.planar {
                    [DVec3::new(a.x, a.y, 0.0), DVec3::new(0.0, 0.0, alpha.z)]
                } else {
                    [a, alpha]
                }
            })
            .collect()
    }

    /// Corrector with the loads evaluated at the predicted poses. A body held in this step
    /// stays at rest but takes the accelerations its load gives, so that the step that
    /// releases it starts as any other does.
    pub fn correct(&mut self, dt: f64, loads: &[Load]) {
        for ((s, load), last) in self.states.iter_mut().zip(loads).zip(&mut self.loads) {
            if let State::Free { body, held, .. } = s {
                // Held: a corrector of no time (velocities unchanged, accelerations taken).
                body.correct(if *held { 0.0 } else { dt }, *load, self.gravity);
            }
            *last = *load;
        }
    }

    /// The current pose of body `k`.
    pub fn pose(&self, k: usize) -> Pose {
        match &self.states[k] {
            State::Free { body, .. } => body.pose,
            State::Prescribed { pose, .. } => *pose,
        }
    }

    /// The load of the last evaluation on body `k`.
    pub fn load(&self, k: usize) -> Load {
        self.loads[k]
    }

    /// Everything that outlives a step, as [`SAVED_PER_BODY`] numbers per body, for
    /// checkpoints: pose, accelerations (free bodies; zero for prescribed ones) and last load.
    pub fn save(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(SAVED_PER_BODY * self.len());
        for (s, load) in self.states.iter().zip(&self.loads) {
            let (pose, accel, alpha) = match s {
                State::Free { body, .. } => (body.pose, body.accel, body.alpha),
                State::Prescribed { pose, .. } => (*pose, DVec3::ZERO, DVec3::ZERO),
            };
            out.extend(pose.center.to_array());
            out.extend(pose.rotation.to_array());
            for v in [
                pose.velocity,
                pose.omega,
                accel,
                alpha,
                load.force,
                load.torque,
            ] {
                out.extend(v.to_array());
            }
        }
        out
    }

    /// Puts back what [`save`](Self::save) gave, for the same bodies.
    pub fn restore(&mut self, saved: &[f64]) -> anyhow::Result<()> {
        if saved.len() != SAVED_PER_BODY * self.len() {
            anyhow::bail!(
                "the saved state has {} numbers for the bodies; this case's {} bodies need {}",
                saved.len(),
                self.len(),
                SAVED_PER_BODY * self.len()
            );
        }
        for ((s, load), v) in self
            .states
            .iter_mut()
            .zip(&mut self.loads)
            .zip(saved.chunks_exact(SAVED_PER_BODY))
        {
            let vec3 = |k: usize| DVec3::new(v[k], v[k + 1], v[k + 2]);
            let pose = Pose {
                center: vec3(0),
                rotation: DQuat::from_xyzw(v[3], v[4], v[5], v[6]),
                velocity: vec3(7),
                omega: vec3(10),
            };
            match s {
                State::Free { body, .. } => {
                    body.pose = pose;
                    body.accel = vec3(13);
                    body.alpha = vec3(16);
                }
                State::Prescribed { pose: p, .. } => *p = pose,
            }
            *load = Load {
                force: vec3(19),
                torque: vec3(22),
            };
        }
        Ok(())
    }
}

/// Numbers per body in [`BodySet::save`]: centre 3, quaternion 4, velocity 3, ω 3,
/// accelerations 3 + 3, force 3, torque 3.
pub const SAVED_PER_BODY: usize = 25;

#[cfg(test)]
mod tests {
    use super::*;

    /// A body held until t = 0.5005 s under gravity alone stays where it is, at rest, and its
    /// ghosts see no acceleration; the step from 0.5 s is the first that ends after the release,
    /// and from it the body falls as one dropped at 0.5 s (the predictor–corrector is exact for
    /// a constant acceleration, so only if the held body took its accelerations).
    #[test]
    fn a_held_body_rests_until_its_release_then_falls_from_rest() {
        const RELEASE: f64 = 0.5005;
        let body = Body {
            name: "held".into(),
            particles: 0..1,
            mass: 2.0,
            center: [0.0, 1.0, 0.0],
            inertia: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            motion: Motion::Free {
                velocity: [0.0; 3],
                omega: [0.0; 3],
                release_s: RELEASE,
            },
        };
        let g = 9.81;
        let mut set = BodySet::new(&[body], [0.0, -g, 0.0], 2);
        let dt = 1e-3;
        for k in 1..=1000 {
            let t_next = k as f64 * dt;
            let pose = set.predict(t_next, dt)[0];
            let [accel, alpha] = set.accelerations(t_next)[0];
            if t_next <= RELEASE {
                assert_eq!(pose.center, DVec3::new(0.0, 1.0, 0.0), "t = {t_next}");
                assert_eq!((pose.velocity, pose.omega), (DVec3::ZERO, DVec3::ZERO));
                assert_eq!((accel, alpha), (DVec3::ZERO, DVec3::ZERO));
            } else {
                assert_eq!(accel, DVec3::new(0.0, -g, 0.0), "t = {t_next}");
            }
            set.correct(dt, &[Load::default()]);
        }
        let (pose, fall) = (set.pose(0), 0.5);
        assert!(
            (pose.center.y - (1.0 - 0.5 * g * fall * fall)).abs() < 1e-9,
            "{pose:?}"
        );
        assert!((pose.velocity.y + g * fall).abs() < 1e-9, "{pose:?}");
        assert_eq!(pose.center.x, 0.0);
    }
}
