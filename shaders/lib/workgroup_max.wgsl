// The largest values over a workgroup, returned to each of its invocations: a tree reduction in
// workgroup memory before one atomicMax per workgroup (max is order-independent, so the result
// is deterministic). Three maxima at once: the corrector reduces speed, acceleration and density
// variation together.
// It has barriers: call it in uniform control flow. No bindings: composed after common.wgsl by
// the passes that reduce a maximum (integrate, bodies, probes).

var<workgroup> wg_max: array<vec3<f32>, WG>;

// Component-wise maximum of `v` over the workgroup; `li` is the local invocation index.
fn workgroup_max(li: u32, v: vec3<f32>) -> vec3<f32> {
    wg_max[li] = v;
    workgroupBarrier();
    for (var s = WG / 2u; s > 0u; s >>= 1u) {
        if (li < s) {
            wg_max[li] = max(wg_max[li], wg_max[li + s]);
        }
        workgroupBarrier();
    }
    let m = wg_max[0];
    // Every invocation has read the result before a next call overwrites it.
    workgroupBarrier();
    return m;
}
