alias real = f64;
// ^ Precision line, replaced by `alias real = f32;` for the f32 variant.
//
// The map and det J = x_xi y_eta - x_eta y_xi (paper eq. 43) on the (n+1)^2 grid of
// winslow::quality::sample_det_j, B-spline or NURBS, one invocation per grid point.
// Univariate basis values and first derivatives at the grid abscissae are tabulated on
// the CPU (winslow::basis::BasisDerivs); the tensor sums run here, in the same order as
// winslow::surface::Surface::derivs_with.

struct Params {
    // degrees
    p: u32,
    q: u32,
    // grid points per direction (n + 1)
    m: u32,
    // basis functions in xi
    nx: u32,
    // 1 when the map is rational
    rational: u32,
    // offset into `tab` of the eta records
    tab_y: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> P: Params;
// per abscissa and direction a record [N(0..=deg), N'(0..=deg)]
@group(0) @binding(1) var<storage, read> tab: array<real>;
// first non-zero function per abscissa: xi at [0, m), eta at [m, 2m)
@group(0) @binding(2) var<storage, read> first: array<u32>;
// control points with weights: (x, y, w) per function
@group(0) @binding(3) var<storage, read> cps: array<real>;
// (x, y, det J) per grid point, eta outer
@group(0) @binding(4) var<storage, read_write> out: array<real>;

@compute @workgroup_size(64)
fn sample(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let id = gid.x + gid.y * nwg.x * 64u;
    if id >= P.m * P.m {
        return;
    }
    let i = id % P.m;
    let j = id / P.m;
    let ru = i * 2u * (P.p + 1u);
    let rv = P.tab_y + j * 2u * (P.q + 1u);
    let fu = first[i];
    let fv = first[P.m + j];
    // h[a][b] = d^a/du^a d^b/dv^b of (w x, w y, w) for (a, b) in (0,0), (0,1), (1,0)
    var h00 = vec3<real>(0.0, 0.0, 0.0);
    var h01 = vec3<real>(0.0, 0.0, 0.0);
    var h10 = vec3<real>(0.0, 0.0, 0.0);
    for (var jb = 0u; jb <= P.q; jb++) {
        let v0 = tab[rv + jb];
        let v1 = tab[rv + P.q + 1u + jb];
        for (var ia = 0u; ia <= P.p; ia++) {
            let u0 = tab[ru + ia];
            let u1 = tab[ru + P.p + 1u + ia];
            let c = 3u * ((fv + jb) * P.nx + fu + ia);
            let w = cps[c + 2u];
            let cx = cps[c];
            let cy = cps[c + 1u];
            let n00 = u0 * v0 * w;
            h00 += vec3<real>(n00 * cx, n00 * cy, n00);
            let n01 = u0 * v1 * w;
            h01 += vec3<real>(n01 * cx, n01 * cy, n01);
            let n10 = u1 * v0 * w;
            h10 += vec3<real>(n10 * cx, n10 * cy, n10);
        }
    }
    var x = h00.xy;
    var xu = h10.xy;
    var xv = h01.xy;
    if P.rational == 1u {
        let w = h00.z;
        x = h00.xy / w;
        xu = (h10.xy - h10.z * x) / w;
        xv = (h01.xy - h01.z * x) / w;
    }
    out[3u * id] = x.x;
    out[3u * id + 1u] = x.y;
    out[3u * id + 2u] = xu.x * xv.y - xv.x * xu.y;
}
