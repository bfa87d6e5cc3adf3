//! # trajpred-sparse
//!
//! Least angle regression (LAR) and its lasso modification (Efron, Hastie, Johnstone and
//! Tibshirani, *Least angle regression*, Ann. Statist. 32(2), 2004), and the group sparse
//! coding of the MSTPM-GSKF paper (`docs/papers.md` A.2, A.3), usable on their own.
//!
//! - [`Lars`]: the whole path (knots, alphas, active order, coefficients at every knot) from a
//!   validating builder, `Lars::params().method(Method::Lasso).max_steps(20).fit(&x, &y)?`;
//! - [`GroupSparseCoder`]: `T` horizon models on the Hankel designs of a series, the matrix
//!   `A` (T x m), intercepts `b`, per-horizon residual variances and `predict(window)`.
//!
//! ## The algorithm
//!
//! Preprocessing (`docs/papers.md` A.2, both optional): centre `y` and every column of `X` (the
//! intercept), and scale every column to unit L2 norm. Constant columns are excluded
//! ([`ExclusionReason::ZeroVariance`]). On the standardised problem, with `beta = 0`,
//! residual `r = y` and correlations `c = X^T r`:
//!
//! 1. `C = max_j |c_j|`; every inactive `j` with `|c_j| >= C (1 - tie_tol)` enters the active
//!    set `A` with sign `s_j = sign(c_j)` (ties enter together); a column whose part
//!    orthogonal to the active columns vanishes is collinear and excluded for good.
//! 2. Equiangular direction (eq. 2.4-2.6): with `G_A = X_A^T X_A`,
//!    `A_A = (s^T G_A^{-1} s)^{-1/2}`, `w_A = A_A G_A^{-1} s`, `u_A = X_A w_A`, and
//!    `a = X^T u_A` (so `a_j = A_A s_j` on the active set).
//! 3. Step (eq. 2.13): `gamma = min+ over inactive j of {(C - c_j)/(A_A - a_j),
//!    (C + c_j)/(A_A + a_j)}`, or `C / A_A` (least squares on the active set) if smaller.
//!    Lasso (eq. 3.4-3.6): if some active `beta_j` reaches zero first, at
//!    `gamma_j = -beta_j / w_j`, the step stops there and `j` is dropped.
//! 4. `beta_A += gamma w_A`, `c -= gamma a`, `C -= gamma A_A`; record the knot with
//!    `alpha = C / n` (scikit-learn's convention) and repeat until every usable column is
//!    active (the end is least squares), the correlation vanishes, or a stopping rule
//!    (steps, `alpha_min`) ends the path.
//!
//! `G_A` is never inverted: its Cholesky factor is updated when a column enters (one
//! triangular solve) and downdated by Givens rotations when the lasso drops one. With
//! `p <= n` the Gram matrix `X^T X` is precomputed once ([`Gram`]), so a step costs
//! `O(p |A|)`; otherwise a step costs two passes over `X`. At the end of a full path the
//! least-squares point is polished by two sweeps of iterative refinement with residuals
//! recomputed from `X`. Decisions and their reasons: `docs/sparse.md`.
//!
//! ## Example: the diabetes data of the LAR paper
//!
//! ```
//! use nalgebra::DMatrix;
//! use trajpred_sparse::{Lars, Method, PathEvent};
//!
//! // 442 x 10 (age, sex, bmi, bp, s1..s6), stored with the scikit-learn fixtures
//! let text = std::fs::read_to_string(concat!(
//!     env!("CARGO_MANIFEST_DIR"),
//!     "/../../fixtures/sparse/lars_sklearn.json"
//! ))
//! .unwrap();
//! let json: serde_json::Value = serde_json::from_str(&text).unwrap();
//! let rows: Vec<Vec<f64>> = serde_json::from_value(json["diabetes"]["x_raw"].clone()).unwrap();
//! let y: Vec<f64> = serde_json::from_value(json["diabetes"]["target"].clone()).unwrap();
//! let x = DMatrix::from_fn(rows.len(), 10, |i, j| rows[i][j]);
//!
//! let lar = Lars::params().fit(&x, &y)?;
//! // bmi (2) enters first, then s5 (8), bp (3), s3 (6): Fig. 1 of the paper
//! assert_eq!(&lar.active()[..4], &[2, 8, 3, 6]);
//! assert_eq!(lar.n_knots(), 11);
//!
//! let lasso = Lars::params().method(Method::Lasso).fit(&x, &y)?;
//! // the lasso drops s3 (6) once and re-adds it: 12 steps instead of 10
//! assert!(lasso.events().contains(&PathEvent::Dropped { feature: 6, step: 10 }));
//! assert_eq!(lasso.n_knots(), 13);
//!
//! // both end at the least-squares fit, on the original scale with an intercept
//! let (a, b) = (lar.predict_row(&rows[0])?, lasso.predict_row(&rows[0])?);
//! assert!((a - b).abs() < 1e-9 * a.abs());
//! # Ok::<(), trajpred_sparse::Error>(())
//! ```
#![forbid(unsafe_code)]

mod cholesky;
pub mod error;
pub mod gsc;
mod kernels;
pub mod lars;

pub use error::{Error, Result};
pub use gsc::{GroupSparseCoder, GscParams};
pub use lars::{Exclusion, ExclusionReason, Gram, Lars, LarsParams, Method, PathEvent, StopReason};
