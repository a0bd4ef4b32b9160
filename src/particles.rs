//! The particles of a run as the host sees them: what the solver reads back from the GPU and
//! the output writes, draws and reads again. Its file forms are `crate::output`'s.

/// Particles read back from the GPU or a particle file, in id order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Particles {
    pub pos: Vec<[f64; 3]>,
    pub vel: Vec<[f32; 3]>,
    pub rho: Vec<f32>,
    pub pressure: Vec<f32>,
    /// 0 fluid, 1 wall, 15 excluded.
    pub kind: Vec<u32>,
    pub id: Vec<u32>,
    /// Specific internal energy [J/kg], when the energy equation is on.
    pub energy: Option<Vec<f32>>,
    /// Deviatoric stress τ (xx, yy, zz, xy, xz, yz) [Pa], when the case has solids (zeros for
    /// other particles).
    pub stress: Option<Vec<[f32; 6]>>,
}
