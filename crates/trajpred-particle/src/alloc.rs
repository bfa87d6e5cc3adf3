//! [`ParticleAllocator`]: one name for the storage a particle filter of state size `D` and
//! observation size `M` needs, so that the filters' generic code states its bounds once.

use nalgebra::allocator::Allocator;
use nalgebra::{Dim, Scalar};
use trajpred_kalman::FilterAllocator;

/// The nalgebra allocators of a particle filter with a state of size `D` and an observation
/// of size `M` (those of [`FilterAllocator`]), whose vectors and matrices of `T` the parallel
/// particle loops share and send between threads: a bound
/// `DefaultAllocator: ParticleAllocator<T, D, M>` stands for the six allocator bounds and for
/// `OVector<T, D>`, `OMatrix<T, D, D>`, `OVector<T, M>` and `OMatrix<T, M, M>` being
/// `Send + Sync`. Every allocator that provides those implements it (nalgebra's
/// `DefaultAllocator`, static and dynamic sizes, for any `T: RealField`).
///
/// ```
/// use nalgebra::{DefaultAllocator, Dim, OVector, RealField, U2, U4};
/// use trajpred_particle::ParticleAllocator;
///
/// fn spread<T: RealField, D: Dim, M: Dim>(v: OVector<T, D>) -> usize
/// where
///     DefaultAllocator: ParticleAllocator<T, D, M>,
/// {
///     std::thread::scope(|s| s.spawn(move || v.nrows()).join().unwrap())
/// }
/// assert_eq!(spread::<f64, U4, U2>(nalgebra::Vector4::zeros()), 4);
/// ```
pub trait ParticleAllocator<T: Scalar, D: Dim, M: Dim>:
    FilterAllocator<D, M>
    + Allocator<D, Buffer<T>: Send + Sync>
    + Allocator<D, D, Buffer<T>: Send + Sync>
    + Allocator<M, Buffer<T>: Send + Sync>
    + Allocator<M, M, Buffer<T>: Send + Sync>
{
}

impl<A, T: Scalar, D: Dim, M: Dim> ParticleAllocator<T, D, M> for A where
    A: FilterAllocator<D, M>
        + Allocator<D, Buffer<T>: Send + Sync>
        + Allocator<D, D, Buffer<T>: Send + Sync>
        + Allocator<M, Buffer<T>: Send + Sync>
        + Allocator<M, M, Buffer<T>: Send + Sync>
{
}
