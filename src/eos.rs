//! Equations of state in f64, one place for the solver's read-back, the case builder and the
//! reference: Tait's for the fluid (docs/equations.md) and the linear one of the solids.
//! Neutral ground: it uses neither the solver nor the reference.

use crate::scenario::Physics;

/// Tait's equation of state p = B ((ρ/ρ0)^γ − 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tait {
    /// B = c0² ρ0 / γ [Pa].
    pub b: f64,
    pub rho0: f64,
    pub gamma: f64,
}

impl Tait {
    /// The fluid's equation of state of `ph`.
    pub fn of(ph: &Physics) -> Tait {
        Tait {
            b: ph.tait_b(),
            rho0: ph.rho0,
            gamma: ph.gamma,
        }
    }

    /// p(ρ) [Pa].
    pub fn pressure(&self, rho: f64) -> f64 {
        self.b * ((rho / self.rho0).powf(self.gamma) - 1.0)
    }
}

/// A solid's pressure p = c_s² (ρ − ρs), in the f32 the GPU state holds.
pub fn solid_pressure(c2: f32, rho: f32, rho0: f32) -> f32 {
    c2 * (rho - rho0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// p(ρ0) = 0, and a 1 % compression gives about c0² (ρ − ρ0).
    #[test]
    fn tait_is_zero_at_rest_and_stiff_as_c0_squared() {
        let eos = Tait {
            b: 1000.0 * 400.0 / 7.0,
            rho0: 1000.0,
            gamma: 7.0,
        };
        assert_eq!(eos.pressure(1000.0), 0.0);
        let p = eos.pressure(1001.0);
        assert!((p / (400.0 * 1.0) - 1.0).abs() < 0.01, "{p}");
    }
}
