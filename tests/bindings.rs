//! Bindings by name: a pass asks for each WGSL global by its name and gets the buffer of the
//! right parity, or an error; it cannot bind a wrong buffer or rebind a shared one.

use bytemuck::Zeroable;
use wgsph::gpu::kernel::Resolve;
use wgsph::layout::Params;
use wgsph::sph::buffers::{CaseTables, InitialParticles, ParticleBuffers, TableSizes};

fn buffers() -> ParticleBuffers {
    let ctx = crate::common::gpu();
    ParticleBuffers::new(
        &ctx.device,
        &Params::zeroed(),
        8,
        &InitialParticles {
            capacity: 4,
            wide_ids: false,
            body_particles: &[],
            body_motions: &[],
            solid: &[],
        },
        &CaseTables {
            probes: &[],
            mirror_planes: &[],
            wall_sensors: &[],
        },
        TableSizes {
            bodies: 1,
            mirror_planes: 1,
            wall_sensors: 1,
        },
        true,
    )
}

fn same(a: &wgpu::Buffer, b: &wgpu::Buffer) -> bool {
    std::ptr::eq(a, b)
}

#[test]
fn particle_arrays_resolve_to_their_parity_and_the_sort_writes_the_other() {
    let b = buffers();
    for p in 0..2 {
        let q = 1 - p;
        let at = b.at(p);
        for (name, want) in [
            ("pos", &b.pos[p]),
            ("pos_in", &b.pos[p]),
            ("pos_out", &b.pos[q]),
            ("velrho", &b.velrho[p]),
            ("velrho_out", &b.velrho[q]),
            ("code_in", &b.code[p]),
            ("code_out", &b.code[q]),
            ("energy", &b.energy[p]),
            ("energy_out", &b.energy[q]),
            ("rate", &b.rate),
            ("rate_old", &b.rate_sorted),
            ("rate_out", &b.rate_sorted),
            ("counts", &b.cell_start),
            ("tables", &b.tables),
        ] {
            assert!(
                same(at.resolve(name).unwrap(), want),
                "{name} at parity {p}"
            );
        }
    }
}

#[test]
fn an_unknown_name_or_a_particle_array_without_parity_is_an_error() {
    let b = buffers();
    let err = b.at(0).resolve("velocity").unwrap_err().to_string();
    assert!(err.contains("no buffer"), "{err}");
    assert!(b.unparitied().resolve("pos").is_err());
    assert!(b.unparitied().resolve("state").is_ok());
    let own = wgsph::gpu::buffers::storage(&crate::common::gpu().device, "own", 16);
    let with = b.at(1).with("terms", &own);
    assert!(same(with.resolve("terms").unwrap(), &own));
}

#[test]
#[should_panic(expected = "shared buffer's name")]
fn a_pass_cannot_rebind_a_shared_buffer() {
    let b = buffers();
    let own = wgsph::gpu::buffers::storage(&crate::common::gpu().device, "own", 16);
    let _ = b.at(0).with("velrho", &own);
}
