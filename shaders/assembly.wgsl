alias real = f64;
// ^ The first line selects the precision: the f32 variant of this shader replaces it by
// `alias real = f32;` (winslow_gpu::shader_source). Everything below is precision-generic.
//
// Galerkin quadrature of winslow's assembly (crates/core/src/assembly.rs) on a
// tensor-product B-spline basis, in two passes without atomics:
//
// 1. `geometry`: one invocation per (element, quadrature point) evaluates the map's
//    derivatives x_xi, x_eta, x_xixi, x_xieta, x_etaeta from the control points and the
//    tabulated univariate basis values (uploaded once per basis) and stores them.
// 2. `egg_residual`, `egg_stencil`, `elasticity_stencil`, `mass_stencil`: one invocation
//    per output entry (a basis function for the residual, a (function, stencil slot)
//    pair for the matrices) sums the integrand over the elements of the common support,
//    in the same order as the CPU's coloured element loop (colour of the element row,
//    then elements along xi; quadrature points eta-outer inside each element), and
//    writes the entry of the stencil storage directly. Deterministic, race free.
// 3. The solver's EGG Jacobian instead runs `egg_element` (one workgroup per element:
//    the terms of each quadrature point computed once in workgroup memory, the element
//    matrix accumulated row-wise) and `egg_gather` (per stencil entry, the element
//    matrices of the common support summed in the CPU's order); `egg_stencil` remains
//    as the per-entry alternative.
//
// EGG (paper eq. 4, 8): with g11 = x_xi.x_xi, g12 = x_xi.x_eta, g22 = x_eta.x_eta,
// L(z) = g22 z_xixi - 2 g12 z_xieta + g11 z_etaeta, F^z_a = int w_a L(z) (divided by
// s = g11 + g22 for the scaled operator), and the exact derivative with respect to
// component d of control point b (see Discretization::egg).

struct Params {
    // degrees, Gauss points per element and direction
    p: u32,
    q: u32,
    nq_u: u32,
    nq_v: u32,
    // basis functions and elements per direction
    nx: u32,
    ny: u32,
    nex: u32,
    ney: u32,
    // offsets into `tab` of the xi and eta tables; per (element, point) a record
    // [w, N(0..=p), N'(0..=p), N''(0..=p)]
    tab_x: u32,
    tab_y: u32,
    // offsets into `idx`: first function per element (x, y) and per function the
    // inclusive range of elements containing it in their support (x, y), as pairs
    first_x: u32,
    first_y: u32,
    range_x: u32,
    range_y: u32,
    // this chunk: element rows [ey0, ey1) in the `geo` buffer, function rows [j0, j1)
    ey0: u32,
    ey1: u32,
    j0: u32,
    j1: u32,
    // 0: plain operator, 1: scaled
    op: u32,
    // offset into `tab` of the Lame constants (lambda, mu)
    lame: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> tab: array<real>;
@group(0) @binding(2) var<storage, read> idx: array<u32>;
@group(0) @binding(3) var<storage, read> cps: array<real>;
@group(0) @binding(4) var<storage, read_write> geo: array<real>;
@group(0) @binding(5) var<storage, read_write> out: array<real>;
@group(0) @binding(6) var<storage, read_write> res: array<real>;
// element matrices of the chunk's elements (egg_element), 4 (p+1)^2 (q+1)^2 per element
@group(0) @binding(7) var<storage, read_write> elm: array<real>;

const WG: u32 = 64u;
// values stored per quadrature point by `geometry`: x_xi, x_eta, x_xixi, x_xieta,
// x_etaeta (2 each), g11, g12, g22, L(x), L(y), the scale (1 or 1 / (g11 + g22)) and the
// scaling denominator (0 or g11 + g22)
const GEO: u32 = 17u;

fn linear_id(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WG;
}

fn rec_x() -> u32 {
    return 1u + 3u * (P.p + 1u);
}

fn rec_y() -> u32 {
    return 1u + 3u * (P.q + 1u);
}

// k-th derivative of local function a of element e at point ku (xi direction)
fn nx_(e: u32, ku: u32, k: u32, a: u32) -> real {
    return tab[P.tab_x + (e * P.nq_u + ku) * rec_x() + 1u + k * (P.p + 1u) + a];
}

fn ny_(e: u32, kv: u32, k: u32, a: u32) -> real {
    return tab[P.tab_y + (e * P.nq_v + kv) * rec_y() + 1u + k * (P.q + 1u) + a];
}

fn wx_(e: u32, ku: u32) -> real {
    return tab[P.tab_x + (e * P.nq_u + ku) * rec_x()];
}

fn wy_(e: u32, kv: u32) -> real {
    return tab[P.tab_y + (e * P.nq_v + kv) * rec_y()];
}

fn geo_base(ex: u32, ey: u32, ku: u32, kv: u32) -> u32 {
    return ((((ey - P.ey0) * P.nex + ex) * P.nq_v + kv) * P.nq_u + ku) * GEO;
}

// Pass 1: derivatives of the map at every quadrature point of the chunk's element rows.
@compute @workgroup_size(64)
fn geometry(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let id = linear_id(gid, nwg);
    let nqp = P.nq_u * P.nq_v;
    let total = (P.ey1 - P.ey0) * P.nex * nqp;
    if id >= total {
        return;
    }
    let e = id / nqp;
    let kq = id % nqp;
    let ku = kq % P.nq_u;
    let kv = kq / P.nq_u;
    let ex = e % P.nex;
    let ey = P.ey0 + e / P.nex;
    let fx = idx[P.first_x + ex];
    let fy = idx[P.first_y + ey];
    var g: array<real, 17>;
    for (var t = 0u; t < GEO; t++) {
        g[t] = 0.0;
    }
    for (var jb = 0u; jb <= P.q; jb++) {
        let v0 = ny_(ey, kv, 0u, jb);
        let v1 = ny_(ey, kv, 1u, jb);
        let v2 = ny_(ey, kv, 2u, jb);
        for (var ib = 0u; ib <= P.p; ib++) {
            let u0 = nx_(ex, ku, 0u, ib);
            let u1 = nx_(ex, ku, 1u, ib);
            let u2 = nx_(ex, ku, 2u, ib);
            let b1 = u1 * v0;
            let b2 = u0 * v1;
            let b3 = u2 * v0;
            let b4 = u1 * v1;
            let b5 = u0 * v2;
            let c = 2u * ((fy + jb) * P.nx + fx + ib);
            for (var d = 0u; d < 2u; d++) {
                let cd = cps[c + d];
                g[d] += b1 * cd;
                g[2u + d] += b2 * cd;
                g[4u + d] += b3 * cd;
                g[6u + d] += b4 * cd;
                g[8u + d] += b5 * cd;
            }
        }
    }
    let g11 = g[0] * g[0] + g[1] * g[1];
    let g12 = g[0] * g[2] + g[1] * g[3];
    let g22 = g[2] * g[2] + g[3] * g[3];
    g[10] = g11;
    g[11] = g12;
    g[12] = g22;
    g[13] = g22 * g[4] - 2.0 * g12 * g[6] + g11 * g[8];
    g[14] = g22 * g[5] - 2.0 * g12 * g[7] + g11 * g[9];
    g[15] = 1.0;
    g[16] = 0.0;
    if P.op == 1u {
        g[16] = g11 + g22;
        g[15] = 1.0 / g[16];
    }
    let o = geo_base(ex, ey, ku, kv);
    for (var t = 0u; t < GEO; t++) {
        geo[o + t] = g[t];
    }
}

// Inclusive element range of function i in xi (x = 0) or eta (x = 1).
fn erange(dir: u32, i: u32) -> vec2<u32> {
    let off = select(P.range_x, P.range_y, dir == 1u);
    return vec2<u32>(idx[off + 2u * i], idx[off + 2u * i + 1u]);
}

// The element rows in the CPU's order: colour c = ey mod (q + 1) outer.
fn in_colour(ey: u32, c: u32) -> bool {
    return ey % (P.q + 1u) == c;
}

// Pass 2a: EGG residual, both components of one basis function of the chunk.
@compute @workgroup_size(64)
fn egg_residual(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let id = linear_id(gid, nwg);
    let rows = (P.j1 - P.j0) * P.nx;
    if id >= rows {
        return;
    }
    let k = P.j0 * P.nx + id;
    let i = k % P.nx;
    let j = k / P.nx;
    let rx = erange(0u, i);
    let ry = erange(1u, j);
    var acc0: real = 0.0;
    var acc1: real = 0.0;
    for (var c = 0u; c <= P.q; c++) {
        for (var ey = ry.x; ey <= ry.y; ey++) {
            if !in_colour(ey, c) {
                continue;
            }
            let ja = j - idx[P.first_y + ey];
            for (var ex = rx.x; ex <= rx.y; ex++) {
                let ia = i - idx[P.first_x + ex];
                var e0: real = 0.0;
                var e1: real = 0.0;
                for (var kv = 0u; kv < P.nq_v; kv++) {
                    let va = ny_(ey, kv, 0u, ja);
                    let wv = wy_(ey, kv);
                    for (var ku = 0u; ku < P.nq_u; ku++) {
                        let wq = wx_(ex, ku) * wv;
                        let o = geo_base(ex, ey, ku, kv);
                        let l0 = geo[o + 13u];
                        let l1 = geo[o + 14u];
                        let scale = geo[o + 15u];
                        let wa = wq * (nx_(ex, ku, 0u, ia) * va) * scale;
                        e0 += wa * l0;
                        e1 += wa * l1;
                    }
                }
                acc0 += e0;
                acc1 += e1;
            }
        }
    }
    res[2u * id] = acc0;
    res[2u * id + 1u] = acc1;
}

// Tensor values (w, w_xi, w_eta, w_xixi, w_xieta, w_etaeta) of local function (ia, ja).
fn tensor(ex: u32, ey: u32, ku: u32, kv: u32, ia: u32, ja: u32) -> array<real, 6> {
    let u0 = nx_(ex, ku, 0u, ia);
    let u1 = nx_(ex, ku, 1u, ia);
    let u2 = nx_(ex, ku, 2u, ia);
    let v0 = ny_(ey, kv, 0u, ja);
    let v1 = ny_(ey, kv, 1u, ja);
    let v2 = ny_(ey, kv, 2u, ja);
    return array<real, 6>(u0 * v0, u1 * v0, u0 * v1, u2 * v0, u1 * v1, u0 * v2);
}

// The stencil entry handled by an invocation: row function k = (i, j), column function
// kk = (ii, jj) = (i + di - p, j + dj - q) for slot s = dj (2p + 1) + di.
struct Entry {
    valid: bool,
    i: u32,
    j: u32,
    ii: u32,
    jj: u32,
    // local row index in the chunk and slot
    kl: u32,
    s: u32,
}

fn entry(id: u32) -> Entry {
    var en: Entry;
    let sw = (2u * P.p + 1u) * (2u * P.q + 1u);
    en.kl = id / sw;
    en.s = id % sw;
    let k = P.j0 * P.nx + en.kl;
    en.i = k % P.nx;
    en.j = k / P.nx;
    let di = en.s % (2u * P.p + 1u);
    let dj = en.s / (2u * P.p + 1u);
    en.valid = en.i + di >= P.p && en.j + dj >= P.q && en.i + di - P.p < P.nx && en.j + dj - P.q < P.ny;
    if en.valid {
        en.ii = en.i + di - P.p;
        en.jj = en.j + dj - P.q;
    }
    return en;
}

fn stencil_width() -> u32 {
    return (2u * P.p + 1u) * (2u * P.q + 1u);
}

// Pass 2b: EGG Jacobian, the four component blocks (z, d) of one stencil entry.
@compute @workgroup_size(64)
fn egg_stencil(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let id = linear_id(gid, nwg);
    let sw = stencil_width();
    if id >= (P.j1 - P.j0) * P.nx * sw {
        return;
    }
    let en = entry(id);
    var acc = array<real, 4>(0.0, 0.0, 0.0, 0.0);
    if en.valid {
        let ra = erange(0u, en.i);
        let rb = erange(0u, en.ii);
        let sa = erange(1u, en.j);
        let sb = erange(1u, en.jj);
        let lox = max(ra.x, rb.x);
        let hix = min(ra.y, rb.y);
        let loy = max(sa.x, sb.x);
        let hiy = min(sa.y, sb.y);
        for (var c = 0u; c <= P.q; c++) {
            for (var ey = loy; ey <= hiy; ey++) {
                if !in_colour(ey, c) {
                    continue;
                }
                let fy = idx[P.first_y + ey];
                for (var ex = lox; ex <= hix; ex++) {
                    let fx = idx[P.first_x + ex];
                    var el = array<real, 4>(0.0, 0.0, 0.0, 0.0);
                    for (var kv = 0u; kv < P.nq_v; kv++) {
                        let wv = wy_(ey, kv);
                        for (var ku = 0u; ku < P.nq_u; ku++) {
                            let wq = wx_(ex, ku) * wv;
                            let a0 = nx_(ex, ku, 0u, en.i - fx) * ny_(ey, kv, 0u, en.j - fy);
                            let wb = tensor(ex, ey, ku, kv, en.ii - fx, en.jj - fy);
                            let o = geo_base(ex, ey, ku, kv);
                            var xu = vec2<real>(geo[o], geo[o + 1u]);
                            var xv = vec2<real>(geo[o + 2u], geo[o + 3u]);
                            var xuu = vec2<real>(geo[o + 4u], geo[o + 5u]);
                            var xuv = vec2<real>(geo[o + 6u], geo[o + 7u]);
                            var xvv = vec2<real>(geo[o + 8u], geo[o + 9u]);
                            let g11 = geo[o + 10u];
                            let g12 = geo[o + 11u];
                            let g22 = geo[o + 12u];
                            var l = vec2<real>(geo[o + 13u], geo[o + 14u]);
                            let scale = geo[o + 15u];
                            let sden = geo[o + 16u];
                            let wa = wq * a0 * scale;
                            let lw = g22 * wb[3] - 2.0 * g12 * wb[4] + g11 * wb[5];
                            for (var d = 0u; d < 2u; d++) {
                                let dg11 = 2.0 * xu[d] * wb[1];
                                let dg12 = xu[d] * wb[2] + xv[d] * wb[1];
                                let dg22 = 2.0 * xv[d] * wb[2];
                                let ds = 2.0 * (xu[d] * wb[1] + xv[d] * wb[2]);
                                for (var z = 0u; z < 2u; z++) {
                                    var v = dg22 * xuu[z] - 2.0 * dg12 * xuv[z] + dg11 * xvv[z];
                                    if z == d {
                                        v += lw;
                                    }
                                    if P.op == 1u {
                                        v -= l[z] * ds / sden;
                                    }
                                    el[z * 2u + d] += wa * v;
                                }
                            }
                        }
                    }
                    for (var zd = 0u; zd < 4u; zd++) {
                        acc[zd] += el[zd];
                    }
                }
            }
        }
    }
    let base = en.kl * 4u * sw + en.s;
    for (var zd = 0u; zd < 4u; zd++) {
        out[base + zd * sw] = acc[zd];
    }
}

// Pass 2c: linear elasticity on the physical domain (Discretization::elasticity):
// a(u, v) = int lambda div u div v + 2 mu eps(u):eps(v) dx with grad_x w = J^{-T} grad_xi w,
// dx = |det J| dxi; parametric gradients where det J vanishes.
@compute @workgroup_size(64)
fn elasticity_stencil(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let id = linear_id(gid, nwg);
    let sw = stencil_width();
    if id >= (P.j1 - P.j0) * P.nx * sw {
        return;
    }
    let en = entry(id);
    let lambda = tab[P.lame];
    let mu = tab[P.lame + 1u];
    var acc = array<real, 4>(0.0, 0.0, 0.0, 0.0);
    if en.valid {
        let ra = erange(0u, en.i);
        let rb = erange(0u, en.ii);
        let sa = erange(1u, en.j);
        let sb = erange(1u, en.jj);
        let lox = max(ra.x, rb.x);
        let hix = min(ra.y, rb.y);
        let loy = max(sa.x, sb.x);
        let hiy = min(sa.y, sb.y);
        for (var c = 0u; c <= P.q; c++) {
            for (var ey = loy; ey <= hiy; ey++) {
                if !in_colour(ey, c) {
                    continue;
                }
                let fy = idx[P.first_y + ey];
                for (var ex = lox; ex <= hix; ex++) {
                    let fx = idx[P.first_x + ex];
                    var el = array<real, 4>(0.0, 0.0, 0.0, 0.0);
                    for (var kv = 0u; kv < P.nq_v; kv++) {
                        let wv = wy_(ey, kv);
                        for (var ku = 0u; ku < P.nq_u; ku++) {
                            let wq = wx_(ex, ku) * wv;
                            let ta = tensor(ex, ey, ku, kv, en.i - fx, en.j - fy);
                            let tb = tensor(ex, ey, ku, kv, en.ii - fx, en.jj - fy);
                            let o = geo_base(ex, ey, ku, kv);
                            let xu = vec2<real>(geo[o], geo[o + 1u]);
                            let xv = vec2<real>(geo[o + 2u], geo[o + 3u]);
                            let det = xu.x * xv.y - xv.x * xu.y;
                            // |det| > 1e-12 |x_xi| |x_eta| and |x_xi| |x_eta| > 0, squared
                            let s2 = (xu.x * xu.x + xu.y * xu.y) * (xv.x * xv.x + xv.y * xv.y);
                            let regular = det * det > 1e-24 * s2 && s2 > 0.0;
                            var ga = vec2<real>(ta[1], ta[2]);
                            var gb = vec2<real>(tb[1], tb[2]);
                            var dx = wq;
                            if regular {
                                ga = vec2<real>((xv.y * ta[1] - xu.y * ta[2]) / det, (-xv.x * ta[1] + xu.x * ta[2]) / det);
                                gb = vec2<real>((xv.y * tb[1] - xu.y * tb[2]) / det, (-xv.x * tb[1] + xu.x * tb[2]) / det);
                                dx = wq * abs(det);
                            }
                            for (var z = 0u; z < 2u; z++) {
                                for (var d = 0u; d < 2u; d++) {
                                    var v = lambda * ga[z] * gb[d] + mu * ga[d] * gb[z];
                                    if z == d {
                                        v += mu * (ga.x * gb.x + ga.y * gb.y);
                                    }
                                    el[z * 2u + d] += dx * v;
                                }
                            }
                        }
                    }
                    for (var zd = 0u; zd < 4u; zd++) {
                        acc[zd] += el[zd];
                    }
                }
            }
        }
    }
    let base = en.kl * 4u * sw + en.s;
    for (var zd = 0u; zd < 4u; zd++) {
        out[base + zd * sw] = acc[zd];
    }
}

// Pass 2d: scalar mass matrix int w_a w_b (eq. 30); needs no geometry.
@compute @workgroup_size(64)
fn mass_stencil(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let id = linear_id(gid, nwg);
    let sw = stencil_width();
    if id >= (P.j1 - P.j0) * P.nx * sw {
        return;
    }
    let en = entry(id);
    var acc: real = 0.0;
    if en.valid {
        let ra = erange(0u, en.i);
        let rb = erange(0u, en.ii);
        let sa = erange(1u, en.j);
        let sb = erange(1u, en.jj);
        let lox = max(ra.x, rb.x);
        let hix = min(ra.y, rb.y);
        let loy = max(sa.x, sb.x);
        let hiy = min(sa.y, sb.y);
        for (var c = 0u; c <= P.q; c++) {
            for (var ey = loy; ey <= hiy; ey++) {
                if !in_colour(ey, c) {
                    continue;
                }
                let fy = idx[P.first_y + ey];
                for (var ex = lox; ex <= hix; ex++) {
                    let fx = idx[P.first_x + ex];
                    var el: real = 0.0;
                    for (var kv = 0u; kv < P.nq_v; kv++) {
                        let wv = wy_(ey, kv);
                        let va = ny_(ey, kv, 0u, en.j - fy);
                        let vb = ny_(ey, kv, 0u, en.jj - fy);
                        for (var ku = 0u; ku < P.nq_u; ku++) {
                            let wq = wx_(ex, ku) * wv;
                            let a0 = nx_(ex, ku, 0u, en.i - fx) * va;
                            let b0 = nx_(ex, ku, 0u, en.ii - fx) * vb;
                            el += wq * (a0 * b0);
                        }
                    }
                    acc += el;
                }
            }
        }
    }
    out[en.kl * sw + en.s] = acc;
}

// The Jacobian terms dL_z/dc^d_b of the current quadrature point, per local function b
// (at most (MAX_DEGREE + 1)^2 = 169 of them, MAX_DEGREE = 12).
var<workgroup> tshared: array<real, 676>;

// Pass 2e: EGG element matrices, one workgroup per element of the chunk. Per quadrature
// point the threads first compute t_b = dL/dc_b for the local functions b (shared), then
// each thread adds w_a t_b to its rows a of the element matrix: the CPU's element loop
// (Discretization::egg) with the terms shared as on the CPU.
@compute @workgroup_size(64)
fn egg_element(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let e = wid.x + wid.y * nwg.x;
    // uniform per workgroup: the whole group returns together
    if e >= (P.ey1 - P.ey0) * P.nex {
        return;
    }
    let ex = e % P.nex;
    let ey = P.ey0 + e / P.nex;
    let nloc = (P.p + 1u) * (P.q + 1u);
    let base = e * 4u * nloc * nloc;
    for (var r = lid; r < 4u * nloc * nloc; r += WG) {
        elm[base + r] = 0.0;
    }
    for (var kv = 0u; kv < P.nq_v; kv++) {
        let wv = wy_(ey, kv);
        for (var ku = 0u; ku < P.nq_u; ku++) {
            let wq = wx_(ex, ku) * wv;
            let o = geo_base(ex, ey, ku, kv);
            var xu = vec2<real>(geo[o], geo[o + 1u]);
            var xv = vec2<real>(geo[o + 2u], geo[o + 3u]);
            var xuu = vec2<real>(geo[o + 4u], geo[o + 5u]);
            var xuv = vec2<real>(geo[o + 6u], geo[o + 7u]);
            var xvv = vec2<real>(geo[o + 8u], geo[o + 9u]);
            let g11 = geo[o + 10u];
            let g12 = geo[o + 11u];
            let g22 = geo[o + 12u];
            var l = vec2<real>(geo[o + 13u], geo[o + 14u]);
            let scale = geo[o + 15u];
            let sden = geo[o + 16u];
            for (var b = lid; b < nloc; b += WG) {
                let wb = tensor(ex, ey, ku, kv, b % (P.p + 1u), b / (P.p + 1u));
                let lw = g22 * wb[3] - 2.0 * g12 * wb[4] + g11 * wb[5];
                for (var d = 0u; d < 2u; d++) {
                    let dg11 = 2.0 * xu[d] * wb[1];
                    let dg12 = xu[d] * wb[2] + xv[d] * wb[1];
                    let dg22 = 2.0 * xv[d] * wb[2];
                    let ds = 2.0 * (xu[d] * wb[1] + xv[d] * wb[2]);
                    for (var z = 0u; z < 2u; z++) {
                        var v = dg22 * xuu[z] - 2.0 * dg12 * xuv[z] + dg11 * xvv[z];
                        if z == d {
                            v += lw;
                        }
                        if P.op == 1u {
                            v -= l[z] * ds / sden;
                        }
                        tshared[b * 4u + z * 2u + d] = v;
                    }
                }
            }
            workgroupBarrier();
            // one thread per row (zd, a) of the element matrix
            for (var r = lid; r < 4u * nloc; r += WG) {
                let zd = r / nloc;
                let a = r % nloc;
                let wa = wq * (nx_(ex, ku, 0u, a % (P.p + 1u)) * ny_(ey, kv, 0u, a / (P.p + 1u))) * scale;
                let row = base + r * nloc;
                for (var b = 0u; b < nloc; b++) {
                    elm[row + b] += wa * tshared[b * 4u + zd];
                }
            }
            workgroupBarrier();
        }
    }
}

// Pass 2f: the stencil entries of the EGG Jacobian from the element matrices, summed over
// the elements of the common support in the CPU's order.
@compute @workgroup_size(64)
fn egg_gather(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let id = linear_id(gid, nwg);
    let sw = stencil_width();
    if id >= (P.j1 - P.j0) * P.nx * sw {
        return;
    }
    let en = entry(id);
    let nloc = (P.p + 1u) * (P.q + 1u);
    var acc = array<real, 4>(0.0, 0.0, 0.0, 0.0);
    if en.valid {
        let ra = erange(0u, en.i);
        let rb = erange(0u, en.ii);
        let sa = erange(1u, en.j);
        let sb = erange(1u, en.jj);
        let lox = max(ra.x, rb.x);
        let hix = min(ra.y, rb.y);
        let loy = max(sa.x, sb.x);
        let hiy = min(sa.y, sb.y);
        for (var c = 0u; c <= P.q; c++) {
            for (var ey = loy; ey <= hiy; ey++) {
                if !in_colour(ey, c) {
                    continue;
                }
                let fy = idx[P.first_y + ey];
                for (var ex = lox; ex <= hix; ex++) {
                    let fx = idx[P.first_x + ex];
                    let a = (en.j - fy) * (P.p + 1u) + en.i - fx;
                    let b = (en.jj - fy) * (P.p + 1u) + en.ii - fx;
                    let base = ((ey - P.ey0) * P.nex + ex) * 4u * nloc * nloc;
                    for (var zd = 0u; zd < 4u; zd++) {
                        acc[zd] += elm[base + (zd * nloc + a) * nloc + b];
                    }
                }
            }
        }
    }
    let base = en.kl * 4u * sw + en.s;
    for (var zd = 0u; zd < 4u; zd++) {
        out[base + zd * sw] = acc[zd];
    }
}
