//! The kinematic transitions built from their per-axis blocks, and rebuilt in place: what a
//! filter over an irregular track does at every step, without searching `F` for its pattern.

use super::{Kinematic, KinematicShift, LinearTransition};
use crate::error::Result;
use crate::linalg::is_psd_sized;
use crate::motion::{KinematicLayout, StateOrder};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, RealField};

/// The checks of a kinematic transition's per-axis blocks (`k` = 2 or 3 derivatives, state
/// size `n`): `f_block` unit upper triangular with finite non-zero entries above the diagonal
/// (the damped velocity is not), `q_block` exactly symmetric and positive semi-definite with
/// the shift of the full size `n` (the same verdict as on the block-diagonal `Q`).
fn kinematic_blocks_ok<T: RealField + Copy>(
    k: usize,
    n: usize,
    f_block: &[[f64; 3]; 3],
    q_block: &[[f64; 3]; 3],
) -> bool {
    if !(2..=3).contains(&k) {
        return false;
    }
    let upper_ok = (0..k).all(|i| {
        (0..k).all(|j| match i.cmp(&j) {
            std::cmp::Ordering::Equal => f_block[i][j] == 1.0,
            std::cmp::Ordering::Greater => f_block[i][j] == 0.0,
            std::cmp::Ordering::Less => f_block[i][j].is_finite() && f_block[i][j] != 0.0,
        })
    });
    let symmetric = (0..k).all(|i| (0..i).all(|j| q_block[i][j] == q_block[j][i]));
    let at = |i: usize, j: usize| nalgebra::convert::<f64, T>(q_block[i][j]);
    upper_ok
        && symmetric
        && if k == 2 {
            is_psd_sized::<T, nalgebra::U2>(&nalgebra::Matrix2::from_fn(at), n)
        } else {
            is_psd_sized::<T, nalgebra::U3>(&nalgebra::Matrix3::from_fn(at), n)
        }
}

impl<T: RealField + Copy, D: Dim> LinearTransition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// The kinematic transition of `layout` from its per-axis blocks (`f_block` unit upper
    /// triangular, `q_block` symmetric), laid out in `f` and `q` by the caller
    /// ([`crate::motion`]): the same value as [`LinearTransition::new`]`(f, q)`, built
    /// without searching `F` for its pattern and with `Q` checked on one axis's block (the
    /// others are copies of it), so a filter over an irregularly sampled track can build
    /// one for every time step cheaply. Falls back to [`LinearTransition::new`] (and its
    /// errors) when `f_block` is not unit upper triangular with finite non-zero entries above
    /// the diagonal (no kinematic pattern: the damped velocity) or the block is not positive semi-definite.
    #[inline]
    pub(crate) fn from_kinematic_blocks(
        layout: KinematicLayout,
        f_block: [[f64; 3]; 3],
        q_block: [[f64; 3]; 3],
        f: OMatrix<T, D, D>,
        q: OMatrix<T, D, D>,
    ) -> Result<Self> {
        let k = layout.derivatives;
        let n = f.nrows();
        let shapes_ok = (2..=3).contains(&k)
            && layout.axes >= 1
            && n == layout.state_dim()
            && q.nrows() == n
            && q.ncols() == n;
        if !(shapes_ok && kinematic_blocks_ok::<T>(k, n, &f_block, &q_block)) {
            return Self::new(f, q);
        }
        // `N = F - I`: the entries above the diagonal
        let mut b = [[T::zero(); 3]; 3];
        for (i, row) in f_block.iter().enumerate() {
            for (j, &v) in row.iter().enumerate().skip(i + 1) {
                b[i][j] = nalgebra::convert::<f64, T>(v);
            }
        }
        // one axis: both orders are the same matrix, which the search reports as axis blocks
        let positions_first = layout.order == StateOrder::PositionsFirst && layout.axes > 1;
        let kinematic = match (k, positions_first) {
            (2, false) => Kinematic::Velocity(KinematicShift {
                block: [[b[0][0], b[0][1]], [b[1][0], b[1][1]]],
            }),
            (2, true) => Kinematic::VelocityPositionsFirst(KinematicShift {
                block: [[b[0][0], b[0][1]], [b[1][0], b[1][1]]],
            }),
            (_, false) => Kinematic::Acceleration(KinematicShift { block: b }),
            (_, true) => Kinematic::AccelerationPositionsFirst(KinematicShift { block: b }),
        };
        Ok(LinearTransition {
            f,
            q,
            shift: None,
            rows_in_place: false,
            kinematic: Some(kinematic),
        })
    }

    /// [`LinearTransition::from_kinematic_blocks`] written over `self` in place (no new
    /// value, no move) when `self` is already the kinematic transition of `layout` and the
    /// new blocks pass the same checks; `false` (and `self` untouched) otherwise, and the
    /// caller builds a new one.
    pub(crate) fn set_kinematic_blocks(
        &mut self,
        layout: KinematicLayout,
        f_block: [[f64; 3]; 3],
        q_block: [[f64; 3]; 3],
    ) -> bool {
        let k = layout.derivatives;
        let n = self.f.nrows();
        let positions_first = layout.order == StateOrder::PositionsFirst && layout.axes > 1;
        let same_pattern = n == layout.state_dim()
            && matches!(
                (&self.kinematic, k, positions_first),
                (Some(Kinematic::Velocity(_)), 2, false)
                    | (Some(Kinematic::VelocityPositionsFirst(_)), 2, true)
                    | (Some(Kinematic::Acceleration(_)), 3, false)
                    | (Some(Kinematic::AccelerationPositionsFirst(_)), 3, true)
            );
        if !(same_pattern && kinematic_blocks_ok::<T>(k, n, &f_block, &q_block)) {
            return false;
        }
        let mut b = [[T::zero(); 3]; 3];
        for axis in 0..layout.axes {
            for i in 0..k {
                for j in 0..k {
                    let (r, c) = (layout.index(axis, i), layout.index(axis, j));
                    if i != j {
                        self.f[(r, c)] = nalgebra::convert(f_block[i][j]);
                    }
                    self.q[(r, c)] = nalgebra::convert(q_block[i][j]);
                    if i < j {
                        b[i][j] = nalgebra::convert(f_block[i][j]);
                    }
                }
            }
        }
        match &mut self.kinematic {
            Some(Kinematic::Velocity(sh)) => sh.block = [[b[0][0], b[0][1]], [b[1][0], b[1][1]]],
            Some(Kinematic::VelocityPositionsFirst(sh)) => {
                sh.block = [[b[0][0], b[0][1]], [b[1][0], b[1][1]]]
            }
            Some(Kinematic::Acceleration(sh)) => sh.block = b,
            Some(Kinematic::AccelerationPositionsFirst(sh)) => sh.block = b,
            None => return false,
        }
        true
    }
}
