// The particles of a 3D snapshot as shaded spheres: one camera-facing square per particle
// (instanced, four vertices as a strip), cut to its inscribed circle and lit as the sphere
// whose silhouette it is. Opaque, so the depth test alone orders them.

struct Camera {
    view_proj: mat4x4<f32>,
    // The camera's right and up directions in the world, w unused.
    right: vec4<f32>,
    up: vec4<f32>,
};

@group(0) @binding(0) var<uniform> camera: Camera;

struct Splat {
    @builtin(position) clip: vec4<f32>,
    // Position on the square, [-1, 1]²: the sphere's silhouette is the unit circle.
    @location(0) uv: vec2<f32>,
    @location(1) color: vec4<f32>,
};

@vertex
fn splat_vertex(
    @builtin(vertex_index) corner: u32,
    @location(0) centre: vec3<f32>,
    @location(1) color: vec4<f32>,
    @location(2) radius: f32,
) -> Splat {
    let uv = vec2<f32>(f32(corner & 1u) * 2.0 - 1.0, f32(corner >> 1u) * 2.0 - 1.0);
    let offset = (camera.right.xyz * uv.x + camera.up.xyz * uv.y) * radius;
    var out: Splat;
    out.clip = camera.view_proj * vec4<f32>(centre + offset, 1.0);
    out.uv = uv;
    out.color = color;
    return out;
}

// Light from the upper left, behind the viewer, in the camera's frame (x right, y up, z
// towards the viewer); an ambient share keeps the sides facing away readable.
const LIGHT: vec3<f32> = vec3<f32>(-0.4, 0.6, 0.7);
const AMBIENT: f32 = 0.4;

@fragment
fn splat_fragment(in: Splat) -> @location(0) vec4<f32> {
    let r2 = dot(in.uv, in.uv);
    if r2 > 1.0 {
        discard;
    }
    let normal = vec3<f32>(in.uv, sqrt(1.0 - r2));
    let diffuse = max(dot(normal, normalize(LIGHT)), 0.0);
    return vec4<f32>(in.color.rgb * (AMBIENT + (1.0 - AMBIENT) * diffuse), 1.0);
}
