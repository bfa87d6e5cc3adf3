//! Adam in one pass over each parameter's values (with `TrainConfig::fused`).
//!
//! burn's `Adam` updates a parameter through about a dozen tensor operations (the two
//! moments, their bias corrections, the square root, the division, the step), each a pass
//! over the values with its own output; on the LSTM epoch's 55 000 parameters that was a
//! seventh of the fused epoch. [`FusedAdam`] does the same `f32` operations in the same
//! order element by element, in one loop: its updates are burn's bit for bit (checked in
//! `fused/tests.rs`). Without weight decay and AMSGrad (which the training loop does not
//! use); tensors that are not contiguous `f32` flex tensors go through burn's `Adam`.

use super::bridge;
use burn::backend::Flex;
use burn::backend::flex::FlexTensor;
use burn::optim::{Adam, AdamConfig, AdamState, AdaptiveMomentumState, LearningRate, Optimizer};
use burn::tensor::{DType, Device, Tensor};
use std::ops::Range;

/// `beta_1` of burn's `AdamConfig` default, which the training loop uses.
const BETA_1: f32 = 0.9;
/// `beta_2` of burn's `AdamConfig` default.
const BETA_2: f32 = 0.999;

/// Adam with burn's arithmetic and state (`AdamState`), one loop per parameter.
#[derive(Clone)]
pub(crate) struct FusedAdam {
    epsilon: f32,
    /// burn's own, for tensors the loop does not take.
    reference: Adam,
}

impl FusedAdam {
    /// Adam with `epsilon` and burn's default betas.
    pub(crate) fn new(epsilon: f32) -> Self {
        FusedAdam {
            epsilon,
            reference: Self::config(epsilon).build(),
        }
    }

    /// The `AdamConfig` whose optimizer this one reproduces.
    pub(crate) fn config(epsilon: f32) -> AdamConfig {
        AdamConfig::new()
            .with_beta_1(BETA_1)
            .with_beta_2(BETA_2)
            .with_epsilon(epsilon)
    }
}

/// The contiguous `f32` values of a flex tensor that owns exactly them (its whole storage,
/// in order): what [`FusedAdam`] updates in place.
fn whole(t: &FlexTensor, n: usize) -> bool {
    t.dtype() == DType::F32
        && t.as_slice::<f32>().is_some_and(|s| s.len() == n)
        && t.storage::<f32>().len() == n
}

/// The primitives of one step: parameter, gradient (with the range of its storage that
/// holds its values), and the step count and moments of the state (none at the first step).
type Prims = (
    FlexTensor,
    (FlexTensor, Range<usize>),
    Option<(usize, FlexTensor, FlexTensor)>,
);

impl FusedAdam {
    /// The flex primitives of a step, when the parameter and the moments are whole `f32`
    /// flex tensors, the gradient a contiguous one, all of the parameter's size, and the
    /// state has no AMSGrad moment; `None` sends the step to burn's
    /// `Adam`.
    fn prims<const D: usize>(
        tensor: &Tensor<D>,
        grad: &Tensor<D>,
        state: Option<&AdamState<D>>,
    ) -> Option<Prims> {
        let flex = Device::flex();
        let prim = |t: &Tensor<D>| {
            (t.dtype() == DType::F32 && t.device() == flex)
                .then(|| t.clone().try_into_primitive::<Flex>().ok())
                .flatten()
        };
        let n = tensor.shape().num_elements();
        let (p, g) = (prim(tensor)?, prim(grad)?);
        let moments = match state.map(|s| &s.momentum) {
            Some(m) if m.max_moment_2.is_none() => {
                Some((m.time, prim(&m.moment_1)?, prim(&m.moment_2)?))
            }
            Some(_) => return None,
            None => None,
        };
        // the gradient is only read: a contiguous view (a slice of the packed parameters'
        // gradient, in the KFU model) will do
        let (start, end) = g.layout().contiguous_offsets()?;
        let all_whole = whole(&p, n)
            && end - start == n
            && moments
                .as_ref()
                .is_none_or(|(_, a, b)| whole(a, n) && whole(b, n));
        all_whole.then_some((p, (g, start..end), moments))
    }

    /// One step over the primitives, in burn's order of `f32` operations, updating the
    /// parameter and the moments in place (copied first if something else still holds
    /// them); returns the parameter and the state.
    fn update(
        &self,
        lr: LearningRate,
        prims: Prims,
        shape: &[usize],
    ) -> (FlexTensor, usize, FlexTensor, FlexTensor) {
        let (mut p, g, moments) = prims;
        let (g, range) = g;
        let g = &g.storage::<f32>()[range];
        let (f1, f2) = (1.0 - BETA_1, 1.0 - BETA_2);
        let (time, m1, m2) = match moments {
            Some((time, mut m1, mut m2)) => {
                for (m, &g) in m1.storage_mut::<f32>().iter_mut().zip(g) {
                    *m = *m * BETA_1 + g * f1;
                }
                for (m, &g) in m2.storage_mut::<f32>().iter_mut().zip(g) {
                    *m = *m * BETA_2 + (g * g) * f2;
                }
                (time + 1, m1, m2)
            }
            None => {
                let m1: Vec<f32> = g.iter().map(|&g| g * f1).collect();
                let m2: Vec<f32> = g.iter().map(|&g| (g * g) * f2).collect();
                (1, bridge::flex(m1, shape), bridge::flex(m2, shape))
            }
        };
        // burn's `powi` takes the step count as `i32`
        let t = i32::try_from(time).unwrap_or(i32::MAX);
        let bias_correction2_sqrt = (1.0 - BETA_2.powi(t)).sqrt();
        let combined = bias_correction2_sqrt / (1.0 - BETA_1.powi(t));
        let eps = self.epsilon * bias_correction2_sqrt;
        let lr = lr as f32;
        let (a, b) = (m1.storage::<f32>(), m2.storage::<f32>());
        for ((v, &a), &b) in p.storage_mut::<f32>().iter_mut().zip(a).zip(b) {
            *v -= (a * combined) / (b.sqrt() + eps) * lr;
        }
        (p, time, m1, m2)
    }
}

impl Optimizer for FusedAdam {
    type State<const D: usize> = AdamState<D>;

    fn step<const D: usize>(
        &self,
        lr: LearningRate,
        tensor: Tensor<D>,
        grad: Tensor<D>,
        state: Option<Self::State<D>>,
    ) -> (Tensor<D>, Option<Self::State<D>>) {
        let Some(prims) = Self::prims(&tensor, &grad, state.as_ref()) else {
            return self.reference.step(lr, tensor, grad, state);
        };
        // the primitives become the only handles on the values, to be updated in place
        let shape = tensor.dims();
        drop((tensor, grad, state));
        let (p, time, m1, m2) = self.update(lr, prims, &shape);
        let t = |f: FlexTensor| Tensor::<D>::from_primitive::<Flex>(f);
        let momentum = AdaptiveMomentumState::new(time, t(m1), t(m2));
        (t(p), Some(AdamState::new(momentum)))
    }

    fn to_device<const D: usize>(state: Self::State<D>, device: &Device) -> Self::State<D> {
        <Adam as Optimizer>::to_device(state, device)
    }
}
