//! An inflow speed that varies in time (a hydrograph), and how far it has carried the water.
//!
//! The speed u(t) is a piecewise cubic in t, a polynomial in τ = t − t_k on each segment from
//! its knot t_k; the distance travelled D(t) = ∫₀ᵗ u is its exact integral, so an inlet's
//! particles are placed from the time alone (shaders/open_boundaries.wgsl `inflow_at`; a resumed
//! run places them where the uninterrupted one does). Samples (t_k, u_k) are joined linearly or
//! by the monotone cubic of Fritsch & Carlson (1980, SIAM J. Numer. Anal. 17(2)), which does not
//! overshoot: non-negative samples give a non-negative speed. The speed is held at the first
//! sample before it and at the last one after it.

/// How samples of a hydrograph are joined.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    Linear,
    /// Monotone piecewise cubic Hermite (Fritsch & Carlson 1980).
    MonotoneCubic,
}

/// One piece of a hydrograph, from its knot `t` to the next one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Its knot [s].
    pub t: f64,
    /// D(t) at the knot [m].
    pub distance: f64,
    /// u(t + τ) = c[0] + c[1] τ + c[2] τ² + c[3] τ³ [m/s].
    pub speed: [f64; 4],
}

impl Segment {
    /// The coefficients of D(t + τ) − D(t) = τ (c[0] + τ (c[1]/2 + τ (c[2]/3 + τ c[3]/4))).
    pub fn distance_coefficients(&self) -> [f64; 4] {
        let c = self.speed;
        [c[0], c[1] / 2.0, c[2] / 3.0, c[3] / 4.0]
    }

    fn speed_at(&self, tau: f64) -> f64 {
        let c = self.speed;
        c[0] + tau * (c[1] + tau * (c[2] + tau * c[3]))
    }

    fn distance_at(&self, tau: f64) -> f64 {
        let c = self.distance_coefficients();
        self.distance + tau * (c[0] + tau * (c[1] + tau * (c[2] + tau * c[3])))
    }
}

/// A speed in time: segments in increasing knot order, the first at t = 0, the last held for
/// ever.
#[derive(Clone, Debug, PartialEq)]
pub struct Hydrograph {
    segments: Vec<Segment>,
}

impl Hydrograph {
    /// The same speed at all times.
    pub fn constant(speed: f64) -> Self {
        Self {
            segments: vec![Segment {
                t: 0.0,
                distance: 0.0,
                speed: [speed, 0.0, 0.0, 0.0],
            }],
        }
    }

    /// The hydrograph through the samples `(t[k], u[k])`: times from 0 on, strictly
    /// increasing, speeds finite (the case reader checks both and says which row is wrong).
    pub fn from_samples(t: &[f64], u: &[f64], how: Interpolation) -> Self {
        assert!(!t.is_empty() && t.len() == u.len() && t[0] >= 0.0);
        let slopes = match how {
            Interpolation::Linear => None,
            Interpolation::MonotoneCubic => Some(fritsch_carlson_slopes(t, u)),
        };
        let mut segments = Vec::with_capacity(t.len() + 1);
        let mut push = |t0: f64, speed: [f64; 4]| {
            let distance = segments
                .last()
                .map_or(0.0, |s: &Segment| s.distance_at(t0 - s.t));
            segments.push(Segment {
                t: t0,
                distance,
                speed,
            });
        };
        if t[0] > 0.0 {
            push(0.0, [u[0], 0.0, 0.0, 0.0]);
        }
        for k in 0..t.len() - 1 {
            let width = t[k + 1] - t[k];
            let secant = (u[k + 1] - u[k]) / width;
            let speed = match &slopes {
                None => [u[k], secant, 0.0, 0.0],
                Some(m) => [
                    u[k],
                    m[k],
                    (3.0 * secant - 2.0 * m[k] - m[k + 1]) / width,
                    (m[k] + m[k + 1] - 2.0 * secant) / (width * width),
                ],
            };
            push(t[k], speed);
        }
        push(t[t.len() - 1], [u[u.len() - 1], 0.0, 0.0, 0.0]);
        Self { segments }
    }

    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The segment in force at `t` (the first before t = 0).
    fn segment(&self, t: f64) -> &Segment {
        let k = self.segments.partition_point(|s| s.t <= t);
        &self.segments[k.saturating_sub(1)]
    }

    /// u(t) [m/s].
    pub fn speed(&self, t: f64) -> f64 {
        let s = self.segment(t);
        s.speed_at(t - s.t)
    }

    /// D(t) = ∫₀ᵗ u [m].
    pub fn distance(&self, t: f64) -> f64 {
        let s = self.segment(t);
        s.distance_at(t - s.t)
    }

    /// The highest speed at any time: at a knot, where a linear or monotone piece has its
    /// extremes.
    pub fn max_speed(&self) -> f64 {
        let ends = self
            .segments
            .windows(2)
            .map(|w| w[0].speed_at(w[1].t - w[0].t));
        (self.segments.iter().map(|s| s.speed[0]))
            .chain(ends)
            .fold(0.0, f64::max)
    }

    /// The same hydrograph with every speed multiplied by `factor` (a discharge divided by the
    /// inlet's section).
    pub fn scaled(&self, factor: f64) -> Self {
        let segments = (self.segments.iter())
            .map(|s| Segment {
                t: s.t,
                distance: s.distance * factor,
                speed: s.speed.map(|c| c * factor),
            })
            .collect();
        Self { segments }
    }

    /// The times its value is above `z`, for a hydrograph joined linearly (a water level in
    /// time): the maximal intervals [start, end) in increasing order, the last one's end
    /// infinite where the value stays above. A value that only touches `z` is not above it.
    pub fn intervals_above(&self, z: f64) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        // The start of the interval still open at the previous piece's end.
        let mut open: Option<f64> = None;
        for (k, s) in self.segments.iter().enumerate() {
            assert!(
                s.speed[2] == 0.0 && s.speed[3] == 0.0,
                "a hydrograph joined linearly"
            );
            let end = self.segments.get(k + 1).map_or(f64::INFINITY, |n| n.t);
            let (v, slope) = (s.speed[0], s.speed[1]);
            // Where v + slope·(t − s.t) > z on this piece.
            let crossing = s.t + (z - v) / slope;
            let (lo, hi) = match slope {
                0.0 if v > z => (s.t, end),
                0.0 => (end, end),
                _ if slope > 0.0 => (crossing.max(s.t), end),
                _ => (s.t, crossing.min(end)),
            };
            if lo >= hi {
                if let Some(start) = open.take() {
                    out.push((start, s.t));
                }
                continue;
            }
            if lo > s.t {
                if let Some(start) = open.take() {
                    out.push((start, s.t));
                }
            }
            let start = *open.get_or_insert(lo);
            if hi < end {
                out.push((start, hi));
                open = None;
            }
        }
        out.extend(open.map(|start| (start, f64::INFINITY)));
        out
    }
}

/// The knot slopes of the monotone cubic through `(t, u)`: the mean of the secants on either
/// side (one-sided at the ends), zero at an extreme or a flat piece, and scaled down where
/// α² + β² > 9 so that every piece stays monotone (Fritsch & Carlson 1980, section 4).
fn fritsch_carlson_slopes(t: &[f64], u: &[f64]) -> Vec<f64> {
    let n = t.len();
    if n < 2 {
        return vec![0.0; n];
    }
    let secant: Vec<f64> = (0..n - 1)
        .map(|k| (u[k + 1] - u[k]) / (t[k + 1] - t[k]))
        .collect();
    let mut m: Vec<f64> = (0..n)
        .map(|k| match k {
            0 => secant[0],
            _ if k == n - 1 => secant[n - 2],
            _ if secant[k - 1] * secant[k] <= 0.0 => 0.0,
            _ => 0.5 * (secant[k - 1] + secant[k]),
        })
        .collect();
    for k in 0..n - 1 {
        if secant[k] == 0.0 {
            m[k] = 0.0;
            m[k + 1] = 0.0;
            continue;
        }
        let (alpha, beta) = (m[k] / secant[k], m[k + 1] / secant[k]);
        // A one-sided end slope against its secant's sign would overshoot.
        if alpha < 0.0 {
            m[k] = 0.0;
        }
        if beta < 0.0 {
            m[k + 1] = 0.0;
        }
        let (alpha, beta) = (m[k] / secant[k], m[k + 1] / secant[k]);
        let r2 = alpha * alpha + beta * beta;
        if r2 > 9.0 {
            let tau = 3.0 / r2.sqrt();
            m[k] = tau * alpha * secant[k];
            m[k + 1] = tau * beta * secant[k];
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫₀ᵗ u by Simpson's rule between the knots, exact for a cubic on each piece.
    fn integral(h: &Hydrograph, t: f64) -> f64 {
        let mut ends: Vec<f64> = (h.segments().iter().map(|s| s.t))
            .filter(|&k| k < t)
            .collect();
        ends.push(t);
        let simpson = |a: f64, b: f64| {
            // Just inside the piece, so that each end is evaluated on its own piece.
            let (a, b) = (a + 1e-15 * (b - a), b - 1e-15 * (b - a));
            (b - a) / 6.0 * (h.speed(a) + 4.0 * h.speed(0.5 * (a + b)) + h.speed(b))
        };
        ends.windows(2).map(|w| simpson(w[0], w[1])).sum()
    }

    #[test]
    fn a_constant_speed_carries_the_water_speed_times_time() {
        let h = Hydrograph::constant(1.5);
        for t in [0.0, 0.3, 7.0] {
            assert_eq!(h.speed(t), 1.5);
            assert_eq!(h.distance(t), 1.5 * t);
        }
        assert_eq!(h.max_speed(), 1.5);
    }

    #[test]
    fn samples_are_passed_through_and_held_outside() {
        let (t, u) = ([0.5, 1.0, 2.0, 3.0], [0.2, 1.0, 0.4, 0.4]);
        for how in [Interpolation::Linear, Interpolation::MonotoneCubic] {
            let h = Hydrograph::from_samples(&t, &u, how);
            for k in 0..t.len() {
                assert!((h.speed(t[k]) - u[k]).abs() < 1e-12, "{how:?} at {}", t[k]);
            }
            assert_eq!(h.speed(0.1), 0.2, "{how:?} held before the first sample");
            assert_eq!(h.speed(9.0), 0.4, "{how:?} held after the last");
            assert!((h.max_speed() - 1.0).abs() < 1e-12);
        }
        let linear = Hydrograph::from_samples(&t, &u, Interpolation::Linear);
        assert!((linear.speed(0.75) - 0.6).abs() < 1e-12);
        assert!((linear.speed(1.5) - 0.7).abs() < 1e-12);
    }

    #[test]
    fn the_distance_is_the_integral_of_the_speed() {
        let t = [0.0, 0.4, 1.1, 1.5, 2.6, 4.0];
        let u = [0.0, 2.0, 2.1, 0.3, 0.0, 1.2];
        for how in [Interpolation::Linear, Interpolation::MonotoneCubic] {
            let h = Hydrograph::from_samples(&t, &u, how);
            for t in [0.13, 0.4, 1.3, 2.9, 4.0, 5.5] {
                let (d, exact) = (h.distance(t), integral(&h, t));
                assert!(
                    (d - exact).abs() < 1e-9,
                    "{how:?} at {t}: {d} against {exact}"
                );
            }
            // Continuous across knots (to rounding).
            for w in h.segments().windows(2) {
                let tau = w[1].t - w[0].t;
                assert!((w[0].distance_at(tau) - w[1].distance).abs() < 1e-12);
                assert!((w[0].speed_at(tau) - w[1].speed[0]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn the_cubic_does_not_overshoot_steps_or_go_below_zero() {
        // A dry start, a steep rise, a plateau and a drop back to zero.
        let t = [0.0, 1.0, 1.2, 3.0, 3.1, 5.0];
        let u = [0.0, 0.0, 4.0, 4.0, 0.0, 0.0];
        let h = Hydrograph::from_samples(&t, &u, Interpolation::MonotoneCubic);
        for i in 0..=5000 {
            let s = h.speed(i as f64 * 1e-3);
            assert!((0.0..=4.0).contains(&s), "u({}) = {s}", i as f64 * 1e-3);
        }
        // Monotone between samples.
        for k in 0..t.len() - 1 {
            let sign = (u[k + 1] - u[k]).signum();
            let mut last = h.speed(t[k]);
            for i in 1..=100 {
                let s = h.speed(t[k] + (t[k + 1] - t[k]) * i as f64 / 100.0);
                assert!((s - last) * sign >= -1e-12, "piece {k}");
                last = s;
            }
        }
    }

    /// The intervals above a level against the level sampled every 0.1 ms: rising through it,
    /// staying above, falling, rising to touch it at a knot, held above after the last sample.
    #[test]
    fn intervals_above_a_level_are_where_the_level_is_above_it() {
        let h = Hydrograph::from_samples(
            &[0.5, 1.0, 2.0, 3.0, 4.0, 5.0],
            &[0.1, 0.3, 0.3, 0.2, 0.25, 0.4],
            Interpolation::Linear,
        );
        let z = 0.25;
        let got = h.intervals_above(z);
        assert_eq!(got.len(), 2, "{got:?}");
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(got[0].0, 0.875) && close(got[0].1, 2.5), "{got:?}");
        // Touching 0.25 at t = 4 is not above it: the second interval starts there.
        assert!(close(got[1].0, 4.0) && got[1].1.is_infinite(), "{got:?}");
        for k in 0..60_000 {
            let t = k as f64 * 1e-4;
            let inside = got.iter().any(|&(a, b)| a <= t && t < b);
            let above = h.speed(t) > z;
            let near = got.iter().any(|&(a, b)| close(t, a) || close(t, b));
            assert!(
                inside == above || near,
                "t = {t}: {} against {got:?}",
                h.speed(t)
            );
        }
        assert!(h.intervals_above(0.5).is_empty());
        assert_eq!(h.intervals_above(0.0), vec![(0.0, f64::INFINITY)]);
    }

    #[test]
    fn scaling_scales_speed_and_distance() {
        let h = Hydrograph::from_samples(&[0.0, 1.0], &[1.0, 3.0], Interpolation::Linear);
        let s = h.scaled(0.5);
        assert_eq!(s.speed(0.5), 1.0);
        assert_eq!(s.distance(2.0), 0.5 * h.distance(2.0));
    }
}
