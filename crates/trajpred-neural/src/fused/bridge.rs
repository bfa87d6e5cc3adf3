//! Between burn's tensors and the fused arithmetic: the `flex` backend's `f32` storage,
//! with or without autodiff.

use crate::error::{NeuralError, Result};
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::NoCheckpointing;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, NodeGuard, Ops, OpsKind};
use burn::backend::flex::FlexTensor;
use burn::backend::tensor::FloatTensor;
use burn::backend::{Autodiff, Flex};
use burn::tensor::{DType, Tensor, TensorData};
use std::borrow::Cow;
use std::marker::PhantomData;

/// An autodiff float primitive of the flex backend.
pub(crate) type AdTensor = FloatTensor<Autodiff<Flex>>;

/// A tensor's primitive: tracked by autodiff (on an autodiff device) or plain flex.
pub(crate) enum Prim {
    /// On an autodiff device (tracked or not).
    Ad(AdTensor),
    /// On the plain flex device (inference).
    Plain(FlexTensor),
}

fn not_flex(what: &str) -> NeuralError {
    NeuralError::Tensor {
        reason: format!("fused op: {what} is not an f32 tensor of the flex backend"),
    }
}

/// The primitive of a tensor of the flex backend (with or without autodiff).
pub(crate) fn prim<const D: usize>(t: Tensor<D>, what: &str) -> Result<Prim> {
    if t.dtype() != DType::F32 {
        return Err(not_flex(what));
    }
    match t.clone().try_into_primitive::<Autodiff<Flex>>() {
        Ok(p) => Ok(Prim::Ad(p)),
        Err(_) => t
            .try_into_primitive::<Flex>()
            .map(Prim::Plain)
            .map_err(|_| not_flex(what)),
    }
}

/// The `f32` values of a flex tensor in row-major order: borrowed when it is contiguous.
pub(crate) fn values<'a>(t: &'a FlexTensor, what: &str) -> Result<Cow<'a, [f32]>> {
    if t.dtype() != DType::F32 {
        return Err(not_flex(what));
    }
    match t.as_slice::<f32>() {
        Some(s) => Ok(Cow::Borrowed(s)),
        None => t
            .to_contiguous()
            .as_slice::<f32>()
            .map(|s| Cow::Owned(s.to_vec()))
            .ok_or_else(|| not_flex(what)),
    }
}

/// A flex tensor an op's backward state keeps (a shared handle, no copy of the values).
#[derive(Clone)]
pub(crate) struct Kept(FlexTensor);

impl Kept {
    /// Keeps `t`.
    pub(crate) fn new(t: &FlexTensor) -> Self {
        Kept(t.clone())
    }

    /// The `f32` values, row-major (see [`values`]).
    pub(crate) fn values(&self, what: &str) -> Result<Cow<'_, [f32]>> {
        values(&self.0, what)
    }
}

impl std::fmt::Debug for Kept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Kept({:?})", self.0.layout().shape())
    }
}

/// A contiguous flex tensor owning `v`.
pub(crate) fn flex(v: Vec<f32>, shape: &[usize]) -> FlexTensor {
    FlexTensor::from_data(TensorData::new(v, shape.to_vec()))
}

/// Primitives split into values and node guards, all on the autodiff device or all plain.
pub(crate) enum Inputs {
    /// On the autodiff device: the inner flex primitives and the guards of their nodes.
    Ad(Vec<FlexTensor>, Vec<NodeGuard>),
    /// Plain flex tensors.
    Plain(Vec<FlexTensor>),
}

/// Splits the primitives of an op's inputs. When any input is on the autodiff device, the
/// plain ones join as untracked constants (as burn's own operations treat them), so a
/// network of plain weights (`Module::valid`) reading autodiff data still runs fused.
pub(crate) fn inputs(prims: Vec<Prim>) -> Inputs {
    if prims.iter().all(|p| matches!(p, Prim::Plain(_))) {
        return Inputs::Plain(
            prims
                .into_iter()
                .filter_map(|p| match p {
                    Prim::Plain(t) => Some(t),
                    Prim::Ad(_) => None,
                })
                .collect(),
        );
    }
    let (flexes, guards) = prims
        .into_iter()
        .map(|p| match p {
            Prim::Ad(t) => t.into_parts(),
            Prim::Plain(t) => AdTensor::new(t).into_parts(),
        })
        .unzip();
    Inputs::Ad(flexes, guards)
}

/// Runs a fused op of `N` inputs: `run` computes the output (`shape`) and the state its
/// backward needs from the inputs' flex tensors. With plain inputs the output is a plain
/// tensor; with autodiff inputs it is registered with `op` as its backward step.
pub(crate) fn apply<Op, const N: usize, const D: usize>(
    op: Op,
    prims: Vec<Prim>,
    shape: &[usize],
    what: &str,
    run: impl FnOnce(&[FlexTensor]) -> Result<(Vec<f32>, Op::State)>,
) -> Result<Tensor<D>>
where
    Op: Backward<Flex, N>,
{
    match inputs(prims) {
        Inputs::Plain(t) => {
            let (out, _) = run(&t)?;
            Ok(Tensor::from_primitive::<Flex>(flex(out, shape)))
        }
        Inputs::Ad(t, guards) => {
            let (out, state) = run(&t)?;
            let nodes: [NodeGuard; N] = guards.try_into().map_err(|_| NeuralError::Tensor {
                reason: format!("{what}: expected {N} inputs"),
            })?;
            let out = flex(out, shape);
            let ad = match op
                .prepare::<NoCheckpointing>(nodes)
                .compute_bound()
                .stateful()
            {
                OpsKind::Tracked(prep) => prep.finish(state, out),
                OpsKind::UnTracked(prep) => prep.finish(out),
            };
            Ok(Tensor::from_primitive::<Autodiff<Flex>>(ad))
        }
    }
}

/// Registers `grad` (`shape`) for a parent node if it requires a gradient.
pub(crate) fn register(
    grads: &mut Gradients,
    parent: Option<&burn::backend::autodiff::NodeId>,
    grad: Vec<f32>,
    shape: &[usize],
) {
    if let Some(id) = parent {
        grads.register::<Flex>(*id, flex(grad, shape));
    }
}

/// The state a fused op of `N` inputs keeps for its backward step, which knows the inputs'
/// gradients: with it, [`FusedBackward`] is the op's autodiff node.
pub(crate) trait FusedState<const N: usize>:
    Clone + Send + std::fmt::Debug + 'static
{
    /// Names the op's output gradient in errors.
    const WHAT: &'static str;

    /// The shapes of the op's inputs.
    fn shapes(&self) -> [Vec<usize>; N];

    /// The inputs' gradients (row-major, of [`FusedState::shapes`]) from the output gradient
    /// `g`; `need[i]` says whether input `i` needs one (an empty vector stands for none).
    fn gradients(&self, g: &[f32], need: [bool; N]) -> Result<[Vec<f32>; N]>;
}

/// The autodiff node of a fused op whose state is `S`. Its backward step hands the output
/// gradient to [`FusedState::gradients`] and registers each input's gradient for its node.
/// An error there (an internal inconsistency, not reachable with the shapes checked in the
/// forward pass) registers NaN gradients, which the training loop reports as divergence.
#[derive(Debug)]
pub(crate) struct FusedBackward<S>(PhantomData<S>);

impl<S> FusedBackward<S> {
    /// The node.
    pub(crate) fn new() -> Self {
        FusedBackward(PhantomData)
    }
}

impl<S: FusedState<N>, const N: usize> Backward<Flex, N> for FusedBackward<S> {
    type State = S;

    fn backward(self, ops: Ops<S, N>, grads: &mut Gradients, _: &mut Checkpointer) {
        let Ops {
            parents,
            node,
            state,
        } = ops;
        let grad: FlexTensor = grads.consume::<Flex>(&node);
        let ids = parents.each_ref().map(|p| p.as_ref().map(|n| n.id));
        let shapes = state.shapes();
        let result = values(&grad, S::WHAT)
            .and_then(|g| state.gradients(&g, ids.each_ref().map(Option::is_some)));
        let parts = result.unwrap_or_else(|_| {
            shapes
                .each_ref()
                .map(|shape| vec![f32::NAN; shape.iter().product()])
        });
        for ((id, g), shape) in ids.iter().zip(parts).zip(&shapes) {
            register(grads, id.as_ref(), g, shape);
        }
    }
}
