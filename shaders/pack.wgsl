alias real = f64;
// ^ The first line selects the precision (winslow_gpu::shader_source); the device
// Jacobian runs only in double precision (the multigrid kernels need SHADER_F64), the
// single-precision variant exists for the validation test.
//
// `pack`: the Newton Jacobian of eq. (12), assembled by `assembly.wgsl` into the stencil
// storage of a chunk of basis rows (`out`, in `real`), rounded to f32 into the split
// stencil bindings that `multigrid.wgsl`'s `system_product` reads (entry g of the whole
// in binding g >> st_shift at g & st_mask): dst[dst_off + i] = f32(src[src_off + i]).
// This is `Stencil32::pack` of crates/core/src/discrete/stencil.rs (Rust's `as f32`,
// round to nearest even) done where the values are, so that the Jacobian never crosses
// the bus. One invocation per entry.

struct Params {
    // entries of this dispatch
    count: u32,
    src_off: u32,
    dst_off: u32,
    st_shift: u32,
    st_mask: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

const WG: u32 = 64u;

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> src: array<real>;
@group(0) @binding(2) var<storage, read_write> dst0: array<f32>;
@group(0) @binding(3) var<storage, read_write> dst1: array<f32>;
@group(0) @binding(4) var<storage, read_write> dst2: array<f32>;
@group(0) @binding(5) var<storage, read_write> dst3: array<f32>;

@compute @workgroup_size(64)
fn pack(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if i >= P.count {
        return;
    }
    let v = f32(src[P.src_off + i]);
    let g = P.dst_off + i;
    let j = g & P.st_mask;
    switch g >> P.st_shift {
        case 0u: {
            dst0[j] = v;
        }
        case 1u: {
            dst1[j] = v;
        }
        case 2u: {
            dst2[j] = v;
        }
        default: {
            dst3[j] = v;
        }
    }
}
