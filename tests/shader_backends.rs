//! Every composed shader variant the shipped cases use (and the all-kinds variant, also as a CPU
//! adapter spreads its neighbour sums) translates with naga's own backends to SPIR-V (Vulkan),
//! MSL (Metal), HLSL (DX12) and GLSL (GL compute), so a shader change that would break another
//! vendor's backend is caught without its device.

use naga::back::{glsl, hlsl, msl, spv};
use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};
use wgsph::gpu::shader::Shader;
use wgsph::sph::passes::SHADERS;
use wgsph::sph::shader::{compose, ShaderConfig, SPREAD_CHUNKS};

fn cases() -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir("cases")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    files
}

/// The distinct shader configurations of the shipped cases, after the all-kinds one, each with
/// the first case that uses it.
fn variants() -> Vec<(String, ShaderConfig)> {
    let mut configs = vec![
        ("all kinds".to_string(), ShaderConfig::default()),
        (
            "all kinds, spread (a CPU adapter's)".to_string(),
            ShaderConfig {
                spread_chunks: SPREAD_CHUNKS,
                ..ShaderConfig::default()
            },
        ),
    ];
    for file in cases() {
        let sc = wgsph::case::load(&file, &[]).unwrap();
        let grid = wgsph::grid::Grid::of(&sc).unwrap();
        let cfg = ShaderConfig::of(&sc, &grid).unwrap();
        if !configs.iter().any(|(_, c)| *c == cfg) {
            configs.push((file.display().to_string(), cfg));
        }
    }
    configs
}

/// `shader` composed for `cfg`, parsed and validated.
fn validated(shader: &Shader, cfg: ShaderConfig) -> (naga::Module, ModuleInfo) {
    let module = naga::front::wgsl::parse_str(&compose(shader, cfg)).unwrap();
    let info = Validator::new(ValidationFlags::all(), Capabilities::empty())
        .validate(&module)
        .unwrap();
    (module, info)
}

/// Every backend's translation of `module`, or the first error with the backend's name.
fn translate(module: &naga::Module, info: &ModuleInfo) -> Result<(), String> {
    spv::write_vec(module, info, &spv::Options::default(), None)
        .map_err(|e| format!("SPIR-V: {e}"))?;
    msl::write_string(
        module,
        info,
        &msl::Options::default(),
        &msl::PipelineOptions::default(),
    )
    .map_err(|e| format!("MSL: {e}"))?;
    let hlsl_options = hlsl::Options::default();
    let hlsl_pipeline = hlsl::PipelineOptions::default();
    let mut out = String::new();
    hlsl::Writer::new(&mut out, &hlsl_options, &hlsl_pipeline)
        .write(module, info, None)
        .map_err(|e| format!("HLSL: {e}"))?;
    let glsl_options = glsl::Options {
        version: glsl::Version::new_gles(310),
        ..Default::default()
    };
    for entry in &module.entry_points {
        let pipeline = glsl::PipelineOptions {
            shader_stage: naga::ShaderStage::Compute,
            entry_point: entry.name.clone(),
            multiview: None,
        };
        let mut out = String::new();
        glsl::Writer::new(
            &mut out,
            module,
            info,
            &glsl_options,
            &pipeline,
            naga::proc::BoundsCheckPolicies::default(),
        )
        .and_then(|mut w| w.write())
        .map_err(|e| format!("GLSL ({}): {e}", entry.name))?;
    }
    Ok(())
}

#[test]
fn every_shipped_variant_translates_to_every_backend() {
    let configs = variants();
    assert!(configs.len() > 5, "{} variants", configs.len());
    let mut failures = Vec::new();
    for (what, cfg) in &configs {
        for shader in SHADERS {
            let (module, info) = validated(shader, *cfg);
            if let Err(e) = translate(&module, &info) {
                failures.push(format!("{}.wgsl for {what}: {e}", shader.name));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// WebGPU's default `max_storage_buffers_per_shader_stage`.
const WEBGPU_STORAGE_BUFFERS: usize = 8;

/// Every entry point of every variant the shipped cases use (and the all-kinds one) binds at
/// most WebGPU's default of 8 storage buffers, so the engine runs on every adapter wgpu
/// supports, browsers included.
#[test]
fn every_entry_point_binds_at_most_8_storage_buffers() {
    let configs = variants();
    let mut over = Vec::new();
    for (what, cfg) in &configs {
        for shader in SHADERS {
            let (module, info) = validated(shader, *cfg);
            for (k, entry) in module.entry_points.iter().enumerate() {
                let uses = info.get_entry_point(k);
                let storage: Vec<&str> = (module.global_variables.iter())
                    .filter(|(h, g)| {
                        !uses[*h].is_empty()
                            && matches!(g.space, naga::AddressSpace::Storage { .. })
                    })
                    .filter_map(|(_, g)| g.name.as_deref())
                    .collect();
                if storage.len() > WEBGPU_STORAGE_BUFFERS {
                    over.push(format!(
                        "{}::{} for {what}: {} ({})",
                        shader.name,
                        entry.name,
                        storage.len(),
                        storage.join(", ")
                    ));
                }
            }
        }
    }
    over.sort();
    over.dedup();
    assert!(over.is_empty(), "{}", over.join("\n"));
}
