//! [`FilterAllocator`]: one name for the storage a filter of state size `D` and observation
//! size `M` needs, so that generic code over static and dynamic sizes states its bounds once.

use nalgebra::Dim;
use nalgebra::allocator::Allocator;

/// The nalgebra allocators of a filter with a state of size `D` and an observation of size
/// `M`: vectors of both sizes and the `D x D`, `M x M`, `D x M` and `M x D` matrices. Every
/// allocator that provides those implements it, so a bound
/// `DefaultAllocator: FilterAllocator<D, M>` stands for the six.
///
/// ```
/// use nalgebra::{DefaultAllocator, Dim, OVector, RealField, U2, U4};
/// use trajpred_kalman::FilterAllocator;
///
/// fn observation_size<T: RealField, D: Dim, M: Dim>(z: &OVector<T, M>) -> usize
/// where
///     DefaultAllocator: FilterAllocator<D, M>,
/// {
///     z.nrows()
/// }
/// assert_eq!(observation_size::<f64, U4, U2>(&nalgebra::Vector2::new(1.0, 2.0)), 2);
/// ```
pub trait FilterAllocator<D: Dim, M: Dim>:
    Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<D, M> + Allocator<M, D>
{
}

impl<A, D: Dim, M: Dim> FilterAllocator<D, M> for A where
    A: Allocator<D>
        + Allocator<D, D>
        + Allocator<M>
        + Allocator<M, M>
        + Allocator<D, M>
        + Allocator<M, D>
{
}
