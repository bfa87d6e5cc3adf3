//! The typed error of a GSKF whose covariance recursion diverges.

/// The GSKF's covariance recursion blew up for a `q`: `F` (the GSC's coefficient rows)
/// amplifies `P` faster than the correction with the previous step's `S(k-1)` contains it
/// (on GeoLife's full LAR paths `|P|` grows about 1e10 times an iteration for small `q`).
#[derive(Debug, thiserror::Error)]
#[error(
    "the covariance recursion diverged for q = {q:.3e}: |P| grew from {from:.1e} to {to:.1e} in {iterations} iterations ({cause})"
)]
pub struct Diverged {
    /// The process noise level.
    pub q: f64,
    /// The Frobenius norm of `P` at the start (`R`'s).
    pub from: f64,
    /// Its norm at the last iteration that could be computed.
    pub to: f64,
    /// Iterations run.
    pub iterations: usize,
    /// What stopped it.
    pub cause: String,
}

#[cfg(test)]
mod tests {
    use super::super::AxisFilter;
    use super::*;
    use nalgebra::{DMatrix, DVector};
    use trajpred_core::Error;
    use trajpred_sparse::GroupSparseCoder;

    /// A coder whose rows extrapolate the window's degree-5 polynomial `t` steps ahead
    /// (Lagrange weights, up to 462 in size), as a least-squares fit to smooth, nearly
    /// collinear windows comes close to; or `scale` times that for `scale` < 1.
    fn coder(scale: f64) -> GroupSparseCoder {
        let m = 6;
        let a = DMatrix::from_fn(m, m, |t, j| {
            let x = (m + t) as f64; // the point predicted, on the grid 0..m of the window
            let w: f64 = (0..m)
                .filter(|&k| k != j)
                .map(|k| (x - k as f64) / (j as f64 - k as f64))
                .product();
            scale * w
        });
        GroupSparseCoder::from_parts(a, DVector::zeros(m), vec![4.0; m]).expect("valid parts")
    }

    #[test]
    fn an_amplifying_f_is_a_typed_divergence_and_a_contracting_one_converges() {
        match AxisFilter::new(coder(1.0), 1e-3) {
            Err(Error::Method { method, source }) => {
                assert_eq!(method, "gskf");
                let d = source.downcast_ref::<Diverged>().expect("a Diverged");
                assert!(d.iterations > 0 && d.to > 1e6 * d.from, "{d}");
                assert_eq!(d.q, 1e-3);
            }
            Err(e) => panic!("another error: {e}"),
            Ok(_) => panic!("converged"),
        }
        let f = AxisFilter::new(coder(1e-3), 1e-3).expect("converges");
        assert!(f.p_prior.iter().all(|v| v.is_finite()));
    }
}
