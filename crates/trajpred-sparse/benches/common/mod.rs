//! The benches' data: a counter-based generator (splitmix64 + Box-Muller) that
//! `benches/sklearn_lars_path.py` reproduces in numpy, so both sides fit the same matrices.
use nalgebra::DMatrix;

const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

fn splitmix(k: u64) -> u64 {
    let mut z = k.wrapping_add(1).wrapping_mul(GOLDEN);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn uniform(k: u64) -> f64 {
    ((splitmix(k) >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
}

/// Standard normal number `k` of the stream (Box-Muller on uniforms 2k, 2k+1).
fn normal(k: u64) -> f64 {
    let (u1, u2) = (uniform(2 * k), uniform(2 * k + 1));
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// X[i, j] = normal(i p + j); beta_j = normal(n p + j); y = X beta + normal(n p + p + i).
pub fn data(n: usize, p: usize) -> (DMatrix<f64>, Vec<f64>) {
    let x = DMatrix::from_fn(n, p, |i, j| normal((i * p + j) as u64));
    let beta: Vec<f64> = (0..p).map(|j| normal((n * p + j) as u64)).collect();
    let y = (0..n)
        .map(|i| (0..p).map(|j| x[(i, j)] * beta[j]).sum::<f64>() + normal((n * p + p + i) as u64))
        .collect();
    (x, y)
}
