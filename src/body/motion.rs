//! Prescribed motion laws: a displacement d(t) and a rotation θ(t) about a fixed axis through
//! a pivot that moves with d. A material point initially at x0 is at
//! x(t) = pivot + d(t) + R(θ(t))(x0 − pivot), and moves at u = ḋ + θ̇ axis × (x − pivot − d).

use glam::{DQuat, DVec3};

use super::Pose;
use crate::scenario::{MotionLaw, Prescribed};

/// (d, θ) and their time derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub translation: DVec3,
    pub velocity: DVec3,
    pub angle: f64,
    pub angle_rate: f64,
}

impl MotionLaw {
    pub fn sample(&self, t: f64) -> Sample {
        match self {
            MotionLaw::Fixed => Sample {
                translation: DVec3::ZERO,
                velocity: DVec3::ZERO,
                angle: 0.0,
                angle_rate: 0.0,
            },
            MotionLaw::Sine {
                translation,
                angle,
                omega,
                phase,
            } => {
                let (s, c) = (omega * t + phase).sin_cos();
                let a = DVec3::from_array(*translation);
                Sample {
                    translation: a * s,
                    velocity: a * omega * c,
                    angle: angle * s,
                    angle_rate: angle * omega * c,
                }
            }
            MotionLaw::Series {
                t: ts,
                translation,
                angle,
            } => {
                let value = |k: usize| {
                    let d = translation[k];
                    [d[0], d[1], d[2], angle[k]]
                };
                let (y, dy) = hermite(ts, value, t);
                Sample {
                    translation: DVec3::new(y[0], y[1], y[2]),
                    velocity: DVec3::new(dy[0], dy[1], dy[2]),
                    angle: y[3],
                    angle_rate: dy[3],
                }
            }
        }
    }
}

impl Prescribed {
    /// The pose at time `t` of a body whose centre of mass was at `center0` at t = 0.
    pub fn pose(&self, center0: DVec3, t: f64) -> Pose {
        let s = self.law.sample(t);
        let axis = DVec3::from_array(self.axis);
        let pivot = DVec3::from_array(self.pivot) + s.translation;
        let rotation = DQuat::from_axis_angle(axis, s.angle);
        let center = pivot + rotation * (center0 - DVec3::from_array(self.pivot));
        let omega = axis * s.angle_rate;
        Pose {
            center,
            rotation,
            velocity: s.velocity + omega.cross(center - pivot),
            omega,
        }
    }
}

/// Cubic Hermite interpolation of samples `value(k)` at times `ts` (strictly increasing), with
/// centred-difference slopes (one-sided at the ends); constant outside [ts[0], ts[last]].
/// Returns the value and its time derivative.
fn hermite(ts: &[f64], value: impl Fn(usize) -> [f64; 4], t: f64) -> ([f64; 4], [f64; 4]) {
    let n = ts.len();
    if n == 1 || t <= ts[0] {
        return (value(0), [0.0; 4]);
    }
    if t >= ts[n - 1] {
        return (value(n - 1), [0.0; 4]);
    }
    let k = ts.partition_point(|&s| s <= t) - 1;
    let slope = |i: usize| {
        let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
        let (ya, yb) = (value(a), value(b));
        let span = ts[b] - ts[a];
        [0, 1, 2, 3].map(|c| (yb[c] - ya[c]) / span)
    };
    let h = ts[k + 1] - ts[k];
    let s = (t - ts[k]) / h;
    let (y0, y1, m0, m1) = (value(k), value(k + 1), slope(k), slope(k + 1));
    let (s2, s3) = (s * s, s * s * s);
    let (h00, h10, h01, h11) = (
        2.0 * s3 - 3.0 * s2 + 1.0,
        s3 - 2.0 * s2 + s,
        -2.0 * s3 + 3.0 * s2,
        s3 - s2,
    );
    let (d00, d10, d01, d11) = (
        6.0 * s2 - 6.0 * s,
        3.0 * s2 - 4.0 * s + 1.0,
        -6.0 * s2 + 6.0 * s,
        3.0 * s2 - 2.0 * s,
    );
    let mut y = [0.0; 4];
    let mut dy = [0.0; 4];
    for c in 0..4 {
        y[c] = h00 * y0[c] + h10 * h * m0[c] + h01 * y1[c] + h11 * h * m1[c];
        dy[c] = (d00 * y0[c] + d01 * y1[c]) / h + d10 * m0[c] + d11 * m1[c];
    }
    (y, dy)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pitch(law: MotionLaw) -> Prescribed {
        Prescribed {
            pivot: [0.5, 0.0, 0.0],
            axis: [0.0, 0.0, 1.0],
            law,
        }
    }

    #[test]
    fn sine_velocity_is_the_derivative_of_the_position() {
        let p = pitch(MotionLaw::Sine {
            translation: [0.02, 0.01, 0.0],
            angle: 4f64.to_radians(),
            omega: 2.0,
            phase: 0.3,
        });
        let c0 = DVec3::new(0.46, 0.2, 0.0);
        for t in [0.0, 0.37, 1.9, 4.2] {
            let e = 1e-6;
            let (a, b) = (p.pose(c0, t - e), p.pose(c0, t + e));
            let fd = (b.center - a.center) / (2.0 * e);
            let pose = p.pose(c0, t);
            assert!(
                (fd - pose.velocity).length() < 1e-8,
                "t = {t}: {fd} vs {}",
                pose.velocity
            );
            let fd_angle = (b.angle_z() - a.angle_z()) / (2.0 * e);
            assert!((fd_angle - pose.omega.z).abs() < 1e-8);
        }
    }

    #[test]
    fn a_point_on_the_pivot_only_translates() {
        let p = pitch(MotionLaw::Sine {
            translation: [0.0; 3],
            angle: 0.1,
            omega: 1.0,
            phase: 0.0,
        });
        let pose = p.pose(DVec3::new(0.5, 0.0, 0.0), 1.0);
        assert!((pose.center - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-15);
        assert!(pose.velocity.length() < 1e-15);
        assert!((pose.angle_z() - 1f64.sin() * 0.1).abs() < 1e-14);
    }

    #[test]
    fn series_passes_through_its_samples_and_reproduces_a_line() {
        let ts = vec![0.0, 0.5, 1.2, 2.0];
        let law = MotionLaw::Series {
            translation: ts.iter().map(|&t| [0.1 * t, -0.2 * t, 0.0]).collect(),
            angle: ts.iter().map(|&t| 0.05 * t).collect(),
            t: ts.clone(),
        };
        for &t in &ts {
            let s = law.sample(t);
            assert!((s.translation.x - 0.1 * t).abs() < 1e-15);
        }
        // Centred slopes are exact for a linear law, so the interpolant is the line itself.
        for t in [0.1, 0.77, 1.5, 1.99] {
            let s = law.sample(t);
            assert!((s.translation - DVec3::new(0.1 * t, -0.2 * t, 0.0)).length() < 1e-14);
            assert!((s.velocity - DVec3::new(0.1, -0.2, 0.0)).length() < 1e-13);
            assert!((s.angle - 0.05 * t).abs() < 1e-15 && (s.angle_rate - 0.05).abs() < 1e-13);
        }
        // Held outside the span.
        assert_eq!(law.sample(-1.0).translation, DVec3::ZERO);
        assert_eq!(law.sample(9.0).velocity, DVec3::ZERO);
        assert!((law.sample(9.0).angle - 0.1).abs() < 1e-15);
    }

    #[test]
    fn series_of_a_sine_is_close_to_the_sine() {
        let ts: Vec<f64> = (0..=200).map(|k| k as f64 * 0.02).collect();
        let law = MotionLaw::Series {
            translation: vec![[0.0; 3]; ts.len()],
            angle: ts.iter().map(|&t| (2.0 * t).sin()).collect(),
            t: ts.clone(),
        };
        for t in [0.013, 1.111, 3.33] {
            let s = law.sample(t);
            assert!((s.angle - (2.0 * t).sin()).abs() < 1e-5);
            assert!((s.angle_rate - 2.0 * (2.0 * t).cos()).abs() < 2e-3);
        }
    }
}
