//! WGSL composition, without physics: a pass's program is a prelude (the caller's constants
//! and library files) followed by its own file.
//!
//! The shaders are compiled into the binary (`include_str!`), so an installed `wgsph` needs no
//! shader files at run time.

/// Invocations per workgroup of every 1D kernel.
pub const WORKGROUP_SIZE: u32 = 128;

/// The WGSL program of one pass: its file, and the library files composed in front of it.
#[derive(Debug)]
pub struct Shader {
    /// The file's stem (`shaders/<name>.wgsl`), also the pass's Rust module.
    pub name: &'static str,
    pub source: &'static str,
    /// Library files (`shaders/lib/`) this pass uses, in order.
    pub libs: &'static [&'static str],
}

/// The full source of `shader` after `prelude` (constants and the libraries every pass reads).
pub fn compose(shader: &Shader, prelude: &str) -> String {
    format!(
        "// wgsph: {name}.wgsl composed\n{prelude}\n{libs}\n{source}",
        name = shader.name,
        libs = shader.libs.concat(),
        source = shader.source,
    )
}
