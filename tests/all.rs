//! The integration tests, one binary: a module per file of tests/ (and the case fuzzer and the
//! validation runs, a folder each), sharing `common`. One binary rather than one per file, so
//! that the harness keeps every core busy across files: with a binary per file, each file's
//! longest test ran alone at its end while the other core waited (in CI about a fifth of the
//! tests' time), and every binary linked the engine and wgpu again. `cargo test --test all
//! validation::` runs one module. `host_memory` stays a binary of its own: it counts its
//! process's allocations.

mod common;

mod analytic_free_fall;
mod analytic_poiseuille;
mod bindings;
mod bodies;
mod case_fuzz;
mod cli;
mod density_filter;
mod determinism;
mod elastic;
mod energy;
mod flood_maps;
mod instability;
mod kernels_vs_reference;
#[cfg(feature = "mpi")]
mod mpi;
mod restart;
mod shader_backends;
mod terrain;
mod validation;
mod wall_treatments;
mod walls;
