//! Free-surface meshes of a 3D run (`wgsph surface DIR`): the fluid particles of each particle
//! output reconstructed by splashsurf (marching cubes over the SPH density of the particles,
//! Löschner et al. 2023, `splashsurf_lib`) into DIR/surface/surface_NNNNNN.vtu and the series
//! DIR/surface.pvd, which ParaView opens beside particles.pvd.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use splashsurf_lib::nalgebra::Vector3;

use crate::output::{
    create_surface_dir, particle_files, write_surface, write_surface_series, ParticleFile,
    SurfaceMesh,
};
use crate::scenario::{Kind, Scenario};

/// What the reconstruction is made with, in metres (the threshold relative to ρ0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceParams {
    /// Half the side of the cube of fluid a particle stands for: splashsurf's particle volume
    /// is (2r)³.
    pub particle_radius: f64,
    /// Where splashsurf's cubic-spline kernel reaches zero.
    pub support_radius: f64,
    /// Edge of the marching-cubes grid.
    pub cube_size: f64,
    /// The surface is where the reconstructed density is this share of ρ0.
    pub iso_threshold: f64,
    pub rho0: f64,
}

impl SurfaceParams {
    /// The run's own: particle radius dx/2 (volume dx³, the run's particle volume), the
    /// run's kernel support 2h, cubes of dx/2, and splashsurf's recommended threshold 0.6.
    pub fn for_scenario(sc: &Scenario) -> Self {
        let (dx, h) = (sc.physics.dx, sc.physics.h);
        Self {
            particle_radius: 0.5 * dx,
            support_radius: 2.0 * h,
            cube_size: 0.5 * dx,
            iso_threshold: 0.6,
            rho0: sc.physics.rho0,
        }
    }

    /// An error naming the first parameter that is not a positive finite number.
    fn check(&self) -> Result<()> {
        for (name, v) in [
            ("--particle-radius", self.particle_radius),
            ("--support-radius", self.support_radius),
            ("--cube-size", self.cube_size),
            ("--iso-threshold", self.iso_threshold),
        ] {
            if !(v.is_finite() && v > 0.0) {
                bail!("{name} = {v}: must be a positive number");
            }
        }
        Ok(())
    }
}

/// The surface around `positions` (fluid particles) at `time_s`; no triangles without fluid.
pub fn reconstruct(positions: &[[f64; 3]], time_s: f64, p: &SurfaceParams) -> Result<SurfaceMesh> {
    p.check()?;
    if positions.is_empty() {
        return Ok(SurfaceMesh {
            time_s,
            ..SurfaceMesh::default()
        });
    }
    // In f32, splashsurf's vectorised path, about the first particle: a city-sized run keeps
    // millimetres.
    let o = positions[0];
    let points: Vec<Vector3<f32>> = (positions.iter())
        .map(|x| {
            Vector3::new(
                (x[0] - o[0]) as f32,
                (x[1] - o[1]) as f32,
                (x[2] - o[2]) as f32,
            )
        })
        .collect();
    let mut params = splashsurf_lib::Parameters::new(
        p.particle_radius as f32,
        p.support_radius as f32,
        p.cube_size as f32,
    );
    params.rest_density = p.rho0 as f32;
    params.iso_surface_threshold = p.iso_threshold as f32;
    let surface = splashsurf_lib::reconstruct_surface::<i64, f32>(&points, &params)
        .map_err(|e| anyhow::anyhow!("surface reconstruction: {e:#}"))?;
    let vertices = (surface.mesh.vertices.iter())
        .map(|v| [0, 1, 2].map(|a| o[a] + v[a] as f64))
        .collect();
    Ok(SurfaceMesh {
        time_s,
        vertices,
        triangles: surface.mesh.triangles,
    })
}

/// Reconstructs the surface of every particle file of the 3D run of `sc` in `dir` with `p`,
/// writing each as it is made; `progress(done, total)` after each. Returns the series file.
pub fn surfaces_of_run(
    dir: &Path,
    sc: &Scenario,
    p: &SurfaceParams,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<PathBuf> {
    if sc.physics.dim != 3 {
        bail!(
            "{} is a 2D run: surface meshes are made for 3D runs (2D outputs are drawn by \
             `wgsph plot DIR --snapshots`)",
            dir.display()
        );
    }
    p.check()?;
    let files = particle_files(dir)?;
    if files.is_empty() {
        bail!(
            "no particle files (particles/particles_NNNNNN.vtu) in {}",
            dir.display()
        );
    }
    create_surface_dir(dir)?;
    let mut series = Vec::with_capacity(files.len());
    for (done, (index, file)) in files.iter().enumerate() {
        let read = ParticleFile::read(file)?;
        let fluid: Vec<[f64; 3]> = (read.particles.kind.iter().zip(&read.particles.pos))
            .filter(|(&k, _)| Kind::from_code(k) == Some(Kind::Fluid))
            .map(|(_, x)| *x)
            .collect();
        let mesh = reconstruct(&fluid, read.time_s, p)
            .with_context(|| format!("the surface of {}", file.display()))?;
        series.push(write_surface(dir, *index, &mesh)?);
        progress(done + 1, files.len());
    }
    Ok(write_surface_series(dir, &series)?)
}

#[cfg(test)]
mod tests;
