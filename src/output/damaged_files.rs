//! Every reader of a run's files on damaged copies of them (issue 64: a VTU whose array length
//! word was eight 0xff bytes panicked `surface`, `plot --snapshots` and a resume): cut short at
//! every length, a word of 0xff or of zeros and a flipped byte at every offset. None may panic;
//! the undamaged file reads back. The checkpoint's reader is tried the same way in
//! `checkpoint.rs`, the probe tables' in `plot`.

use super::particle_file::ParticleFile;
use super::test_util::survives_damage;
use super::vtu::{pvtu_pieces, reader::Vtu, write_pvtu, write_triangles_vtu, write_vtu};
use super::{RunSummary, SurfaceMesh};
use crate::particles::Particles;

fn particles(n: u32) -> Particles {
    Particles {
        pos: (0..n).map(|i| [i as f64 * 0.1, 0.5, -0.25]).collect(),
        vel: (0..n).map(|i| [i as f32, 0.5, -0.25]).collect(),
        rho: (0..n).map(|i| 1000.0 + i as f32).collect(),
        pressure: (0..n).map(|i| i as f32 * 9.81).collect(),
        kind: (0..n).map(|i| i % 2).collect(),
        id: (0..n).collect(),
        energy: Some((0..n).map(|i| i as f32).collect()),
        stress: None,
    }
}

#[test]
fn a_damaged_particle_file_is_an_error_not_a_panic() {
    let p = particles(6);
    let extra = p.extra_arrays();
    let extra: Vec<(&str, &[f32])> = extra.iter().map(|(n, v)| (*n, v.as_slice())).collect();
    let mut bytes = Vec::new();
    write_vtu(&mut bytes, &p.snapshot(0.25, &extra)).unwrap();
    let read = |b: &[u8]| ParticleFile::parse(b);
    assert_eq!(read(&bytes).unwrap().particles.id, p.id);
    let ok = survives_damage("a particle file", &bytes, 1, read);
    // A flipped byte inside a value reads as another value; most damage is an error.
    assert!(
        ok < bytes.len(),
        "{ok} damaged copies read without an error"
    );
}

#[test]
fn a_damaged_surface_or_pvtu_is_an_error_not_a_panic() {
    let mesh = SurfaceMesh {
        time_s: 0.5,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        triangles: vec![[0, 1, 2], [0, 1, 3], [1, 2, 3]],
    };
    let mut bytes = Vec::new();
    write_triangles_vtu(&mut bytes, &mesh).unwrap();
    assert_eq!(SurfaceMesh::parse(&bytes).unwrap(), mesh);
    survives_damage("a surface", &bytes, 1, SurfaceMesh::parse);
    survives_damage("a VTU's arrays", &bytes, 1, |b| {
        Vtu::parse(b).and_then(|v| v.f64s("Points", 3))
    });
    let mut pvtu = Vec::new();
    let pieces = [
        "particles_000001_p0000.vtu".to_string(),
        "particles_000001_p0001.vtu".into(),
    ];
    write_pvtu(&mut pvtu, &["energy"], &pieces).unwrap();
    survives_damage("a .pvtu", &pvtu, 1, |b| {
        pvtu_pieces(&String::from_utf8_lossy(b))
    });
    for odd in ["particles_000001.pvtu", "../x.vtu", "/etc/passwd"] {
        let text = String::from_utf8(pvtu.clone())
            .unwrap()
            .replace(&pieces[0], odd);
        assert!(pvtu_pieces(&text).is_err(), "{odd}");
    }
}

#[test]
fn a_damaged_run_summary_is_an_error_not_a_panic() {
    let json = r#"{"case": "c", "adapter": "a", "backend": "Vulkan", "dimension": 2,
        "particles_fluid": 10, "particles_wall": 5, "particles_solid": 0, "particles_inlet": 0,
        "particles_excluded": 0, "particles_drained": 0, "steps": 3, "simulated_time_s": 0.5,
        "wall_time_s": 1.0, "particle_steps_per_s": 45.0, "gpu_bytes_per_particle": 100.0,
        "outputs": 2, "status": "completed", "warnings": [], "max_density_variation": 0.01}"#;
    let read = |b: &[u8]| serde_json::from_slice::<RunSummary>(b);
    read(json.as_bytes()).unwrap();
    survives_damage("run.json", json.as_bytes(), 1, read);
}
