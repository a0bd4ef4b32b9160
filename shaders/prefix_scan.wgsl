// Exclusive prefix sum of u32, in place, in blocks of 2·WG elements; each block's total goes
// to `block_sums`, which the host scans recursively and adds back with `scan_add`.
// Deterministic (integer sums). Lengths come from the exact buffer sizes.

@group(0) @binding(1) var<storage, read_write> data: array<u32>;
@group(0) @binding(2) var<storage, read_write> block_sums: array<u32>;

var<workgroup> partial: array<u32, WG>;

fn block_index(wid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return wid.x + wid.y * nwg.x;
}

@compute @workgroup_size(WG)
fn scan_blocks(
    @builtin(local_invocation_index) li: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
) {
    let block = block_index(wid, nwg);
    let n = arrayLength(&data);
    let i0 = block * 2u * WG + 2u * li;
    var a = 0u;
    var b = 0u;
    if (i0 < n) {
        a = data[i0];
    }
    if (i0 + 1u < n) {
        b = data[i0 + 1u];
    }
    partial[li] = a + b;
    workgroupBarrier();
    // Hillis–Steele inclusive scan of the pair sums.
    for (var offset = 1u; offset < WG; offset *= 2u) {
        var v = 0u;
        if (li >= offset) {
            v = partial[li - offset];
        }
        workgroupBarrier();
        partial[li] += v;
        workgroupBarrier();
    }
    let exclusive = partial[li] - (a + b);
    if (i0 < n) {
        data[i0] = exclusive;
    }
    if (i0 + 1u < n) {
        data[i0 + 1u] = exclusive + a;
    }
    if (li == WG - 1u && block < arrayLength(&block_sums)) {
        block_sums[block] = partial[li];
    }
}

@compute @workgroup_size(WG)
fn scan_add(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i < arrayLength(&data)) {
        data[i] += block_sums[i / (2u * WG)];
    }
}
