//! Every f64 twin (src/reference/) has the name of the WGSL function it mirrors: the table below
//! names each pair once, and a twin renamed on either side fails here (the Rust side at compile
//! time). A test module of its own, so neither layer imports the other.

use crate::gpu::shader::Shader;
use crate::sph::shader::{compose, ShaderConfig};
use crate::sph::{
    bodies, cell_list, density_filter, elastic, flood_maps, ghost, integrate, interaction,
    open_boundaries, probes,
};

/// (shader, WGSL function) of each twin; `$twin` must exist and end in the WGSL name.
macro_rules! twins {
    ($($shader:expr => [$($module:ident :: $name:ident),* $(,)?]),* $(,)?) => {{
        let mut pairs: Vec<(&Shader, &str)> = Vec::new();
        $($(
            let _ = crate::reference::$module::$name;
            pairs.push((&$shader, stringify!($name)));
        )*)*
        pairs
    }};
}

#[test]
fn every_twin_is_named_as_its_wgsl_function() {
    let pairs = twins! {
        interaction::SHADER => [
            interaction::continuity_rate,
            interaction::delta_sph_molteni2009,
            interaction::artificial_viscosity_monaghan1992,
            interaction::laminar_viscosity_morris1997,
            interaction::pressure_acceleration,
            interaction::specific_energy_rate,
            interaction::pair_rates,
            interaction::diffused_density,
            interaction::repulsion,
            interaction::contact,
            interaction::contact_velocity,
            interaction::boundary_rates,
            interaction::fluid_rates,
            interaction::mirror_rates,
            interaction::interaction,
            elastic::interface_rates,
            elastic::contact_weight,
        ],
        elastic::SHADER => [
            elastic::elastic_rates,
            elastic::jaumann_stress_rate,
            elastic::artificial_stress,
        ],
        ghost::SHADER => [
            ghost::ghost_interpolate,
            ghost::solid_interface_pressure,
            ghost::fluid_at,
            mls::mls_basis,
            mls::mls_add,
            mls::mls_solve,
        ],
        density_filter::SHADER => [
            density_filter::counts,
            density_filter::filter_density,
            mls::mls_solve,
        ],
        integrate::SHADER => [integrate::predict, integrate::correct, integrate::timestep],
        cell_list::SHADER => [cell_list::cell_key],
        bodies::SHADER => [bodies::body_move, bodies::body_force],
        open_boundaries::SHADER => [open_boundaries::inflow_at, open_boundaries::inlet_flow],
        probes::SHADER => [
            probes::probe_pressure,
            probes::probe_height,
            probes::probe_height_search,
            probes::gauge_fraction,
            probes::probe_front,
            probes::section_weight,
            probes::discharge_contribution,
        ],
        flood_maps::SHADER => [
            water_fraction::map_sums,
            water_fraction::water_fraction,
            flood_maps::map_cell_centre,
            flood_maps::map_point,
            flood_maps::map_surface_search,
            flood_maps::map_depth,
            flood_maps::map_velocity,
            flood_maps::map_accumulate,
            flood_maps::map_sample,
        ],
    };
    let mut missing = Vec::new();
    for (shader, name) in pairs {
        let source = compose(shader, ShaderConfig::default());
        let module = wgpu::naga::front::wgsl::parse_str(&source).expect("the shader parses");
        let has = module
            .functions
            .iter()
            .any(|(_, f)| f.name.as_deref() == Some(name))
            || module.entry_points.iter().any(|e| e.name == name);
        if !has {
            missing.push(format!("{}.wgsl has no `{name}`", shader.name));
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}
