//! The range-bearing sensor ([`RangeBearing`]) and the angle wrap its residuals use.

use crate::error::{KalmanError, Result};
use crate::linalg::{check_dim, check_pd};
use crate::model::{Observation, ObservationJacobian, SigmaImages};
use crate::motion::check_positive;
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, Matrix2, OMatrix, OVector, RealField, U2, Vector2};
use std::any::Any;
use trajpred_core::Error as CoreError;
use wide::f64x4;

/// Range and bearing of the target from a sensor at `(sx, sy)`:
/// `h(x) = [sqrt(dx^2 + dy^2), atan2(dy, dx)]` with `dx = x[ix] - sx`, `dy = x[iy] - sy`.
/// The bearing residual is wrapped into `[-pi, pi)`, and averaged bearings are wrapped back,
/// so the filters handle targets crossing the `+-pi` line.
#[derive(Debug, Clone, PartialEq)]
pub struct RangeBearing<T: RealField> {
    sensor: Vector2<T>,
    x_index: usize,
    y_index: usize,
    r: Matrix2<T>,
}

impl<T: RealField + Copy> RangeBearing<T> {
    /// A sensor at `sensor`, reading the target position from state components `x_index`
    /// and `y_index`, with range variance `range_var` and bearing variance `bearing_var`
    /// (rad^2).
    pub fn new(
        sensor: Vector2<T>,
        x_index: usize,
        y_index: usize,
        range_var: f64,
        bearing_var: f64,
    ) -> Result<Self> {
        check_positive("range_var", range_var, false)?;
        check_positive("bearing_var", bearing_var, false)?;
        let r = Matrix2::new(
            nalgebra::convert(range_var),
            T::zero(),
            T::zero(),
            nalgebra::convert(bearing_var),
        );
        check_pd(&r, "R")?;
        if sensor.iter().any(|v| !v.is_finite()) {
            return Err(CoreError::NonFinite {
                what: "sensor position",
                index: sensor.iter().position(|v| !v.is_finite()).unwrap_or(0),
            }
            .into());
        }
        Ok(RangeBearing {
            sensor,
            x_index,
            y_index,
            r,
        })
    }

    fn offsets<D: Dim>(&self, x: &OVector<T, D>) -> Result<(T, T)>
    where
        DefaultAllocator: Allocator<D>,
    {
        let need = self.x_index.max(self.y_index) + 1;
        if x.nrows() < need {
            return Err(CoreError::DimensionMismatch {
                what: "state too short for the position indices",
                expected: need,
                got: x.nrows(),
            }
            .into());
        }
        Ok((
            x[self.x_index] - self.sensor.x,
            x[self.y_index] - self.sensor.y,
        ))
    }
}

/// Wraps an angle into `[-pi, pi)`.
pub fn wrap_angle<T: RealField + Copy>(a: T) -> T {
    // the common case, an angle already in range, without the (slow) floating remainder
    if a >= -T::pi() && a < T::pi() {
        return a;
    }
    let two_pi = T::two_pi();
    let r = (a + T::pi()) % two_pi;
    let r = if r < T::zero() { r + two_pi } else { r };
    r - T::pi()
}

impl<T: RealField + Copy, D: Dim> Observation<T, D, U2> for RangeBearing<T>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn observe(&self, x: &OVector<T, D>) -> Result<Vector2<T>> {
        let (dx, dy) = self.offsets(x)?;
        Ok(Vector2::new((dx * dx + dy * dy).sqrt(), dy.atan2(dx)))
    }
    fn observation_noise(&self) -> &Matrix2<T> {
        &self.r
    }
    fn observation_residual(&self, a: &Vector2<T>, b: &Vector2<T>) -> Vector2<T> {
        Vector2::new(a[0] - b[0], wrap_angle(a[1] - b[1]))
    }
    fn normalize_observation(&self, z: Vector2<T>) -> Vector2<T> {
        Vector2::new(z[0], wrap_angle(z[1]))
    }

    /// `h` depends on the position only: a pair of sigma points whose offset `L_j` is zero
    /// in both position components (every column after the position's, for a state
    /// ordered with the positions first in their blocks, such as `[x, vx, y, vy, w]`: 2 of
    /// the 5 pairs) has the centre's image exactly, without the `sqrt` and `atan2`.
    fn observe_sigma_points(
        &self,
        x: &OVector<T, D>,
        l: &OMatrix<T, D, D>,
    ) -> Result<SigmaImages<T, D, U2>>
    where
        DefaultAllocator: Allocator<U2, D>,
    {
        let n = x.nrows();
        check_dim("sigma-point spread", n, l.nrows())?;
        check_dim("sigma-point spread", n, l.ncols())?;
        let (dx, dy) = self.offsets(x)?;
        let d = x.shape_generic().0;
        let mut center = Vector2::zeros();
        let mut plus = OMatrix::<T, U2, D>::zeros_generic(nalgebra::Const::<2>, d);
        let mut minus = OMatrix::<T, U2, D>::zeros_generic(nalgebra::Const::<2>, d);
        // four images at a time (the bearings vectorised, [`bearings4`]): the centre, then
        // both points of every pair that moves the position
        let mut batch = Batch {
            y: [T::zero(); 4],
            x: [T::one(); 4],
            to: [0; 4],
            len: 0,
            center: &mut center,
            plus: &mut plus,
            minus: &mut minus,
        };
        batch.push(dx, dy, 0);
        for j in 0..n {
            let (ex, ey) = (l[(self.x_index, j)], l[(self.y_index, j)]);
            if ex != T::zero() || ey != T::zero() {
                batch.push(dx + ex, dy + ey, 2 * j + 1);
                batch.push(dx - ex, dy - ey, 2 * j + 2);
            }
        }
        batch.flush();
        for j in 0..n {
            let (ex, ey) = (l[(self.x_index, j)], l[(self.y_index, j)]);
            if ex == T::zero() && ey == T::zero() {
                plus.set_column(j, &center);
                minus.set_column(j, &center);
            }
        }
        Ok(SigmaImages::<T, D, U2> {
            center,
            plus,
            minus,
        })
    }
}

impl<T: RealField + Copy, D: Dim> ObservationJacobian<T, D, U2> for RangeBearing<T>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<U2, D>,
{
    fn observation_jacobian(&self, x: &OVector<T, D>) -> Result<OMatrix<T, U2, D>> {
        let (dx, dy) = self.offsets(x)?;
        let r2 = dx * dx + dy * dy;
        if r2 <= T::zero() || !r2.is_finite() {
            return Err(KalmanError::Undefined {
                what: "range-bearing Jacobian at the sensor position",
            });
        }
        let r = r2.sqrt();
        let d = x.shape_generic().0;
        let mut h = OMatrix::<T, U2, D>::zeros_generic(nalgebra::Const::<2>, d);
        h[(0, self.x_index)] = dx / r;
        h[(0, self.y_index)] = dy / r;
        h[(1, self.x_index)] = -dy / r2;
        h[(1, self.y_index)] = dx / r2;
        Ok(h)
    }
}

/// `atan2(y[i], x[i])` for four pairs. For `f64`, `wide`'s vectorised `atan2` (the polynomial
/// of Agner Fog's vector class library; within 2 ulp of glibc's `atan2` on 4 million random
/// points, [kalman.md](../../../../docs/kalman.md) "2026-12-07: the bearings four at a
/// time"), about 10 ns a lane against 25 ns a call; `T::atan2` one by one otherwise.
#[inline(always)]
fn bearings4<T: RealField + Copy>(y: [T; 4], x: [T; 4]) -> [T; 4] {
    if let (Some(y), Some(x)) = (
        (&y as &dyn Any).downcast_ref::<[f64; 4]>(),
        (&x as &dyn Any).downcast_ref::<[f64; 4]>(),
    ) {
        let b = f64x4::from(*y).atan2(f64x4::from(*x)).to_array();
        if let Some(b) = (&b as &dyn Any).downcast_ref::<[T; 4]>() {
            return *b;
        }
    }
    std::array::from_fn(|i| y[i].atan2(x[i]))
}

/// Up to four offsets from the sensor whose range and bearing are computed together, with
/// where each image goes: `0` the centre, `2j + 1` column `j` of `plus`, `2j + 2` of `minus`.
struct Batch<'a, T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<U2, D>,
{
    y: [T; 4],
    x: [T; 4],
    to: [usize; 4],
    len: usize,
    center: &'a mut Vector2<T>,
    plus: &'a mut OMatrix<T, U2, D>,
    minus: &'a mut OMatrix<T, U2, D>,
}

impl<T: RealField + Copy, D: Dim> Batch<'_, T, D>
where
    DefaultAllocator: Allocator<U2, D>,
{
    /// Adds the offset `(dx, dy)` for `to`, computing the batch when it is full.
    #[inline(always)]
    fn push(&mut self, dx: T, dy: T, to: usize) {
        self.x[self.len] = dx;
        self.y[self.len] = dy;
        self.to[self.len] = to;
        self.len += 1;
        if self.len == 4 {
            self.flush();
        }
    }

    /// Computes and writes the pending images (lanes past `len` hold finite leftovers or the
    /// initial `(1, 0)`, and are not written).
    #[inline(always)]
    fn flush(&mut self) {
        if self.len == 0 {
            return;
        }
        let bearings = bearings4(self.y, self.x);
        for (i, &bearing) in bearings.iter().enumerate().take(self.len) {
            let (dx, dy) = (self.x[i], self.y[i]);
            let image = Vector2::new((dx * dx + dy * dy).sqrt(), bearing);
            match self.to[i] {
                0 => *self.center = image,
                k if k % 2 == 1 => self.plus.set_column(k / 2, &image),
                k => self.minus.set_column(k / 2 - 1, &image),
            }
        }
        self.len = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Units in the last place between two finite `f64` of the same sign.
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            0
        } else {
            (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
        }
    }

    #[test]
    fn bearings4_are_within_2_ulp_of_atan2() {
        let mut s = 0x1234_5678_9ABC_DEF1u64;
        let mut uniform = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        // every quadrant, both axes and the origin with both signs of zero, then random
        // offsets over eight decades and ratios over two
        let mut pairs = vec![
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, 0.0),
            (3.0, 3.0),
            (-3.0, 3.0),
            (3.0, -3.0),
            (-3.0, -3.0),
            (1e-300, 1.0),
            (1.0, 1e-300),
        ];
        for _ in 0..100_000 {
            let scale = 10f64.powf(uniform() * 8.0 - 4.0);
            let y = (2.0 * uniform() - 1.0) * scale;
            let x = (2.0 * uniform() - 1.0) * scale * 10f64.powf(2.0 * uniform() - 1.0);
            pairs.push((y, x));
        }
        for chunk in pairs.chunks(4) {
            let mut y = [0.0; 4];
            let mut x = [1.0; 4];
            for (i, &(a, b)) in chunk.iter().enumerate() {
                (y[i], x[i]) = (a, b);
            }
            let got = bearings4(y, x);
            for i in 0..chunk.len() {
                let want = y[i].atan2(x[i]);
                assert!(
                    ulps(got[i], want) <= 2,
                    "atan2({}, {}) = {} against {want}",
                    y[i],
                    x[i],
                    got[i]
                );
            }
        }
        // the generic path (f32) is the scalar function itself
        let got = bearings4([1.0f32, -2.0, 0.5, 0.0], [2.0f32, 1.0, -3.0, -1.0]);
        assert_eq!(got[1], (-2.0f32).atan2(1.0));
    }
}
