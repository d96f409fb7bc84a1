//! The recorded V-cycle of [`super::GpuCycles`]: the layout of an uploaded hierarchy in
//! the kernels' buffers ([`pack`]), the parameter record of each dispatch ([`Params`],
//! `Params` in `shaders/multigrid.wgsl`) and the recorder that turns the core's cycle
//! operations ([`LevelKernels`], strung together by `v_cycle`) into dispatches.

use winslow::linalg::multigrid_kernels::{Hierarchy, LevelKernels, LevelOperator, LineBlocks, Smoothing};
use winslow::linalg::sparse::Csr;

use crate::GpuError;

/// The parameter record of `multigrid.wgsl` (all `u32`; `Params` there).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct Params {
    pub(crate) count: u32,
    pub(crate) op_kind: u32,
    pub(crate) nx: u32,
    pub(crate) ny: u32,
    pub(crate) bx: u32,
    pub(crate) by: u32,
    pub(crate) st_off: u32,
    pub(crate) csr_ptr: u32,
    pub(crate) csr_col: u32,
    pub(crate) csr_val: u32,
    pub(crate) b_off: u32,
    pub(crate) x_off: u32,
    pub(crate) r_off: u32,
    pub(crate) l_starts: u32,
    pub(crate) l_stride: u32,
    pub(crate) l_len: u32,
    pub(crate) l_bw: u32,
    pub(crate) l_fac: u32,
    pub(crate) l_first: u32,
    pub(crate) l_step: u32,
    pub(crate) a_ptr: u32,
    pub(crate) a_col: u32,
    pub(crate) a_val: u32,
    pub(crate) m0: u32,
    pub(crate) n0: u32,
    pub(crate) in_off: u32,
    pub(crate) out_off: u32,
    pub(crate) t_off: u32,
    pub(crate) accumulate: u32,
    pub(crate) zero_off: u32,
    pub(crate) cn: u32,
    pub(crate) c_fac: u32,
    pub(crate) c_lo: u32,
    pub(crate) c_hi: u32,
    pub(crate) c_phase: u32,
    pub(crate) c_pad: u32,
    pub(crate) st_shift: u32,
    pub(crate) st_mask: u32,
    pub(crate) s_free: u32,
    pub(crate) s_free_of: u32,
    pub(crate) s_m: u32,
    pub(crate) s_comp: u32,
    pub(crate) s_pad0: u32,
    pub(crate) s_pad1: u32,
}

/// `NONE` of the shader: no vector to zero.
pub(crate) const NONE: u32 = u32::MAX;
/// Multiply-adds per dispatch of the coarsest solve (one invocation): lavapipe cut a
/// single invocation of the whole solve at 289 unknowns (about 65 000 loop iterations)
/// short, so it runs in row blocks of about this much work.
const COARSE_WORK: usize = 4096;

/// Which kernel a recorded step runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kernel {
    Residual,
    LineResidual,
    LineSmooth,
    TransferRows,
    TransferCols,
    CoarseSolve,
    /// `system_product` (the Galerkin system's product, `crate::product`).
    SystemProduct,
}

/// One dispatch of the recorded cycle.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step {
    pub(crate) kernel: Kernel,
    pub(crate) params: Params,
}

/// Where a level's operator lives.
#[derive(Debug, Clone, Copy)]
pub(crate) enum OpAt {
    Stencil { nx: u32, ny: u32, bx: u32, by: u32, st_off: u32 },
    Csr { ptr: u32, col: u32, val: u32 },
}

/// Where a direction's lines live.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LinesAt {
    pub(crate) starts: u32,
    pub(crate) stride: u32,
    pub(crate) len: u32,
    pub(crate) bw: u32,
    pub(crate) fac: u32,
    pub(crate) colours: u32,
    pub(crate) count: u32,
}

/// A 1D factor in `idx` / `reals`: row pointers, columns, values, rows, columns.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FactorAt {
    pub(crate) ptr: u32,
    pub(crate) col: u32,
    pub(crate) val: u32,
    pub(crate) rows: u32,
    pub(crate) cols: u32,
}

/// Offsets of everything a level's operations read and write.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LevelAt {
    pub(crate) size: u32,
    pub(crate) b: u32,
    pub(crate) x: u32,
    pub(crate) r: u32,
    pub(crate) op: Option<OpAt>,
    pub(crate) lines: Option<[LinesAt; 2]>,
}

/// The layout of an uploaded hierarchy.
#[derive(Debug, Clone)]
pub(crate) struct Layout {
    pub(crate) levels: Vec<LevelAt>,
    /// Per transfer: `[P_0, P_1]` and `[P_0^T, P_1^T]`.
    pub(crate) transfers: Vec<([FactorAt; 2], [FactorAt; 2])>,
    pub(crate) coarse_fac: u32,
    pub(crate) t_off: u32,
    pub(crate) vec_len: usize,
    pub(crate) smoothing: Smoothing,
}

fn to_u32(v: usize, what: &str) -> Result<u32, GpuError> {
    crate::to_u32(v, &format!("multigrid {what}"))
}

/// What goes into the three read-only buffers, being laid out: the indices (built here,
/// `O(sqrt n)` per level: line starts, 1D factors' pattern), and the reals and stencil
/// values as the hierarchy's own slices in buffer order (written straight into the
/// buffers' mappings: no host copy of what is `O(n)`).
#[derive(Default)]
pub(crate) struct Packed<'a> {
    pub(crate) reals: Vec<&'a [f64]>,
    pub(crate) reals_len: usize,
    pub(crate) idx: Vec<u32>,
    pub(crate) stencil: Vec<&'a [f32]>,
    pub(crate) stencil_len: usize,
}

impl<'a> Packed<'a> {
    /// Append `v` to the reals; its offset.
    fn real(&mut self, v: &'a [f64]) -> Result<u32, GpuError> {
        let at = to_u32(self.reals_len, "real")?;
        self.reals.push(v);
        self.reals_len += v.len();
        Ok(at)
    }

    fn csr(&mut self, a: &'a Csr) -> Result<FactorAt, GpuError> {
        let ptr = to_u32(self.idx.len(), "index")?;
        for &p in &a.row_ptr {
            self.idx.push(to_u32(p, "row pointer")?);
        }
        let col = to_u32(self.idx.len(), "index")?;
        for &c in &a.col_idx {
            self.idx.push(to_u32(c, "column")?);
        }
        let val = self.real(&a.values)?;
        Ok(FactorAt { ptr, col, val, rows: to_u32(a.nrows, "rows")?, cols: to_u32(a.ncols, "columns")? })
    }

    fn lines(&mut self, l: &LineBlocks<'a>) -> Result<LinesAt, GpuError> {
        let starts = to_u32(self.idx.len(), "index")?;
        for &s in l.starts {
            self.idx.push(to_u32(s, "line start")?);
        }
        let fac = self.real(l.factors)?;
        Ok(LinesAt {
            starts,
            stride: to_u32(l.stride, "stride")?,
            len: to_u32(l.len, "line length")?,
            bw: to_u32(l.bandwidth, "bandwidth")?,
            fac,
            colours: to_u32(l.colours.max(1), "colours")?,
            count: to_u32(l.starts.len(), "lines")?,
        })
    }
}

/// Pack `h` into the three read-only buffers and lay out the vectors.
pub(crate) fn pack<'a>(h: &Hierarchy<'a>) -> Result<(Layout, Packed<'a>), GpuError> {
    let mut p = Packed::default();
    let mut levels = Vec::new();
    let mut off = 0usize;
    for (l, (op, lines)) in h.levels.iter().enumerate() {
        let n = op.size();
        let op = match *op {
            LevelOperator::Stencil { nx, ny, half, values } => {
                let st_off = to_u32(p.stencil_len, "stencil offset")?;
                p.stencil.push(values);
                p.stencil_len += values.len();
                OpAt::Stencil {
                    nx: to_u32(nx, "grid width")?,
                    ny: to_u32(ny, "grid height")?,
                    bx: to_u32(half[0], "half width")?,
                    by: to_u32(half[1], "half width")?,
                    st_off,
                }
            }
            LevelOperator::Csr(a) => {
                let f = p.csr(a)?;
                OpAt::Csr { ptr: f.ptr, col: f.col, val: f.val }
            }
        };
        let lines = [p.lines(&lines[0])?, p.lines(&lines[1])?];
        let at = |k: usize| to_u32(off + k * n, "vector offset");
        levels.push(LevelAt {
            size: to_u32(n, "level size")?,
            b: at(0)?,
            x: at(1)?,
            r: at(2)?,
            op: Some(op),
            lines: Some(lines),
        });
        off += 3 * n;
        debug_assert_eq!(n, h.size(l));
    }
    let (cn, cfac) = h.coarse;
    levels.push(LevelAt {
        size: to_u32(cn, "coarsest size")?,
        b: to_u32(off, "vector offset")?,
        x: to_u32(off + cn, "vector offset")?,
        r: NONE,
        op: None,
        lines: None,
    });
    off += 2 * cn;
    let coarse_fac = p.real(cfac)?;
    let mut transfers = Vec::new();
    let mut t_len = 0usize;
    for t in &h.transfers {
        let pro = [p.csr(t.prolongation[0])?, p.csr(t.prolongation[1])?];
        let res = [p.csr(t.restriction[0])?, p.csr(t.restriction[1])?];
        // t of a pass: n_1 m_0 values
        t_len = t_len.max(pro[1].cols as usize * pro[0].rows as usize).max(res[1].cols as usize * res[0].rows as usize);
        transfers.push((pro, res));
    }
    let t_off = to_u32(off, "vector offset")?;
    let vec_len = off + t_len;
    to_u32(vec_len, "vector length")?;
    Ok((Layout { levels, transfers, coarse_fac, t_off, vec_len, smoothing: h.smoothing }, p))
}

/// Records the dispatches of [`LevelKernels`] operations.
pub(crate) struct Recorder<'a> {
    pub(crate) layout: &'a Layout,
    pub(crate) steps: Vec<Step>,
}

impl Recorder<'_> {
    fn level(&self, l: usize) -> Params {
        let at = &self.layout.levels[l];
        let mut p = Params { b_off: at.b, x_off: at.x, r_off: at.r, zero_off: NONE, ..Default::default() };
        match at.op {
            Some(OpAt::Stencil { nx, ny, bx, by, st_off }) => {
                (p.op_kind, p.nx, p.ny, p.bx, p.by, p.st_off) = (0, nx, ny, bx, by, st_off);
            }
            Some(OpAt::Csr { ptr, col, val }) => {
                (p.op_kind, p.csr_ptr, p.csr_col, p.csr_val) = (1, ptr, col, val);
            }
            None => {}
        }
        p
    }

    /// `out = (a_1 ⊗ a_0) in` (added when `accumulate`), `zero` zeroed.
    fn kron(&mut self, a: [FactorAt; 2], input: u32, out: u32, accumulate: bool, zero: u32) {
        let t_off = self.layout.t_off;
        let base = Params { m0: a[0].rows, n0: a[0].cols, in_off: input, out_off: out, t_off, ..Default::default() };
        let rows = Params {
            count: a[1].cols * a[0].rows,
            a_ptr: a[0].ptr,
            a_col: a[0].col,
            a_val: a[0].val,
            zero_off: NONE,
            ..base
        };
        self.steps.push(Step { kernel: Kernel::TransferRows, params: rows });
        let cols = Params {
            count: a[1].rows * a[0].rows,
            a_ptr: a[1].ptr,
            a_col: a[1].col,
            a_val: a[1].val,
            accumulate: accumulate as u32,
            zero_off: zero,
            ..base
        };
        self.steps.push(Step { kernel: Kernel::TransferCols, params: cols });
    }
}

impl LevelKernels for Recorder<'_> {
    fn smooth(&mut self, l: usize, dir: usize, backward: bool) {
        let Some(lines) = self.layout.levels[l].lines.map(|ls| ls[dir]) else { return };
        if lines.len == 0 {
            return;
        }
        let c = lines.colours;
        let colours: Vec<u32> = if backward { (0..c).rev().collect() } else { (0..c).collect() };
        for k in colours {
            let count = (lines.count - k).div_ceil(c);
            let params = Params {
                count: count * lines.len,
                l_starts: lines.starts,
                l_stride: lines.stride,
                l_len: lines.len,
                l_bw: lines.bw,
                l_fac: lines.fac,
                l_first: k,
                l_step: c,
                ..self.level(l)
            };
            self.steps.push(Step { kernel: Kernel::LineResidual, params });
            self.steps.push(Step { kernel: Kernel::LineSmooth, params: Params { count, ..params } });
        }
    }

    fn residual(&mut self, l: usize) {
        let params = Params { count: self.layout.levels[l].size, ..self.level(l) };
        self.steps.push(Step { kernel: Kernel::Residual, params });
    }

    fn restrict(&mut self, l: usize) {
        let (fine, coarse) = (self.layout.levels[l], self.layout.levels[l + 1]);
        let a = self.layout.transfers[l].1;
        self.kron(a, fine.r, coarse.b, false, coarse.x);
    }

    fn prolong_add(&mut self, l: usize) {
        let (fine, coarse) = (self.layout.levels[l], self.layout.levels[l + 1]);
        let a = self.layout.transfers[l].0;
        self.kron(a, coarse.x, fine.x, true, NONE);
    }

    fn coarse_solve(&mut self) {
        let c = self.layout.levels.len() - 1;
        let at = self.layout.levels[c];
        let base = Params {
            count: 1,
            cn: at.size,
            c_fac: self.layout.coarse_fac,
            b_off: at.b,
            x_off: at.x,
            ..Default::default()
        };
        let n = at.size;
        // forward: row i costs i multiply-adds; backward: n - 1 - i
        for phase in [0u32, 1] {
            let mut lo = 0u32;
            while lo < n {
                let (mut hi, mut work) = (lo, 0usize);
                while hi < n && (hi == lo || work < COARSE_WORK) {
                    work += if phase == 0 { hi as usize } else { (n - 1 - hi) as usize } + 1;
                    hi += 1;
                }
                let params = Params { c_lo: lo, c_hi: hi, c_phase: phase, ..base };
                self.steps.push(Step { kernel: Kernel::CoarseSolve, params });
                lo = hi;
            }
        }
        // the backward blocks run from the last rows to the first
        let first_back = self.steps.iter().rposition(|s| s.kernel == Kernel::CoarseSolve && s.params.c_phase == 0);
        if let Some(k) = first_back {
            self.steps[k + 1..].reverse();
        }
    }
}
