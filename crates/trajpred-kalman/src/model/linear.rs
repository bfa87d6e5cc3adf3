//! The linear models: [`LinearTransition`] (`F`, `Q`, with the structure of kinematic
//! transitions used to shortcut products) and [`LinearObservation`] (`H`, `R`).

use crate::error::Result;
use crate::linalg::{
    check_dim, check_finite, check_pd, check_psd, check_square, is_static, mul, mul_tr_sym_plus,
    mul_vec,
};
use crate::motion::{KinematicLayout, StateOrder};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, RealField};

/// A function `g` evaluated at the `2n + 1` symmetric sigma points `x`, `x + L_j`,
use super::{
    LinearObservationModel, LinearTransitionModel, Observation, ObservationJacobian, Transition,
    TransitionJacobian,
};

mod kinematic_build;

// ---- linear models --------------------------------------------------------------------------

/// The linear transition `x(k+1) = F x(k) + w`, `w ~ N(0, Q)`, validated at construction.
///
/// ```
/// use nalgebra::{Matrix2, Vector2};
/// use trajpred_kalman::{LinearTransition, Transition};
/// let tr = LinearTransition::new(Matrix2::new(1.0, 1.0, 0.0, 1.0), Matrix2::identity() * 0.1)?;
/// assert_eq!(tr.transition(&Vector2::new(1.0, 2.0))?, Vector2::new(3.0, 2.0));
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LinearTransition<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D, D>,
{
    f: OMatrix<T, D, D>,
    q: OMatrix<T, D, D>,
    /// `F = I + N` with few non-zeros in `N` outside the kinematic pattern: the non-zeros
    /// `(row, column, value)` of `N`; `None` for a general `F` and for the kinematic pattern
    /// (`kinematic`).
    shift: Option<Vec<(usize, usize, T)>>,
    /// No entry of `shift` reads a row of `X` that an earlier entry updates, so the row
    /// updates `F X = X + N X` can run in place (true for the kinematic models).
    rows_in_place: bool,
    /// `N` in the pattern of [`crate::motion::kinematic`].
    kinematic: Option<Kinematic<T>>,
}

/// The non-zeros `(i, j, a)` of `N` in `F = I + N`, visited with `j` ascending for each
/// row `i` (the order of the sums). The kinematic pattern also never visits an entry whose
/// `j` is the `i` of an earlier entry, so its row updates `F X = X + N X` run in place; a
/// general sparse `N` may, and then runs them on a copy (`rows_in_place`).
trait Shift<T> {
    /// Calls `f(i, j, a)` for every entry, `i, j < n`.
    fn for_each(&self, n: usize, f: impl FnMut(usize, usize, T));
}

/// A general sparse `N`: its entries as found, column by column.
struct SparseShift<'a, T>(&'a [(usize, usize, T)]);

impl<T: Copy> Shift<T> for SparseShift<'_, T> {
    #[inline(always)]
    fn for_each(&self, n: usize, mut f: impl FnMut(usize, usize, T)) {
        let last = n.saturating_sub(1);
        for &(i, j, a) in self.0 {
            // indices < n by construction; the `min` drops the bounds checks
            f(i.min(last), j.min(last), a);
        }
    }
}

/// `N` of the kinematic models: in each of the `n / K` axes, the strictly upper triangle
/// of the `K x K` block `block` (non-zero), at the indices of the axes' derivatives in the
/// order `POSITIONS_FIRST` (else axis blocks). With a static `n` the compiler knows every
/// index.
#[derive(Debug, Clone, Copy, PartialEq)]
struct KinematicShift<T, const K: usize, const POSITIONS_FIRST: bool> {
    block: [[T; K]; K],
}

impl<T: Copy, const K: usize, const POSITIONS_FIRST: bool> Shift<T>
    for KinematicShift<T, K, POSITIONS_FIRST>
{
    #[inline(always)]
    fn for_each(&self, n: usize, mut f: impl FnMut(usize, usize, T)) {
        let (layout, last) = (kinematic_layout::<K, POSITIONS_FIRST>(n), n - 1);
        for axis in 0..layout.axes {
            for d1 in 0..K {
                for d2 in d1 + 1..K {
                    let (i, j) = (
                        layout.index(axis, d1).min(last),
                        layout.index(axis, d2).min(last),
                    );
                    f(i, j, self.block[d1][d2]);
                }
            }
        }
    }
}

/// The layout of `n / K` axes of `K` derivatives in the order `POSITIONS_FIRST` (else axis
/// blocks); any number of axes (the kinematic models' constructors allow 1 to 3).
#[inline(always)]
fn kinematic_layout<const K: usize, const POSITIONS_FIRST: bool>(n: usize) -> KinematicLayout {
    KinematicLayout {
        axes: n / K,
        derivatives: K,
        order: if POSITIONS_FIRST {
            StateOrder::PositionsFirst
        } else {
            StateOrder::AxisBlocks
        },
    }
}

/// The kinematic patterns of `N` (two or three derivatives, either state order).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kinematic<T> {
    Velocity(KinematicShift<T, 2, false>),
    VelocityPositionsFirst(KinematicShift<T, 2, true>),
    Acceleration(KinematicShift<T, 3, false>),
    AccelerationPositionsFirst(KinematicShift<T, 3, true>),
}

/// Runs `$body` with `$sh` bound to the [`Shift`] of a [`Kinematic`] (one arm per pattern,
/// each compiled with its indices).
macro_rules! with_kinematic {
    ($kin:expr, $sh:ident => $body:expr) => {
        match $kin {
            Kinematic::Velocity($sh) => $body,
            Kinematic::VelocityPositionsFirst($sh) => $body,
            Kinematic::Acceleration($sh) => $body,
            Kinematic::AccelerationPositionsFirst($sh) => $body,
        }
    };
}

/// The block `N_b` when `F = I + N` has the kinematic pattern with `K` derivatives in the
/// order `POSITIONS_FIRST`: `N_b` read from the first axis, non-zero above its diagonal,
/// the same in every axis, every other entry of `N` zero.
fn kinematic_block<T, D, const K: usize, const POSITIONS_FIRST: bool>(
    f: &OMatrix<T, D, D>,
) -> Option<KinematicShift<T, K, POSITIONS_FIRST>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let n = f.nrows();
    if n == 0 || !n.is_multiple_of(K) {
        return None;
    }
    let layout = kinematic_layout::<K, POSITIONS_FIRST>(n);
    let axes = layout.axes;
    // (axis, derivative) of a state index, the inverse of `layout.index`
    let split = |i: usize| {
        if POSITIONS_FIRST {
            (i % axes, i / axes)
        } else {
            (i / K, i % K)
        }
    };
    let mut block = [[T::zero(); K]; K];
    for d1 in 0..K {
        for d2 in d1 + 1..K {
            block[d1][d2] = f[(layout.index(0, d1), layout.index(0, d2))];
            if block[d1][d2] == T::zero() {
                return None;
            }
        }
    }
    for c in 0..n {
        for r in 0..n {
            let ((ar, dr), (ac, dc)) = (split(r), split(c));
            let expected = if r == c {
                T::one()
            } else if ar == ac && dr < dc {
                block[dr][dc]
            } else {
                T::zero()
            };
            if f[(r, c)] != expected {
                return None;
            }
        }
    }
    Some(KinematicShift { block })
}

/// The kinematic pattern of `F`, if it has one.
fn kinematic_pattern<T, D>(f: &OMatrix<T, D, D>) -> Option<Kinematic<T>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    kinematic_block::<T, D, 2, false>(f)
        .map(Kinematic::Velocity)
        .or_else(|| kinematic_block::<T, D, 2, true>(f).map(Kinematic::VelocityPositionsFirst))
        .or_else(|| kinematic_block::<T, D, 3, false>(f).map(Kinematic::Acceleration))
        .or_else(|| kinematic_block::<T, D, 3, true>(f).map(Kinematic::AccelerationPositionsFirst))
}

/// `F x = x + N x` over the entries of `N`.
#[inline(always)]
fn shift_mean<T, D>(shift: &impl Shift<T>, x: &OVector<T, D>) -> OVector<T, D>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D>,
{
    let mut out = x.clone();
    shift.for_each(x.nrows(), |i, j, a| out[i] += a * x[j]);
    out
}

/// `F P F^T + (Q + Q^T) / 2` for `F = I + N` and a symmetric `P` (see
/// [`LinearTransitionModel::propagate_covariance`] of [`LinearTransition`]).
#[inline(always)]
fn shift_congruence<T, D>(
    shift: &impl Shift<T>,
    p: &OMatrix<T, D, D>,
    q: &OMatrix<T, D, D>,
    rows_in_place: bool,
) -> OMatrix<T, D, D>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let n = p.nrows();
    let half = nalgebra::convert::<f64, T>(0.5);
    let mut x = p.clone();
    shift.for_each(n, |i, j, a| {
        for r in 0..n {
            x[(r, i)] += a * p[(r, j)];
        }
    });
    let mut out = if rows_in_place {
        shift.for_each(n, |i, j, a| {
            for c in 0..n {
                let v = a * x[(j, c)];
                x[(i, c)] += v;
            }
        });
        x
    } else {
        let mut out = x.clone();
        shift.for_each(n, |i, j, a| {
            for c in 0..n {
                out[(i, c)] += a * x[(j, c)];
            }
        });
        out
    };
    for j in 0..n {
        for i in j..n {
            // `(Q + Q^T) / 2` formed here (the same value as stored, without its storage)
            let q_sym = (q[(j, i)] + q[(i, j)]) * half;
            let v = out[(j, i)] + q_sym;
            out[(j, i)] = v;
            out[(i, j)] = v;
        }
    }
    out
}

/// The off-diagonal non-zeros of `F` when its diagonal is all ones and there are at most
/// `n` of them (the kinematic models: `n / 2` for constant velocity, `n` for constant
/// acceleration); `None` otherwise.
fn unit_plus_sparse<T, D>(f: &OMatrix<T, D, D>) -> Option<Vec<(usize, usize, T)>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let n = f.nrows();
    let mut out = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let v = f[(i, j)];
            if i == j {
                if v != T::one() {
                    return None;
                }
            } else if v != T::zero() {
                out.push((i, j, v));
            }
        }
    }
    (out.len() <= n).then_some(out)
}

/// No entry of a sparse `N` reads a row that an earlier entry updates (see `rows_in_place`).
fn rows_update_in_place<T>(sh: &[(usize, usize, T)]) -> bool {
    sh.iter()
        .enumerate()
        .all(|(k, &(_, j, _))| sh[..k].iter().all(|&(i, _, _)| i != j))
}

impl<T: RealField + Copy, D: Dim> LinearTransition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// `F` and `Q`: both square of the same size, finite, `Q` symmetric positive
    /// semi-definite. Errors: [`DimensionMismatch`](trajpred_core::Error::DimensionMismatch),
    /// [`NonFinite`](trajpred_core::Error::NonFinite),
    /// [`NotPositiveDefinite`](trajpred_core::Error::NotPositiveDefinite) (`"Q"`).
    pub fn new(f: OMatrix<T, D, D>, q: OMatrix<T, D, D>) -> Result<Self> {
        let n = f.nrows();
        check_square(&f, n, "F")?;
        check_square(&q, n, "Q vs F")?;
        check_finite(&f, "F")?;
        check_psd(&q, "Q")?;
        let kinematic = kinematic_pattern(&f);
        // the kinematic pattern needs no list of entries (and no allocation)
        let shift = kinematic.is_none().then(|| unit_plus_sparse(&f)).flatten();
        let rows_in_place = shift.as_deref().is_some_and(rows_update_in_place);
        Ok(LinearTransition {
            f,
            q,
            shift,
            rows_in_place,
            kinematic,
        })
    }

    /// The transition matrix `F`.
    pub fn f(&self) -> &OMatrix<T, D, D> {
        &self.f
    }

    /// The process noise covariance `Q`.
    pub fn q(&self) -> &OMatrix<T, D, D> {
        &self.q
    }
}

impl<T: RealField + Copy, D: Dim> Transition<T, D> for LinearTransition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn transition(&self, x: &OVector<T, D>) -> Result<OVector<T, D>> {
        check_dim("state", self.f.ncols(), x.nrows())?;
        Ok(&self.f * x)
    }
    fn process_noise(&self) -> &OMatrix<T, D, D> {
        &self.q
    }
    /// Checked by the constructors; `Q` cannot change afterwards.
    fn check_process_noise(&self) -> Result<()> {
        Ok(())
    }
}

impl<T: RealField + Copy, D: Dim> TransitionJacobian<T, D> for LinearTransition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn transition_jacobian(&self, _x: &OVector<T, D>) -> Result<OMatrix<T, D, D>> {
        Ok(self.f.clone())
    }
}

impl<T: RealField + Copy, D: Dim> LinearTransitionModel<T, D> for LinearTransition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn transition_matrix(&self) -> &OMatrix<T, D, D> {
        &self.f
    }

    /// `x + N x` over the non-zeros of `N` when `F = I + N` is sparse: for the kinematic
    /// pattern (indices known at compile time for static sizes) and for a general sparse `N`
    /// when the size is known at run time only; `F x` for a general `N` of static size,
    /// whose unrolled product stays in registers (the same sums: the other terms are exact
    /// zeros added in the same column order).
    #[inline(always)]
    fn propagate_mean(&self, x: &OVector<T, D>) -> OVector<T, D> {
        if let Some(kin) = &self.kinematic {
            return with_kinematic!(kin, sh => shift_mean(sh, x));
        }
        match &self.shift {
            Some(shift) if !is_static::<D, D>() => shift_mean(&SparseShift(shift), x),
            _ => mul_vec(&self.f, x),
        }
    }

    /// With `F = I + N` sparse: `X = P F^T = P + P N^T` (column updates), `F X = X + N X`
    /// (row updates), then its upper triangle plus `(Q + Q^T) / 2`, read row by row and
    /// mirrored (exactly symmetric). For a symmetric `P` this is bit for bit the lower
    /// triangle of `(F P) F^T` formed in that order; this order writes whole columns before
    /// the row updates read them element by element, so no load waits for two earlier
    /// single-element stores (measured: about 3 % of the KF step). The row updates run in
    /// place when no entry of `N` reads a row that an earlier one updated (the kinematic
    /// models), on a copy otherwise. The kinematic pattern runs the same updates in the same
    /// order with indices the compiler knows for static sizes (the matrices stay in
    /// registers).
    #[inline(always)]
    fn propagate_covariance(&self, p: &OMatrix<T, D, D>) -> OMatrix<T, D, D> {
        if let Some(kin) = &self.kinematic {
            return with_kinematic!(kin, sh => shift_congruence(sh, p, &self.q, true));
        }
        let Some(shift) = &self.shift else {
            return mul_tr_sym_plus(&mul(&self.f, p), &self.f, &self.q);
        };
        shift_congruence(&SparseShift(shift), p, &self.q, self.rows_in_place)
    }

    fn has_structured_propagation(&self) -> bool {
        self.shift.is_some() || self.kinematic.is_some()
    }

    /// Every path mirrors: the sparse and kinematic updates and the dense products (static
    /// sizes) form the lower triangle and copy it; run-time sizes' dense products are
    /// symmetrised, `(a + b) / 2` on both sides, which is the same value.
    #[inline(always)]
    fn mirrors_covariance(&self) -> bool {
        true
    }
}

/// The linear observation `z = H x + v`, `v ~ N(0, R)`, validated at construction.
///
/// ```
/// use nalgebra::{Matrix1, Matrix1x2, Vector1, Vector2};
/// use trajpred_kalman::{LinearObservation, Observation};
/// let ob = LinearObservation::new(Matrix1x2::new(1.0, 0.0), Matrix1::new(0.5))?;
/// assert_eq!(ob.observe(&Vector2::new(3.0, 4.0))?, Vector1::new(3.0));
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LinearObservation<T: RealField, D: Dim, M: Dim>
where
    DefaultAllocator: Allocator<M> + Allocator<M, D> + Allocator<M, M>,
{
    h: OMatrix<T, M, D>,
    r: OMatrix<T, M, M>,
    /// The state component each row of `H` selects, when every row is a unit vector (a
    /// vector of the observation's size: no heap for static sizes, so a clone is a copy).
    selection: Option<OVector<usize, M>>,
}

impl<T: RealField + Copy, D: Dim, M: Dim> LinearObservation<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    /// `H` (`m x n`) and `R` (`m x m`, symmetric positive definite). Errors:
    /// [`DimensionMismatch`](trajpred_core::Error::DimensionMismatch),
    /// [`NonFinite`](trajpred_core::Error::NonFinite),
    /// [`NotPositiveDefinite`](trajpred_core::Error::NotPositiveDefinite) (`"R"`).
    pub fn new(h: OMatrix<T, M, D>, r: OMatrix<T, M, M>) -> Result<Self> {
        check_square(&r, h.nrows(), "R vs H")?;
        check_finite(&h, "H")?;
        check_pd(&r, "R")?;
        let selection = (0..h.nrows())
            .map(|a| {
                let row = h.row(a);
                let ones = row.iter().filter(|&&v| v == T::one()).count();
                let zeros = row.iter().filter(|&&v| v == T::zero()).count();
                if ones == 1 && zeros + 1 == row.len() {
                    row.iter().position(|&v| v == T::one())
                } else {
                    None
                }
            })
            .collect::<Option<Vec<usize>>>()
            .map(|idx| {
                OVector::<usize, M>::from_iterator_generic(
                    h.shape_generic().0,
                    nalgebra::Const::<1>,
                    idx,
                )
            });
        Ok(LinearObservation { h, r, selection })
    }

    /// The observation matrix `H`.
    pub fn h(&self) -> &OMatrix<T, M, D> {
        &self.h
    }

    /// The observation noise covariance `R`.
    pub fn r(&self) -> &OMatrix<T, M, M> {
        &self.r
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim> Observation<T, D, M> for LinearObservation<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    fn observe(&self, x: &OVector<T, D>) -> Result<OVector<T, M>> {
        check_dim("state", self.h.ncols(), x.nrows())?;
        Ok(&self.h * x)
    }
    fn observation_noise(&self) -> &OMatrix<T, M, M> {
        &self.r
    }
    /// Checked by [`LinearObservation::new`]; `R` cannot change afterwards.
    fn check_observation_noise(&self) -> Result<()> {
        Ok(())
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim> ObservationJacobian<T, D, M>
    for LinearObservation<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    fn observation_jacobian(&self, _x: &OVector<T, D>) -> Result<OMatrix<T, M, D>> {
        Ok(self.h.clone())
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim> LinearObservationModel<T, D, M>
    for LinearObservation<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    fn observation_matrix(&self) -> &OMatrix<T, M, D> {
        &self.h
    }
    fn selected_components(&self) -> Option<&[usize]> {
        self.selection.as_ref().map(|idx| idx.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::{StateOrder, constant_acceleration, constant_velocity};
    use nalgebra::{Const, Dyn};

    /// The constant-velocity (`derivatives` 2) or constant-acceleration (3) model.
    fn kinematic_model<D: Dim>(
        derivatives: usize,
        axes: usize,
        order: StateOrder,
    ) -> LinearTransition<f64, D>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let tr = if derivatives == 2 {
            constant_velocity(axes, 0.37, 0.7, order)
        } else {
            constant_acceleration(axes, 0.37, 0.7, order)
        };
        tr.expect("valid model")
    }

    /// A symmetric positive definite matrix whose entries use every bit of the mantissa.
    fn spd<D: Dim>(d: D) -> OMatrix<f64, D, D>
    where
        DefaultAllocator: Allocator<D, D>,
    {
        let a = OMatrix::<f64, D, D>::from_fn_generic(d, d, |i, j| {
            ((3 * i + 7 * j + 1) as f64).sin() * 1.3
        });
        &a * a.transpose() + OMatrix::<f64, D, D>::identity_generic(d, d) * 0.1
    }

    fn same_bits<D: Dim, C: Dim>(a: &OMatrix<f64, D, C>, b: &OMatrix<f64, D, C>) -> bool
    where
        DefaultAllocator: Allocator<D, C>,
    {
        a.iter()
            .zip(b.iter())
            .all(|(x, y)| x.to_bits() == y.to_bits())
    }

    /// Every kinematic model of size `D` is detected as its pattern, and the pattern's
    /// propagation is bit for bit the general sparse one (same sums in the same order) and
    /// within rounding of the dense products.
    fn check_kinematic<D: Dim>(d: D)
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let n = d.value();
        for derivatives in [2, 3] {
            for order in [StateOrder::AxisBlocks, StateOrder::PositionsFirst] {
                if !n.is_multiple_of(derivatives) {
                    continue;
                }
                let tr: LinearTransition<f64, D> =
                    kinematic_model(derivatives, n / derivatives, order);
                let kin = tr.kinematic.expect("a kinematic pattern");
                // one axis: both orders are the same matrix, detected as axis blocks
                let positions_first = order == StateOrder::PositionsFirst && n > derivatives;
                let found = match kin {
                    Kinematic::Velocity(_) => (2, false),
                    Kinematic::VelocityPositionsFirst(_) => (2, true),
                    Kinematic::Acceleration(_) => (3, false),
                    Kinematic::AccelerationPositionsFirst(_) => (3, true),
                };
                assert_eq!(found, (derivatives, positions_first), "n = {n}");
                assert!(tr.shift.is_none(), "the kinematic pattern keeps no list");
                let entries = unit_plus_sparse(&tr.f).expect("sparse");
                let sparse = SparseShift(&entries);
                assert!(rows_update_in_place(&entries));
                let p = spd(d);
                let x = OVector::<f64, D>::from_fn_generic(d, Const::<1>, |i, _| {
                    ((5 * i + 2) as f64).cos() * 3.1
                });
                let fast = tr.propagate_covariance(&p);
                let general = shift_congruence(&sparse, &p, &tr.q, true);
                assert!(
                    same_bits(&fast, &general),
                    "F P F^T + Q, n = {n}\n{fast}{general}"
                );
                let fast_mean = tr.propagate_mean(&x);
                assert!(
                    same_bits(&fast_mean, &shift_mean(&sparse, &x)),
                    "F x, n = {n}"
                );
                let dense = &tr.f * &p * tr.f.transpose() + (&tr.q + tr.q.transpose()) * 0.5;
                for (a, b) in fast.iter().zip(dense.iter()) {
                    assert!((a - b).abs() <= 1e-13 * b.abs().max(1.0), "{a} vs {b}");
                }
                for (a, b) in fast_mean.iter().zip((&tr.f * &x).iter()) {
                    assert!((a - b).abs() <= 1e-14 * b.abs().max(1.0), "{a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn kinematic_pattern_propagation_is_the_sparse_one_bit_for_bit() {
        check_kinematic(Const::<2>);
        check_kinematic(Const::<3>);
        check_kinematic(Const::<4>);
        check_kinematic(Const::<6>);
        check_kinematic(Const::<9>);
        for n in [2, 3, 4, 6, 9] {
            check_kinematic(Dyn(n));
        }
    }

    #[test]
    fn other_transitions_have_no_kinematic_pattern() {
        let cv: LinearTransition<f64, Const<4>> = kinematic_model(2, 2, StateOrder::AxisBlocks);
        let f = cv.f;
        let q = cv.q;
        let variants = [
            // a different time step in the second axis
            {
                let mut g = f;
                g[(2, 3)] = 0.5;
                g
            },
            // a coupling between the axes
            {
                let mut g = f;
                g[(0, 3)] = 0.1;
                g
            },
            // a zero coefficient (the sparse path leaves zeros out)
            {
                let mut g = f;
                g[(0, 1)] = 0.0;
                g[(2, 3)] = 0.0;
                g
            },
            // a lower-triangle entry
            {
                let mut g = f;
                g[(1, 0)] = 0.2;
                g
            },
            // a damped velocity (not unit-diagonal: the dense products)
            {
                let mut g = f;
                g[(1, 1)] = 0.99;
                g
            },
        ];
        for g in variants {
            let tr = LinearTransition::new(g, q).expect("valid model");
            assert!(tr.kinematic.is_none(), "{g}");
            let p = spd(Const::<4>);
            let dense = g * p * g.transpose() + q;
            for (a, b) in tr.propagate_covariance(&p).iter().zip(dense.iter()) {
                assert!((a - b).abs() <= 1e-13 * b.abs().max(1.0), "{a} vs {b}");
            }
        }
        // constant acceleration with the velocity-to-position entry of one axis changed
        let ca: LinearTransition<f64, Dyn> = kinematic_model(3, 2, StateOrder::PositionsFirst);
        let mut g = ca.f.clone();
        g[(1, 5)] = 0.1;
        assert!(
            LinearTransition::new(g, ca.q.clone())
                .expect("valid")
                .kinematic
                .is_none()
        );
        // the sizes that fit no pattern
        let one = LinearTransition::new(
            OMatrix::<f64, Const<1>, Const<1>>::identity(),
            OMatrix::<f64, Const<1>, Const<1>>::identity(),
        )
        .expect("valid model");
        assert!(one.kinematic.is_none());
    }
}
