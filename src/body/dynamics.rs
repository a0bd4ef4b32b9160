//! Rigid-body dynamics of a free body (the seed's rigid-body equations): Newton for the centre
//! of mass, M dV/dt = F + M g, and Euler for the rotation, d(I ω)/dt = T, with F and T the sums
//! of the particle forces and of their moments about the centre of mass. In 2D the rotation is
//! about z only; in 3D the orientation is a quaternion and the inertia tensor rotates with the
//! body, I = R I0 Rᵀ, so dω/dt = I⁻¹ (T − ω × I ω).
//!
//! Stepped with the same velocity-Verlet predictor–corrector as the fluid
//! (shaders/integrate.wgsl): the predictor moves the body with its last accelerations, the GPU
//! evaluates the loads at the predicted pose, the corrector takes the trapezoidal mean.

use glam::{DMat3, DQuat, DVec3};

use super::{Load, Pose};
use crate::scenario::Body;

pub struct RigidBody {
    pub mass: f64,
    /// Inertia about the centre of mass at t = 0, world axes.
    inertia0: DMat3,
    pub pose: Pose,
    /// Linear and angular accelerations of the last evaluation.
    pub(super) accel: DVec3,
    pub(super) alpha: DVec3,
    /// Rotation about z only (2D).
    planar: bool,
}

impl RigidBody {
    pub fn new(body: &Body, velocity: [f64; 3], omega: [f64; 3], planar: bool) -> Self {
        let mut omega = DVec3::from_array(omega);
        if planar {
            omega = DVec3::new(0.0, 0.0, omega.z);
        }
        Self {
            mass: body.mass,
            inertia0: DMat3::from_cols_array_2d(&body.inertia).transpose(),
            pose: Pose {
                center: DVec3::from_array(body.center),
                rotation: DQuat::IDENTITY,
                velocity: DVec3::from_array(velocity),
                omega,
            },
            accel: DVec3::ZERO,
            alpha: DVec3::ZERO,
            planar,
        }
    }

    /// x += dt v + ½dt² a, v += dt a, and likewise for the rotation (the rotation vector of the
    /// step is dt (ω + ½dt α)).
    pub fn predict(&mut self, dt: f64) {
        let p = &mut self.pose;
        p.center += dt * p.velocity + 0.5 * dt * dt * self.accel;
        let turn = dt * (p.omega + 0.5 * dt * self.alpha);
        p.rotation = (DQuat::from_scaled_axis(turn) * p.rotation).normalize();
        p.velocity += dt * self.accel;
        p.omega += dt * self.alpha;
    }

    /// New accelerations from the load at the predicted pose; v += ½dt (a_new − a_old).
    pub fn correct(&mut self, dt: f64, load: Load, gravity: DVec3) {
        let accel = load.force / self.mass + gravity;
        let alpha = self.angular_acceleration(load.torque);
        self.pose.velocity += 0.5 * dt * (accel - self.accel);
        self.pose.omega += 0.5 * dt * (alpha - self.alpha);
        self.accel = accel;
        self.alpha = alpha;
    }

    fn angular_acceleration(&self, torque: DVec3) -> DVec3 {
        if self.planar {
            return DVec3::new(0.0, 0.0, torque.z / self.inertia0.z_axis.z);
        }
        let r = DMat3::from_quat(self.pose.rotation);
        let inertia = r * self.inertia0 * r.transpose();
        let w = self.pose.omega;
        inertia.inverse() * (torque - w.cross(inertia * w))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Motion;

    fn body(mass: f64, inertia: [[f64; 3]; 3]) -> Body {
        Body {
            name: "b".into(),
            particles: 0..1,
            mass,
            center: [1.0, 2.0, 0.0],
            inertia,
            motion: Motion::Free {
                velocity: [0.0; 3],
                omega: [0.0; 3],
                release_s: 0.0,
            },
        }
    }

    fn step(b: &mut RigidBody, dt: f64, load: impl Fn(&Pose) -> Load, g: DVec3) {
        b.predict(dt);
        let l = load(&b.pose);
        b.correct(dt, l, g);
    }

    #[test]
    fn free_fall_is_exact() {
        let g = DVec3::new(0.0, -9.81, 0.0);
        let mut b = RigidBody::new(
            &body(3.0, [[1.0, 0.0, 0.0]; 3]),
            [1.0, 0.5, 0.0],
            [0.0; 3],
            true,
        );
        b.correct(0.0, Load::default(), g);
        let dt = 1e-3;
        for _ in 0..1000 {
            step(&mut b, dt, |_| Load::default(), g);
        }
        let t = 1.0;
        let want = DVec3::new(1.0 + t, 2.0 + 0.5 * t - 0.5 * 9.81 * t * t, 0.0);
        assert!((b.pose.center - want).length() < 1e-9, "{}", b.pose.center);
        assert!((b.pose.velocity - DVec3::new(1.0, 0.5 - 9.81, 0.0)).length() < 1e-9);
    }

    #[test]
    fn planar_spring_oscillates_at_its_frequency() {
        // A torsion spring T = −k θ on I = 2: θ = θ0 cos(sqrt(k/I) t).
        let inertia = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]];
        let mut b = RigidBody::new(&body(1.0, inertia), [0.0; 3], [0.0; 3], true);
        b.pose.rotation = DQuat::from_rotation_z(0.1);
        let k = 8.0;
        let spring = |p: &Pose| Load {
            force: DVec3::ZERO,
            torque: DVec3::new(0.0, 0.0, -k * p.angle_z()),
        };
        b.correct(0.0, spring(&b.pose), DVec3::ZERO);
        let dt = 1e-4;
        let steps = 15_708; // t ≈ π/2, half a period: θ ≈ −0.1
        for _ in 0..steps {
            step(&mut b, dt, spring, DVec3::ZERO);
        }
        let t = steps as f64 * dt;
        let want = 0.1 * (2.0 * t).cos();
        assert!(
            (b.pose.angle_z() - want).abs() < 1e-6,
            "{} vs {want}",
            b.pose.angle_z()
        );
    }

    #[test]
    fn torque_free_rotation_conserves_angular_momentum_and_energy() {
        // An asymmetric top spinning about a tilted axis: the world-frame L = I ω and the
        // energy ½ ω·I ω stay constant (the axis itself tumbles).
        let inertia = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]];
        let mut b = RigidBody::new(&body(1.0, inertia), [0.0; 3], [0.3, 1.0, 0.2], false);
        b.correct(0.0, Load::default(), DVec3::ZERO);
        let world_inertia = |b: &RigidBody| {
            let r = DMat3::from_quat(b.pose.rotation);
            r * b.inertia0 * r.transpose()
        };
        let l0 = world_inertia(&b) * b.pose.omega;
        let e0 = 0.5 * b.pose.omega.dot(world_inertia(&b) * b.pose.omega);
        let start = DVec3::new(0.3, 1.0, 0.2).normalize();
        let mut least_aligned: f64 = 1.0;
        for _ in 0..20_000 {
            step(&mut b, 5e-4, |_| Load::default(), DVec3::ZERO);
            let body_frame = b.pose.rotation.inverse() * b.pose.omega;
            least_aligned = least_aligned.min(body_frame.normalize().dot(start));
        }
        let l = world_inertia(&b) * b.pose.omega;
        let e = 0.5 * b.pose.omega.dot(world_inertia(&b) * b.pose.omega);
        assert!((l - l0).length() < 1e-3 * l0.length(), "{l} vs {l0}");
        assert!((e - e0).abs() < 1e-3 * e0, "{e} vs {e0}");
        // The motion is not trivial: near the intermediate axis the spin flips in the body
        // frame (the Dzhanibekov effect).
        assert!(least_aligned < -0.5, "{least_aligned}");
    }
}
