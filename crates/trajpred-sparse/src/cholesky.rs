//! Incremental Cholesky factor `G = L L^T` of the active Gram matrix: append a column
//! (a variable enters), remove one (a lasso drop, by Givens rotations), and solve.
//!
//! The rows are packed in one line-aligned buffer from the thread's pool, each row starting
//! on a 64-byte line (see [`kernels::Tri`]): both triangular solves run over contiguous,
//! aligned memory, and a fit does not allocate a row per variable.

use crate::kernels::{self, Tri, tri_offset};
use crate::workspace::Aligned;

/// Lower-triangular Cholesky factor of the Gram matrix of the active set.
pub(crate) struct CholeskyFactor {
    buf: Aligned,
    len: usize,
}

impl Default for CholeskyFactor {
    fn default() -> Self {
        CholeskyFactor {
            buf: Aligned::empty(),
            len: 0,
        }
    }
}

/// Outcome of trying to append a column to the factor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Append {
    /// The column was appended.
    Appended,
    /// The column lies (numerically) in the span of the active columns: the squared norm of
    /// its part orthogonal to them is at most `tolerance * G_jj`. Nothing was changed.
    Collinear,
}

impl CholeskyFactor {
    /// An empty factor with room for `rows` rows.
    pub(crate) fn with_capacity(rows: usize) -> Self {
        CholeskyFactor {
            buf: Aligned::zeroed(tri_offset(rows)),
            len: 0,
        }
    }

    /// Size of the factor (number of active variables).
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    fn tri(&self) -> Tri<'_> {
        Tri {
            data: self.buf.as_slice(),
            len: self.len,
        }
    }

    /// Row `i`, `L[i][0..=i]`.
    fn row(&self, i: usize) -> &[f64] {
        let o = tri_offset(i);
        &self.buf.as_slice()[o..o + i + 1]
    }

    /// Room for one more row (doubling the room when it is full).
    fn reserve_row(&mut self) {
        let need = tri_offset(self.len + 1);
        if self.buf.as_slice().len() < need {
            let mut bigger = Aligned::zeroed(tri_offset(2 * self.len + 8));
            let used = tri_offset(self.len);
            bigger.as_mut_slice()[..used].copy_from_slice(&self.buf.as_slice()[..used]);
            self.buf = bigger;
        }
    }

    /// Tries to append the variable whose Gram entries with the active set are `g` (in the
    /// factor's order) and whose own squared norm is `gjj`.
    pub(crate) fn append(&mut self, g: &[f64], gjj: f64, tolerance: f64) -> Append {
        debug_assert_eq!(g.len(), self.len());
        let k = self.len;
        self.reserve_row();
        let o = tri_offset(k);
        // the new row is solved in its own place, from the rows above it
        let (above, rest) = self.buf.as_mut_slice().split_at_mut(o);
        let w = &mut rest[..k + 1];
        w[..k].copy_from_slice(g);
        kernels::forward(
            Tri {
                data: above,
                len: k,
            },
            &mut w[..k],
        );
        let d2 = gjj - w[..k].iter().map(|v| v * v).sum::<f64>();
        if !(d2.is_finite() && d2 > tolerance * gjj && gjj > 0.0) {
            return Append::Collinear;
        }
        w[k] = d2.sqrt();
        self.len += 1;
        Append::Appended
    }

    /// Removes the variable at position `idx` (a lasso drop): the row is deleted and the
    /// resulting Hessenberg part is restored to triangular form with Givens rotations.
    pub(crate) fn remove(&mut self, idx: usize) {
        if idx >= self.len {
            return;
        }
        // (rare: the rows are taken out, rotated as separate rows and packed again)
        let mut rows: Vec<Vec<f64>> = (0..self.len).map(|i| self.row(i).to_vec()).collect();
        rows.remove(idx);
        let k = rows.len();
        for i in idx..k {
            let a = rows[i][i];
            let b = rows[i][i + 1];
            let r = a.hypot(b);
            let (c, s) = if r > 0.0 { (a / r, b / r) } else { (1.0, 0.0) };
            for row in &mut rows[i..] {
                let (x, y) = (row[i], row[i + 1]);
                row[i] = c * x + s * y;
                row[i + 1] = -s * x + c * y;
            }
            rows[i].truncate(i + 1);
        }
        let data = self.buf.as_mut_slice();
        for (i, row) in rows.iter().enumerate() {
            let o = tri_offset(i);
            data[o..o + i + 1].copy_from_slice(row);
        }
        self.len = k;
    }

    /// Extends `z = L^{-1} b`, solved for the factor without its last row, by the entry of
    /// that row (`b_last` the matching entry of `b`): bit for bit what a full forward solve
    /// gives, in `O(len)` instead of `O(len^2)`.
    pub(crate) fn forward_extend(&self, z: &mut Vec<f64>, b_last: f64) {
        let Some(k) = self.len.checked_sub(1) else {
            return;
        };
        let row = self.row(k);
        debug_assert_eq!(z.len(), k);
        let s = kernels::forward_dot(row, z, k);
        z.push((b_last - s) / row[k]);
    }

    /// Solves `L z = b` in place.
    pub(crate) fn forward_in_place(&self, b: &mut [f64]) {
        kernels::forward(self.tri(), b);
    }

    /// Solves `L^T x = z` in place.
    pub(crate) fn backward_in_place(&self, z: &mut [f64]) {
        kernels::backward(self.tri(), z);
    }

    /// Solves `G x = b` in place.
    pub(crate) fn solve_in_place(&self, b: &mut [f64]) {
        self.forward_in_place(b);
        self.backward_in_place(b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    fn gram() -> DMatrix<f64> {
        let x = DMatrix::from_fn(7, 4, |i, j| {
            ((i * 3 + j * 5) % 7) as f64 + 0.1 * (i * j) as f64
        });
        x.transpose() * &x
    }

    #[test]
    fn append_matches_full_cholesky_and_remove_matches_refactorisation() {
        let g = gram();
        let mut f = CholeskyFactor::default();
        for j in 0..4 {
            let col: Vec<f64> = (0..j).map(|i| g[(i, j)]).collect();
            assert_eq!(f.append(&col, g[(j, j)], 1e-12), Append::Appended);
        }
        // solve against nalgebra's LU (independent) to 1e-10: G is well conditioned here
        let b = [1.0, -2.0, 0.5, 3.0];
        let mut x = b.to_vec();
        f.solve_in_place(&mut x);
        let x_ref = g
            .clone()
            .lu()
            .solve(&nalgebra::DVector::from_column_slice(&b))
            .unwrap();
        for (a, r) in x.iter().zip(x_ref.iter()) {
            assert!((a - r).abs() < 1e-10 * r.abs().max(1.0));
        }
        // drop variable 1: the factor must now solve the Gram matrix of {0, 2, 3}
        f.remove(1);
        let keep = [0usize, 2, 3];
        let g2 = DMatrix::from_fn(3, 3, |i, j| g[(keep[i], keep[j])]);
        let b2 = [1.0, 0.5, 3.0];
        let mut x2 = b2.to_vec();
        f.solve_in_place(&mut x2);
        let x2_ref = g2
            .lu()
            .solve(&nalgebra::DVector::from_column_slice(&b2))
            .unwrap();
        for (a, r) in x2.iter().zip(x2_ref.iter()) {
            assert!((a - r).abs() < 1e-10 * r.abs().max(1.0));
        }
    }

    #[test]
    fn forward_extend_equals_a_full_forward_solve_bit_for_bit() {
        // 21 variables: several blocks of the blocked forward solve
        let x = DMatrix::from_fn(40, 21, |i, j| {
            ((i * 31 + j * 17) as f64 * 0.7).sin() + 0.3 * ((i * j) as f64).cos()
        });
        let g = x.transpose() * &x;
        let mut f = CholeskyFactor::default();
        let b: Vec<f64> = (0..21)
            .map(|j| if j % 3 == 0 { -1.0 } else { 1.0 })
            .collect();
        let mut z = Vec::new();
        for j in 0..21 {
            let col: Vec<f64> = (0..j).map(|i| g[(i, j)]).collect();
            assert_eq!(f.append(&col, g[(j, j)], 1e-12), Append::Appended);
            f.forward_extend(&mut z, b[j]);
            let mut full = b[..=j].to_vec();
            f.forward_in_place(&mut full);
            assert_eq!(z, full, "{j} variables");
        }
        // and the solve is right: G x = b against nalgebra's LU
        let mut sol = b.clone();
        f.solve_in_place(&mut sol);
        let want = g
            .lu()
            .solve(&nalgebra::DVector::from_column_slice(&b))
            .unwrap();
        for (a, r) in sol.iter().zip(want.iter()) {
            assert!((a - r).abs() < 1e-9 * r.abs().max(1.0), "{a} vs {r}");
        }
    }

    #[test]
    fn duplicate_column_is_reported_collinear() {
        let g = DMatrix::from_row_slice(2, 2, &[2.0, 2.0, 2.0, 2.0]);
        let mut f = CholeskyFactor::default();
        assert_eq!(f.append(&[], g[(0, 0)], 1e-12), Append::Appended);
        assert_eq!(f.append(&[g[(0, 1)]], g[(1, 1)], 1e-12), Append::Collinear);
        assert_eq!(f.len(), 1);
    }
}
