alias real = f64;
// ^ The first line selects the precision (winslow_gpu::shader_source); the multigrid
// cycle runs only in double precision (the GPU crate refuses it without SHADER_F64), the
// single-precision variant exists for the validation test.
//
// The level work of winslow's multigrid V-cycle (crates/core/src/linalg/multigrid:
// kernels.rs names the operations, grid.rs, lines.rs, tensor.rs and dense.rs hold the CPU
// code these kernels mirror, term for term and in the same order, so that on an adapter
// without fused multiply-adds the results are the CPU's bits):
//
// - `residual`: r = b - A x on a level, one invocation per row;
// - `line_residual`, `line_smooth`: one colour of a coloured line Gauss-Seidel sweep in
//   two dispatches: the residual (b - A x)_L at every unknown of the colour's lines (one
//   invocation per unknown), then per line of the colour (one invocation each) the banded
//   Cholesky solve with the factor computed on the CPU at set-up and x_L += the
//   correction. Lines of one colour are farther apart than the operator couples, so no
//   invocation reads what another writes;
// - `transfer_rows`, `transfer_cols`: y = (a_1 (x) a_0) x in two 1D passes, t = X a_0^T
//   then Y = a_1 t (prolongation P = P_1 (x) P_0 and restriction P^T alike); the second
//   pass writes y, or adds it to its output (x += P x_c), and may zero a vector of its
//   size (x_{l+1} = 0 after the restriction);
// - `coarse_solve`: the dense Cholesky solve of the coarsest level, one invocation;
// - `system_product`: y = A x for the free-free Galerkin system of `s_comp` components
//   held as its stencil storage in single precision (the Newton Jacobian of eq. 12 that
//   GMRES multiplies with; crates/core/src/discrete/stencil.rs,
//   `Discretization::stencil_product`), one invocation per row, the row's terms added
//   as `Csr::mul_vec` adds them.
//
// Buffers: `vecs` holds every level's b, x, r and the transfer scratch t (read-write);
// `reals` the line factors, the 1D transfer factors, CSR level values and the coarsest
// factor; `idx` their row pointers, column indices and the lines' first unknowns;
// `stencil0` .. `stencil3` the levels' stencil values in single precision (the CPU's
// storage), each product widened and summed in `real`: one array split into chunks of
// 2^st_shift entries, one binding each, so that no binding exceeds the adapter's
// storage-binding limit (lavapipe: 128 MiB); `st_at` reads entry g of the whole.

struct Params {
    // invocations of this dispatch
    count: u32,
    // level operator: 0 stencil, 1 CSR
    op_kind: u32,
    nx: u32,
    ny: u32,
    bx: u32,
    by: u32,
    // offset into `stencil` (stencil level); into `idx` of row_ptr and col_idx and into
    // `reals` of the values (CSR level)
    st_off: u32,
    csr_ptr: u32,
    csr_col: u32,
    csr_val: u32,
    // offsets into `vecs` of the level's b, x, r
    b_off: u32,
    x_off: u32,
    r_off: u32,
    // lines: offset into `idx` of the first unknowns, stride, length, bandwidth,
    // offset into `reals` of the factors, first line and line step (colour, colours)
    l_starts: u32,
    l_stride: u32,
    l_len: u32,
    l_bw: u32,
    l_fac: u32,
    l_first: u32,
    l_step: u32,
    // transfer pass: the 1D factor (CSR offsets), m0 (rows of a_0), n0 (columns of
    // a_0), input, output and scratch offsets into `vecs`, whether the second pass
    // adds, and a vector to zero (or NONE)
    a_ptr: u32,
    a_col: u32,
    a_val: u32,
    m0: u32,
    n0: u32,
    in_off: u32,
    out_off: u32,
    t_off: u32,
    accumulate: u32,
    zero_off: u32,
    // coarsest level: size and offset into `reals` of its factor; the rows [c_lo, c_hi)
    // of this dispatch and its phase (0: forward, copying b to x first when c_lo = 0;
    // 1: backward)
    cn: u32,
    c_fac: u32,
    c_lo: u32,
    c_hi: u32,
    c_phase: u32,
    c_pad: u32,
    // stencil chunks: entry g lies in chunk g >> st_shift at g & st_mask
    st_shift: u32,
    st_mask: u32,
    // system product: offsets into `idx` of the free functions (their global indices)
    // and of the free index of every function (NONE: fixed), free functions m, components
    s_free: u32,
    s_free_of: u32,
    s_m: u32,
    s_comp: u32,
    s_pad0: u32,
    s_pad1: u32,
}

const WG: u32 = 64u;
const NONE: u32 = 0xffffffffu;

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> reals: array<real>;
@group(0) @binding(2) var<storage, read> idx: array<u32>;
@group(0) @binding(3) var<storage, read> stencil0: array<f32>;
@group(0) @binding(4) var<storage, read_write> vecs: array<real>;
@group(0) @binding(5) var<storage, read> stencil1: array<f32>;
@group(0) @binding(6) var<storage, read> stencil2: array<f32>;
@group(0) @binding(7) var<storage, read> stencil3: array<f32>;

fn linear_id(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WG;
}

// Entry g of the stencil values (see the buffers above).
fn st_at(g: u32) -> f32 {
    let j = g & P.st_mask;
    switch g >> P.st_shift {
        case 0u: {
            return stencil0[j];
        }
        case 1u: {
            return stencil1[j];
        }
        case 2u: {
            return stencil2[j];
        }
        default: {
            return stencil3[j];
        }
    }
}

// (A x)_i on a stencil level (GridOperator::row_product): per stencil row dy the
// products with the unknowns inside the grid summed in dx order, the rows' sums added.
fn stencil_row(i: u32) -> real {
    let wx = 2u * P.bx + 1u;
    let wy = 2u * P.by + 1u;
    let ix = i % P.nx;
    let iy = i / P.nx;
    let x0 = ix - min(ix, P.bx);
    let x1 = min(ix + P.bx + 1u, P.nx);
    let base = P.st_off + i * wx * wy;
    var sum = real(0.0);
    let y0 = iy - min(iy, P.by);
    let y1 = min(iy + P.by + 1u, P.ny);
    for (var jy = y0; jy < y1; jy++) {
        let row = base + (jy + P.by - iy) * wx + (x0 + P.bx - ix);
        let xs = P.x_off + jy * P.nx + x0;
        var s = -real(0.0);
        for (var k = 0u; k < x1 - x0; k++) {
            s += real(st_at(row + k)) * vecs[xs + k];
        }
        sum += s;
    }
    return sum;
}

// (A x)_i on a CSR level (Csr::row_dot): four partial sums, then the remainder.
fn csr_row(i: u32) -> real {
    let start = idx[P.csr_ptr + i];
    let len = idx[P.csr_ptr + i + 1u] - start;
    let full = len - len % 4u;
    var acc = array<real, 4>(real(0.0), real(0.0), real(0.0), real(0.0));
    for (var k = 0u; k < full; k += 4u) {
        for (var l = 0u; l < 4u; l++) {
            let e = start + k + l;
            acc[l] += reals[P.csr_val + e] * vecs[P.x_off + idx[P.csr_col + e]];
        }
    }
    var sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (var k = full; k < len; k++) {
        let e = start + k;
        sum += reals[P.csr_val + e] * vecs[P.x_off + idx[P.csr_col + e]];
    }
    return sum;
}

fn row_product(i: u32) -> real {
    if P.op_kind == 0u {
        return stencil_row(i);
    }
    return csr_row(i);
}

@compute @workgroup_size(64)
fn residual(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_id(gid, nwg);
    if i >= P.count {
        return;
    }
    vecs[P.r_off + i] = vecs[P.b_off + i] - row_product(i);
}

// Lines::correction, first half: the residual (b - A x)_L into r at the unknowns of the
// lines of one colour, one invocation per unknown (q = line's place in the colour times
// l_len plus the unknown's place on the line): a dispatch of its own before
// `line_smooth`, so that no invocation loops over a whole long line's stencil rows
// (lavapipe cut invocations of about 65 000 loop iterations short). The lines of a
// colour do not couple, so every residual is the one the line's own sweep would take.
@compute @workgroup_size(64)
fn line_residual(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let q = linear_id(gid, nwg);
    if q >= P.count {
        return;
    }
    let li = P.l_first + (q / P.l_len) * P.l_step;
    let i = idx[P.l_starts + li] + (q % P.l_len) * P.l_stride;
    vecs[P.r_off + i] = vecs[P.b_off + i] - row_product(i);
}

// Lines::correction, second half, and Lines::add for line l_first + q l_step: with the
// line's residual in r (`line_residual`), L y = r, L^T d = y in place, x_L += d.
@compute @workgroup_size(64)
fn line_smooth(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let q = linear_id(gid, nwg);
    if q >= P.count {
        return;
    }
    let li = P.l_first + q * P.l_step;
    let s0 = idx[P.l_starts + li];
    let len = P.l_len;
    let w = P.l_bw + 1u;
    let f = P.l_fac + li * len * w;
    let st = P.l_stride;
    let r = P.r_off + s0;
    for (var t = 0u; t < len; t++) {
        var s = vecs[r + t * st];
        for (var d = 1u; d < min(w, t + 1u); d++) {
            s -= reals[f + t * w + d] * vecs[r + (t - d) * st];
        }
        vecs[r + t * st] = s / reals[f + t * w];
    }
    for (var u = len; u > 0u; u--) {
        let t = u - 1u;
        var s = vecs[r + t * st];
        for (var d = 1u; d < min(w, len - t); d++) {
            s -= reals[f + (t + d) * w + d] * vecs[r + (t + d) * st];
        }
        vecs[r + t * st] = s / reals[f + t * w];
    }
    for (var t = 0u; t < len; t++) {
        vecs[P.x_off + s0 + t * st] += vecs[r + t * st];
    }
}

// First pass of kron_apply: t[row m0 + i] = sum over a_0's row i of v x[row n0 + col],
// for the count = n1 m0 entries.
@compute @workgroup_size(64)
fn transfer_rows(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_id(gid, nwg);
    if k >= P.count {
        return;
    }
    let row = k / P.m0;
    let i = k % P.m0;
    var s = -real(0.0);
    for (var e = idx[P.a_ptr + i]; e < idx[P.a_ptr + i + 1u]; e++) {
        s += reals[P.a_val + e] * vecs[P.in_off + row * P.n0 + idx[P.a_col + e]];
    }
    vecs[P.t_off + k] = s;
}

// Second pass: y[row m0 + i] = sum over a_1's row `row` of v t[col m0 + i], accumulated
// from zero, for the count = m1 m0 entries; written, or added to the output.
@compute @workgroup_size(64)
fn transfer_cols(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_id(gid, nwg);
    if k >= P.count {
        return;
    }
    let row = k / P.m0;
    let i = k % P.m0;
    var y = real(0.0);
    for (var e = idx[P.a_ptr + row]; e < idx[P.a_ptr + row + 1u]; e++) {
        y += reals[P.a_val + e] * vecs[P.t_off + idx[P.a_col + e] * P.m0 + i];
    }
    if P.accumulate == 1u {
        vecs[P.out_off + k] += y;
    } else {
        vecs[P.out_off + k] = y;
    }
    if P.zero_off != NONE {
        vecs[P.zero_off + k] = real(0.0);
    }
}

// DenseCholesky::solve_columns on the coarsest level, x = b, L y = x, L^T x = y, rows
// [c_lo, c_hi) of one phase per dispatch (one invocation; the host splits the solve into
// dispatches of a few thousand multiply-adds each: lavapipe cut a single invocation of
// about 65 000 loop iterations short).
@compute @workgroup_size(1)
fn coarse_solve() {
    let n = P.cn;
    let f = P.c_fac;
    let x = P.x_off;
    if P.c_phase == 0u {
        if P.c_lo == 0u {
            for (var i = 0u; i < n; i++) {
                vecs[x + i] = vecs[P.b_off + i];
            }
        }
        for (var i = P.c_lo; i < P.c_hi; i++) {
            var s = -real(0.0);
            for (var k = 0u; k < i; k++) {
                s += reals[f + i * n + k] * vecs[x + k];
            }
            vecs[x + i] = (vecs[x + i] - s) / reals[f + i * n + i];
        }
        return;
    }
    for (var u = P.c_hi; u > P.c_lo; u--) {
        let i = u - 1u;
        var s = vecs[x + i];
        for (var k = i + 1u; k < n; k++) {
            s -= reals[f + k * n + i] * vecs[x + k];
        }
        vecs[x + i] = s / reals[f + i * n + i];
    }
}

// Discretization::stencil_product for row z m + f (component z, free function f at
// global index k = i + nx j): the terms a x over the components d, then the free
// neighbours (dj, then di) of k, the entry of neighbour slot s at
// st_off + (k c^2 + z c + d) sw + s (sw = (2p + 1)(2q + 1), p = bx, q = by), each x at
// x_off + d m + its free index; summed as Csr::mul_vec sums a row: the first
// 4 floor(n / 4) terms into four partial sums (term t into sum t mod 4), combined as
// (s_0 + s_1) + (s_2 + s_3), then the remaining terms in order. Written at r_off + row.
@compute @workgroup_size(64)
fn system_product(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let row = linear_id(gid, nwg);
    if row >= P.count {
        return;
    }
    let m = P.s_m;
    let nc = P.s_comp;
    let z = row / m;
    let f = row % m;
    let k = idx[P.s_free + f];
    let i = k % P.nx;
    let j = k / P.nx;
    let wx = 2u * P.bx + 1u;
    let sw = wx * (2u * P.by + 1u);
    let i0 = i - min(i, P.bx);
    let i1 = min(i + P.bx + 1u, P.nx);
    let j0 = j - min(j, P.by);
    let j1 = min(j + P.by + 1u, P.ny);
    var cols = 0u;
    for (var dj = j0; dj < j1; dj++) {
        for (var di = i0; di < i1; di++) {
            if idx[P.s_free_of + dj * P.nx + di] != NONE {
                cols++;
            }
        }
    }
    let n = nc * cols;
    let full = n - n % 4u;
    var acc = array<real, 4>(real(0.0), real(0.0), real(0.0), real(0.0));
    var sum = real(0.0);
    var t = 0u;
    let base = P.st_off + (k * nc + z) * nc * sw;
    for (var d = 0u; d < nc; d++) {
        let st = base + d * sw;
        let xo = P.x_off + d * m;
        for (var dj = j0; dj < j1; dj++) {
            for (var di = i0; di < i1; di++) {
                let fc = idx[P.s_free_of + dj * P.nx + di];
                if fc == NONE {
                    continue;
                }
                let term = real(st_at(st + (dj + P.by - j) * wx + (di + P.bx - i))) * vecs[xo + fc];
                if t < full {
                    acc[t % 4u] += term;
                } else {
                    if t == full {
                        sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
                    }
                    sum += term;
                }
                t++;
            }
        }
    }
    if full == n {
        sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    }
    vecs[P.r_off + row] = sum;
}
