//! The kinematic transitions rewritten in place for a new time step.

use super::{
    KinematicLayout, check_positive, continuous_noise_block, kinematic_with, polynomial_block,
};
use crate::error::Result;
use crate::model::LinearTransition;
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, RealField};

/// [`kinematic_continuous`](super::kinematic_continuous) written into `transition` in
/// place: when `transition` is already a kinematic transition of `layout` (of any step), its
/// `F` and `Q` entries are rewritten for `dt` (no new value is built or moved: what a filter
/// over an irregular track does at every step); otherwise it is replaced by
/// `kinematic_continuous(layout, dt, spectral_density)`. Either way the result equals that
/// value; the same errors, and `transition` is left as it was on an error.
///
/// ```
/// use nalgebra::U4;
/// use trajpred_kalman::motion::{
///     KinematicLayout, StateOrder, kinematic_continuous, kinematic_continuous_in_place,
/// };
/// let l = KinematicLayout::new(2, 2, StateOrder::PositionsFirst)?;
/// let mut tr = kinematic_continuous::<f64, U4>(l, 1.0, 0.5)?;
/// kinematic_continuous_in_place(&mut tr, l, 2.5, 0.5)?;
/// assert_eq!(tr, kinematic_continuous::<f64, U4>(l, 2.5, 0.5)?);
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
pub fn kinematic_continuous_in_place<T: RealField + Copy, D: Dim>(
    transition: &mut LinearTransition<T, D>,
    layout: KinematicLayout,
    dt: f64,
    spectral_density: f64,
) -> Result<()>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    check_positive("dt", dt, false)?;
    check_positive("spectral_density", spectral_density, true)?;
    let (f_block, q_block) = (
        polynomial_block(dt),
        continuous_noise_block(layout.derivatives, dt, spectral_density),
    );
    if !transition.set_kinematic_blocks(layout, f_block, q_block) {
        *transition = kinematic_with(layout, f_block, q_block)?;
    }
    Ok(())
}
