//! The run's uniform parameters (`Params`) and fixed case tables from its scenario and grid:
//! pure functions of the case, tested without a GPU.

use anyhow::{bail, Result};
use bytemuck::Zeroable;

use super::initial::{body_id_base, solid_range};
use super::shader::WgslEnum;
use crate::grid::Grid;
use crate::kernel::{kernel_norm, w};
use crate::layout::{MirrorPlane, Params, SolidMaterial, WallSensor, MAX_SOLID_MATERIALS};
use crate::scenario::{
    ContactGroup, ElasticMaterial, Physics, Scenario, SolidFormulation, Viscosity,
};

impl Params {
    /// The parameters every kernel reads, for `sc` on `grid`.
    pub fn from_scenario(sc: &Scenario, grid: &Grid) -> Result<Params> {
        let ph = &sc.physics;
        let n = sc.particles.len() as u32;
        let body_id_base = body_id_base(sc)?;
        let (alpha, nu) = match ph.viscosity {
            Viscosity::Artificial { alpha } => (alpha, 0.0),
            Viscosity::Laminar { nu } => (0.0, nu),
        };
        let mut params = Params {
            grid_cells: grid.cells,
            hash_mask: grid.slots - 1,
            contiguous_rows: grid.contiguous_rows() as u32,
            hash_stride: grid.stride,
            block_size: grid.block_size,
            cells_per_block: grid.cells_per_block,
            inv_cell_size: grid.cell_size.map(|c| (1.0 / c) as f32),
            periodic: (0..3)
                .filter(|&a| grid.periodic[a])
                .map(|a| 1u32 << a)
                .sum(),
            domain_size: grid.extent.map(|e| e as f32),
            n_particles: n,
            h: ph.h as f32,
            kernel_norm: kernel_norm(ph.kernel, ph.dim, ph.h) as f32,
            eta2: (0.01 * ph.h * ph.h) as f32,
            mass: ph.particle_mass as f32,
            rho0: ph.rho0 as f32,
            tait_b: ph.tait_b() as f32,
            gamma: ph.gamma as f32,
            c0: ph.c0 as f32,
            gravity: ph.gravity.map(|g| g as f32),
            alpha: alpha as f32,
            nu: nu as f32,
            delta_coef: (ph.delta_sph * ph.h * ph.c0) as f32,
            cfl: sc.time.cfl as f32,
            density_warn: sc.time.density_variation_warn as f32,
            density_stop: sc.time.density_variation_stop as f32,
            n_probes: sc.probes.len() as u32,
            n_mirror_planes: sc.walls.mirror_planes.len() as u32,
            ghost_mls: sc.walls.ghost_correction.code(),
            repulsive_d: sc.walls.repulsive_d as f32,
            repulsive_r0: sc.walls.repulsive_r0 as f32,
            repulsive_form: sc.walls.repulsive_form.code(),
            repulsive_k_over_beta: (sc.walls.repulsive_k / sc.walls.repulsive_beta) as f32,
            friction: sc.walls.friction as f32,
            friction_slip: sc.walls.friction_slip as f32,
            body_id_base,
            n_body_particles: n - body_id_base,
            ..Zeroable::zeroed()
        };
        params.set_friction_table(sc)?;
        params.set_solids(sc)?;
        if let (Some(first), Some(last)) = (sc.inlets.first(), sc.inlets.last()) {
            params.inlet_id_base = first.particles.start as u32;
            params.n_inlet_particles = (last.particles.end - first.particles.start) as u32;
            params.n_inlets = sc.inlets.len() as u32;
        }
        params.n_outlets = sc.outlets.len() as u32;
        Ok(params)
    }

    /// The friction coefficient of every pair of contact groups, when the case sets any by pair.
    fn set_friction_table(&mut self, sc: &Scenario) -> Result<()> {
        if sc.walls.friction_pairs.is_empty() {
            return Ok(());
        }
        let groups = friction_groups(sc)?;
        self.friction_groups = groups.len() as u32;
        self.friction_first_solid = 1 + sc.bodies.len() as u32;
        let table: &mut [f32] = bytemuck::cast_slice_mut(&mut self.friction_table);
        for (a, ga) in groups.iter().enumerate() {
            for (b, gb) in groups.iter().enumerate() {
                table[a * groups.len() + b] = sc.walls.friction_between(*ga, *gb) as f32;
            }
        }
        Ok(())
    }

    /// The solids' distinct materials and what the solid kernels read of them.
    fn set_solids(&mut self, sc: &Scenario) -> Result<()> {
        let Some(solids) = &sc.solids else {
            return Ok(());
        };
        let ph = &sc.physics;
        let (distinct, _) = solids.distinct_materials();
        if distinct.len() > MAX_SOLID_MATERIALS {
            bail!(
                "the solids have {} different materials, more than the {} a case may hold",
                distinct.len(),
                MAX_SOLID_MATERIALS
            );
        }
        for (slot, m) in self.solid_materials.iter_mut().zip(&distinct) {
            *slot = solid_material(m, ph);
        }
        self.solid_p_speed = solids.max_p_wave_speed() as f32;
        self.solid_inv_w_dx = (1.0 / w(ph.kernel, ph.dim, ph.h, ph.dx)) as f32;
        self.solid_id_base = solid_range(sc)?.start as u32;
        Ok(())
    }
}

/// GPU mirror planes in domain coordinates.
pub fn mirror_planes(sc: &Scenario, origin: [f64; 3]) -> Vec<MirrorPlane> {
    sc.walls
        .mirror_planes
        .iter()
        .map(|m| MirrorPlane {
            point: [0, 1, 2].map(|a| (m.point[a] - origin[a]) as f32),
            no_slip: m.no_slip as u32,
            normal: m.normal.map(|x| x as f32),
            pad: 0,
        })
        .collect()
}

/// The fixed walls' wall-pressure sensors (`WallParams::sensors`) in domain coordinates.
pub fn wall_sensors(sc: &Scenario, origin: [f64; 3]) -> Vec<WallSensor> {
    (sc.walls.sensors.iter())
        .zip(sc.walls.sensor_faces())
        .map(|(s, face_id)| WallSensor {
            point: [0, 1, 2].map(|a| (s.point[a] - origin[a]) as f32),
            radius: s.radius as f32,
            normal: s.normal.map(|x| x as f32),
            face: s.face as f32,
            over_lo: [0, 1, 2].map(|a| (s.over_lo[a] - origin[a]) as f32),
            face_id,
            over_hi: [0, 1, 2].map(|a| (s.over_hi[a] - origin[a]) as f32),
            pad: 0,
        })
        .collect()
}

/// The contact groups of a case in the GPU's order (`Params::friction_groups`): the walls, the
/// bodies, the solids.
fn friction_groups(sc: &Scenario) -> Result<Vec<ContactGroup>> {
    let solids = sc.solids.as_ref().map_or(0, |s| s.materials.len());
    let groups: Vec<ContactGroup> = std::iter::once(ContactGroup::Walls)
        .chain((0..sc.bodies.len()).map(ContactGroup::Body))
        .chain((0..solids).map(ContactGroup::Solid))
        .collect();
    if groups.len() > crate::layout::MAX_FRICTION_GROUPS {
        bail!(
            "friction by pair needs at most {} walls, bodies and solids together; the case has {}",
            crate::layout::MAX_FRICTION_GROUPS,
            groups.len()
        );
    }
    Ok(groups)
}

/// What the kernels use of an elastic material.
fn solid_material(m: &ElasticMaterial, ph: &Physics) -> SolidMaterial {
    let c_s = m.sound_speed();
    SolidMaterial {
        rho0: m.density as f32,
        c2: (c_s * c_s) as f32,
        mu: m.shear_modulus() as f32,
        mass: m.particle_mass(ph.dx, ph.dim) as f32,
        alpha: m.alpha as f32,
        eps: m.artificial_stress as f32,
        lambda: m.lame_lambda() as f32,
        total_lagrangian: (m.formulation == SolidFormulation::TotalLagrangian) as u32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(case: &str) -> (Scenario, Grid) {
        let sc = crate::case::load(std::path::Path::new(case), &[]).unwrap();
        let grid = Grid::of(&sc).unwrap();
        (sc, grid)
    }

    /// A fluid case's parameters follow its physics: the kernel's normalisation, Tait's B, and
    /// no body, solid or inlet ranges.
    #[test]
    fn a_dam_break_has_its_physics_and_no_body_or_solid_ranges() {
        let (sc, grid) = load("cases/dam_break_2d.toml");
        let p = Params::from_scenario(&sc, &grid).unwrap();
        let ph = &sc.physics;
        assert_eq!(p.n_particles as usize, sc.particles.len());
        assert_eq!(p.body_id_base, p.n_particles);
        assert_eq!(p.n_body_particles, 0);
        assert_eq!(p.n_inlets, 0);
        assert_eq!(p.solid_materials[0].rho0, 0.0);
        assert_eq!(p.h, ph.h as f32);
        assert_eq!(p.tait_b, ph.tait_b() as f32);
        // Wendland C2 in 2D: α = 7 / (4π h²).
        assert_eq!(ph.kernel, crate::scenario::KernelKind::WendlandC2);
        let norm = 7.0 / (4.0 * std::f64::consts::PI * ph.h * ph.h);
        assert!((p.kernel_norm as f64 / norm - 1.0).abs() < 1e-6);
        assert_eq!(p.hash_mask + 1, grid.slots);
    }

    /// A floating box's particles come last: the body range starts at its first particle.
    #[test]
    fn a_floating_box_has_its_body_range_at_the_end() {
        let (sc, grid) = load("cases/floating_box_2d.toml");
        let p = Params::from_scenario(&sc, &grid).unwrap();
        let start = sc.bodies[0].particles.start as u32;
        assert_eq!(p.body_id_base, start);
        assert_eq!(p.n_body_particles, p.n_particles - start);
    }

    /// A gate of one material fills one material slot, with the solids' first id.
    #[test]
    fn an_elastic_gate_has_one_material_and_its_solid_range() {
        let (sc, grid) = load("cases/elastic_gate_2d.toml");
        let p = Params::from_scenario(&sc, &grid).unwrap();
        let first = sc.particles.iter().position(|q| q.kind.is_solid()).unwrap();
        assert_eq!(p.solid_id_base as usize, first);
        assert!(p.solid_materials[0].rho0 > 0.0 && p.solid_materials[0].c2 > 0.0);
        assert_eq!(p.solid_materials[1].rho0, 0.0);
        assert!(p.solid_p_speed > 0.0 && p.solid_inv_w_dx > 0.0);
    }

    /// Mirror planes and wall sensors are given from the domain's min corner.
    #[test]
    fn tables_are_in_domain_coordinates() {
        let (sc, grid) = load("cases/hydrostatic_2d.toml");
        let o = [1.0, -2.0, 0.5];
        for (s, g) in sc.walls.sensors.iter().zip(wall_sensors(&sc, o)) {
            assert_eq!(g.point[0], (s.point[0] - 1.0) as f32);
            assert_eq!(g.point[1], (s.point[1] + 2.0) as f32);
        }
        for (m, g) in sc
            .walls
            .mirror_planes
            .iter()
            .zip(mirror_planes(&sc, grid.origin))
        {
            assert_eq!(g.point[0], (m.point[0] - grid.origin[0]) as f32);
        }
    }
}
