//! The path's coefficients, knot after knot, written straight into the column-major
//! `knots x p` layout of [`super::Lars::standardized_coef_path`]: no knot-major buffer to
//! transpose at the end, and the entries of features that are not active stay the zeros of
//! the allocation (never written, so their memory is not even touched before the end).

use nalgebra::DMatrix;

/// Column-major `knots x p` storage with room for `cap` knots per column.
pub(super) struct Knots {
    data: Vec<f64>,
    cap: usize,
    len: usize,
    p: usize,
}

impl Knots {
    /// Room for `cap` knots (at least one) of `p` coefficients.
    pub(super) fn with_capacity(p: usize, cap: usize) -> Self {
        let cap = cap.max(1);
        Knots {
            data: vec![0.0; cap * p],
            cap,
            len: 0,
            p,
        }
    }

    /// Number of knots stored.
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// Appends a knot (doubling the room when it is full).
    pub(super) fn push(&mut self, coef: &[f64]) {
        debug_assert_eq!(coef.len(), self.p);
        if self.len == self.cap {
            let cap = 2 * self.cap;
            let mut data = vec![0.0; cap * self.p];
            for j in 0..self.p {
                data[j * cap..j * cap + self.len]
                    .copy_from_slice(&self.data[j * self.cap..j * self.cap + self.len]);
            }
            self.data = data;
            self.cap = cap;
        }
        let k = self.len;
        for (j, &b) in coef.iter().enumerate() {
            // the zeros are already there
            if b != 0.0 {
                self.data[j * self.cap + k] = b;
            }
        }
        self.len += 1;
    }

    /// Knot `k` (a copy, `p` values).
    pub(super) fn knot(&self, k: usize) -> Vec<f64> {
        (0..self.p).map(|j| self.data[j * self.cap + k]).collect()
    }

    /// Overwrites knot `k`.
    pub(super) fn set_knot(&mut self, k: usize, coef: &[f64]) {
        for (j, &b) in coef.iter().enumerate() {
            self.data[j * self.cap + k] = b;
        }
    }

    /// The `knots x p` matrix (columns moved together in place when there was room left).
    pub(super) fn into_matrix(self) -> DMatrix<f64> {
        let Knots {
            mut data,
            cap,
            len,
            p,
        } = self;
        if cap != len {
            for j in 1..p {
                data.copy_within(j * cap..j * cap + len, j * len);
            }
            data.truncate(len * p);
            if 2 * len < cap {
                data.shrink_to_fit();
            }
        }
        DMatrix::from_vec(len, p, data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knots_grow_and_come_out_as_the_knots_by_features_matrix() {
        let p = 3;
        // room for 2 knots: the third and fifth push grow it
        let mut k = Knots::with_capacity(p, 2);
        let rows: Vec<Vec<f64>> = (0..5)
            .map(|r| {
                (0..p)
                    .map(|j| {
                        if (r + j) % 2 == 0 {
                            0.0
                        } else {
                            (r * 10 + j) as f64
                        }
                    })
                    .collect()
            })
            .collect();
        for r in &rows {
            k.push(r);
        }
        assert_eq!(k.len(), 5);
        assert_eq!(k.knot(3), rows[3]);
        k.set_knot(4, &[7.0, 0.0, 8.0]);
        let m = k.into_matrix();
        assert_eq!(m.shape(), (5, p));
        for (r, row) in rows.iter().enumerate().take(4) {
            for j in 0..p {
                assert_eq!(m[(r, j)], row[j], "knot {r} feature {j}");
            }
        }
        assert_eq!((m[(4, 0)], m[(4, 1)], m[(4, 2)]), (7.0, 0.0, 8.0));
    }
}
