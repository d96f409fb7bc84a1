//! One level of a hierarchy (paper §5.4): a tensor-product basis and the four sides on
//! it, with the weights of its rational basis when a side is NURBS (§5.2).

use crate::error::{Error, Result};
use crate::spline::curve::Curve;
use crate::spline::knots::KnotVector;
use crate::spline::surface::Side;

/// One level of the hierarchy: a tensor-product basis and the four side fits on it.
#[derive(Debug, Clone)]
pub struct Level {
    /// Knot vectors in `xi` (union of the south and north fits) and `eta` (union of the
    /// east and west fits).
    pub knots: [KnotVector; 2],
    /// South, east, north, west: each side's fit, prolonged exactly onto
    /// `knots[side.direction()]` (so opposite sides share one knot vector).
    pub sides: [Curve; 4],
}

impl Level {
    /// Number of tensor-product basis functions `n_xi * n_eta`.
    pub fn num_basis(&self) -> usize {
        self.knots[0].num_basis() * self.knots[1].num_basis()
    }

    /// The side `s` on this level's basis.
    pub fn side(&self, s: Side) -> &Curve {
        &self.sides[s as usize]
    }

    /// Weights of the level's rational tensor basis, or `None` when every side is
    /// polynomial (NURBS sides on the input basis, §5.2).
    ///
    /// The boundary weights are the sides' weights; the interior ones are the discrete
    /// Coons blend of them at the Greville abscissae `(u_i, v_j)`,
    /// `w_ij = (1-u) w^W_j + u w^E_j + (1-v) w^S_i + v w^N_i - [(1-u)(1-v) w_SW + ...]`.
    /// By the linear precision of B-splines (`sum_i u_i N_i(xi) = xi`) the weight function
    /// `W = sum w_ij N_i M_j` is then the continuous Coons interpolant of the four boundary
    /// weight functions: it does not depend on the basis, so knot insertion commutes with
    /// the blend, and a side pair with equal weights (`w^S = w^N`, `w^W = w^E = 1`: a
    /// quarter annulus from two exact arcs) gives the tensor-product weights `w_i`
    /// exactly. With `eta` periodic (a ring) it is the linear blend in `xi` of west and
    /// east. A blend with a non-positive weight is an error: such sides need the fitted
    /// basis.
    pub fn weights(&self) -> Result<Option<Vec<f64>>> {
        if self.sides.iter().all(|c| c.weights.is_none()) {
            return Ok(None);
        }
        let [nx, ny] = [self.knots[0].num_basis(), self.knots[1].num_basis()];
        let w = |s: Side| -> Vec<f64> {
            let c = self.side(s);
            c.weights.clone().unwrap_or_else(|| vec![1.0; c.control_points.len()])
        };
        let (ws, we, wn, ww) = (w(Side::South), w(Side::East), w(Side::North), w(Side::West));
        let periodic = self.knots[1].is_periodic();
        if we.len() != ny || ww.len() != ny || (!periodic && (ws.len() != nx || wn.len() != nx)) {
            return Err(Error::Invalid("the sides' weights do not match the level's basis".into()));
        }
        let (gu, gv) = (self.knots[0].greville(), self.knots[1].greville());
        let ((a0, a1), (b0, b1)) = (self.knots[0].domain(), self.knots[1].domain());
        let mut out = vec![0.0; nx * ny];
        for j in 0..ny {
            let v = (gv[j] - b0) / (b1 - b0);
            for i in 0..nx {
                let u = (gu[i] - a0) / (a1 - a0);
                out[j * nx + i] = if periodic {
                    (1.0 - u) * ww[j] + u * we[j]
                } else {
                    (1.0 - u) * ww[j] + u * we[j] + (1.0 - v) * ws[i] + v * wn[i]
                        - ((1.0 - u) * (1.0 - v) * ws[0]
                            + u * (1.0 - v) * ws[nx - 1]
                            + (1.0 - u) * v * wn[0]
                            + u * v * wn[nx - 1])
                };
            }
        }
        // the boundary rows are the sides' weights exactly (the blend reproduces them up
        // to rounding; the boundary must be the input curve bit for bit)
        for i in 0..nx {
            if !periodic {
                out[i] = ws[i];
                out[(ny - 1) * nx + i] = wn[i];
            }
        }
        for j in 0..ny {
            out[j * nx] = ww[j];
            out[j * nx + nx - 1] = we[j];
        }
        if let Some(k) = out.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
            return Err(Error::Invalid(format!(
                "the Coons blend of the boundary weights is {} at control point ({}, {}): \
                 the rational tensor basis needs positive weights",
                out[k],
                k % nx,
                k / nx
            )));
        }
        Ok(Some(out))
    }
}
