//! Cord-length parameters of a point sequence (paper eq. 36-37), the abscissae of
//! point-cloud fits ([`super::fit`]) and the starting parameters of the constrained
//! reparameterization ([`super::reparam`], §7.2).

use crate::spline::curve::Point;

/// Cord-length abscissae of a point cloud (paper eq. 36-37): `ξ_1 = 0`,
/// `ξ_i = l_i / l_K` with `l_i = l_{i-1} + ||p_i - p_{i-1}||`, and `ξ_K = 1` exactly.
/// `None` when the cloud has fewer than two points or zero total length.
pub fn cord_length_params(points: &[Point]) -> Option<Vec<f64>> {
    if points.len() < 2 {
        return None;
    }
    let mut l = Vec::with_capacity(points.len());
    l.push(0.0);
    for w in points.windows(2) {
        let d = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
        l.push(l.last().unwrap() + d);
    }
    let total = *l.last().unwrap();
    if !(total.is_finite() && total > 0.0) {
        return None;
    }
    for v in &mut l {
        *v /= total;
    }
    *l.last_mut().unwrap() = 1.0;
    Some(l)
}
