//! The checks of the fused ops: over random shapes, seeds, weights and inputs, every
//! gradient of every fused op equals burn's autodiff through the composed reference
//! (`FusedLstm::forward`, burn's `nn::Rnn`, `KfuCell::run` without a spec) within `1e-5` of the largest
//! magnitude of that gradient (f32); the backward passes equal central finite differences
//! of the forward passes in f64; and the outputs agree within `1e-5` (f32).

use super::recurrent::{self, Cell};
use super::{adam, head, kfu};
use crate::arch::{Architecture, FusedLstm, LstmArch, RecurrentLayers, RnnArch};
use crate::config::{Activation, TrainConfig};
use crate::kfu::{KfuCell, KfuConfig};
use crate::train::{device, read, rng};
use burn::grad_clipping::GradientClippingConfig;
use burn::module::{Module, ModuleMapper, ModuleVisitor, Param};
use burn::optim::{GradientsParams, ModuleOptimizer};
use burn::tensor::{Device, Tensor, TensorData};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

/// Gradient tolerance relative to the largest magnitude of the reference gradient (f32).
const GRAD_TOL: f32 = 1e-5;
/// Output tolerance relative to the largest magnitude of the reference output (f32).
const OUT_TOL: f32 = 1e-5;

/// Fills every parameter with uniform values in `[-scale, scale]` (non-zero biases too).
struct Fill<'a> {
    rng: &'a mut ChaCha8Rng,
    scale: f64,
}

impl ModuleMapper for Fill<'_> {
    fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
        let (rng, scale) = (&mut *self.rng, self.scale);
        param.map(|t| {
            let dims = t.dims();
            let n = dims.iter().product();
            let v = uniform(rng, n, scale);
            Tensor::<D>::from_data(TensorData::new(v, dims), &t.device()).require_grad()
        })
    }
}

/// Collects the gradient of every parameter, in visiting order.
struct Collect<'a> {
    grads: &'a GradientsParams,
    out: Vec<Vec<f32>>,
}

impl ModuleVisitor for Collect<'_> {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        let g = self
            .grads
            .get::<D>(param.id)
            .map(|g| read(g).unwrap_or_default())
            .unwrap_or_default();
        self.out.push(g);
    }
}

fn uniform(rng: &mut ChaCha8Rng, n: usize, scale: f64) -> Vec<f32> {
    (0..n)
        .map(|_| ((rng.random::<f64>() * 2.0 - 1.0) * scale) as f32)
        .collect()
}

fn tensor<const D: usize>(v: Vec<f32>, dims: [usize; D], device: &Device) -> Tensor<D> {
    Tensor::from_data(TensorData::new(v, dims), device)
}

/// `max |a - b| <= tol * max |b|` (with a floor for all-zero references).
fn assert_close(a: &[f32], b: &[f32], tol: f32, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    let scale = b.iter().fold(0f32, |m, v| m.max(v.abs())).max(1e-6);
    let err = a.iter().zip(b).fold(0f32, |m, (x, y)| m.max((x - y).abs()));
    assert!(
        err <= tol * scale,
        "{what}: max |fused - reference| = {err:e} > {tol:e} x {scale:e}"
    );
}

/// A parameter's gradient: burn's autodiff has none for a parameter the output does not
/// depend on (`W_hh` over a single step), where the fused op registers zeros.
fn assert_param(fused: &[f32], reference: &[f32], what: &str) {
    if reference.is_empty() {
        assert!(
            fused.iter().all(|v| *v == 0.0),
            "{what}: expected no gradient"
        );
    } else {
        assert_close(fused, reference, GRAD_TOL, what);
    }
}

fn gradients<M: Module>(loss: Tensor<1>, module: &M) -> Vec<Vec<f32>> {
    let grads = GradientsParams::from_grads(loss.backward(), module);
    let mut c = Collect {
        grads: &grads,
        out: Vec::new(),
    };
    module.visit(&mut c);
    c.out
}

/// One LSTM layer: the fused op against the composed layer, gradients of the input and of
/// every weight, over random shapes and seeds.
#[test]
fn lstm_layer_gradients_equal_the_composed_reference() {
    let device = device();
    for seed in 0..24u64 {
        let mut r = rng(seed, 7);
        let (b, t) = (r.random_range(1..6), r.random_range(1..9));
        let (d, h) = (r.random_range(1..6), r.random_range(1..10));
        let layer = FusedLstm::new(d, h, &device).map(&mut Fill {
            rng: &mut r,
            scale: 0.6,
        });
        let xv = uniform(&mut r, b * t * d, 1.5);
        let wv = uniform(&mut r, b * t * h, 1.0);
        let w = tensor(wv, [b, t, h], &device);
        let x_ref = tensor(xv.clone(), [b, t, d], &device).require_grad();
        let x_fused = tensor(xv, [b, t, d], &device).require_grad();
        let (out_ref, _) = layer.forward(x_ref.clone(), None);
        let (w_ih, bias, w_hh) = layer.fused_params();
        let out =
            recurrent::layer(Cell::Lstm, x_fused.clone(), w_ih, bias, w_hh).expect("flex tensors");
        let what = format!("seed {seed}: B {b} T {t} D {d} H {h}");
        assert_close(
            &read(out.clone()).expect("f32"),
            &read(out_ref.clone()).expect("f32"),
            OUT_TOL,
            &format!("{what}: output"),
        );
        let loss_ref = (out_ref * w.clone()).sum();
        let loss = (out * w).sum();
        let g_ref_all = loss_ref.backward();
        let g_all = loss.backward();
        let gx_ref = read(x_ref.grad(&g_ref_all).expect("input gradient")).expect("f32");
        let gx = read(x_fused.grad(&g_all).expect("input gradient")).expect("f32");
        assert_close(&gx, &gx_ref, GRAD_TOL, &format!("{what}: dx"));
        let g_ref = GradientsParams::from_grads(g_ref_all, &layer);
        let g = GradientsParams::from_grads(g_all, &layer);
        for (k, (a, e)) in collect(&g, &layer)
            .iter()
            .zip(collect(&g_ref, &layer))
            .enumerate()
        {
            assert_param(a, &e, &format!("{what}: parameter {k}"));
        }
    }
}

fn collect<M: Module>(grads: &GradientsParams, module: &M) -> Vec<Vec<f32>> {
    let mut c = Collect {
        grads,
        out: Vec::new(),
    };
    module.visit(&mut c);
    c.out
}

/// Stacked layers and a head (the windowed LSTM and RNN models' networks): fused and
/// composed forward passes give the same outputs and the same gradient of every parameter.
#[test]
fn lstm_stack_gradients_equal_the_composed_reference() {
    stack_gradients_equal_the_composed_reference(LstmArch, 8);
}

/// [`lstm_stack_gradients_equal_the_composed_reference`] for the Elman RNN (burn's
/// `nn::Rnn` the reference).
#[test]
fn rnn_stack_gradients_equal_the_composed_reference() {
    stack_gradients_equal_the_composed_reference(RnnArch, 18);
}

fn stack_gradients_equal_the_composed_reference<A: Architecture>(
    make: fn(RecurrentLayers) -> A,
    stream: u64,
) {
    let device = device();
    for seed in 0..10u64 {
        let mut r = rng(seed, stream);
        let n_layers = r.random_range(1..4);
        let layers: Vec<usize> = (0..n_layers).map(|_| r.random_range(1..9)).collect();
        let fc: Vec<usize> = (0..r.random_range(0..2))
            .map(|_| r.random_range(1..6))
            .collect();
        let arch = make(RecurrentLayers {
            layers,
            fc,
            activation: Activation::Tanh,
        });
        let (b, m, f, out) = (
            r.random_range(1..5),
            r.random_range(1..7),
            r.random_range(1..4),
            r.random_range(1..4),
        );
        let net = arch.build(f, m, out, &device).map(&mut Fill {
            rng: &mut r,
            scale: 0.5,
        });
        let x = tensor(uniform(&mut r, b * m * f, 1.5), [b, m, f], &device);
        let w = tensor(uniform(&mut r, b * out, 1.0), [b, out], &device);
        let cfg = TrainConfig::new(1e-3);
        let fused = arch.configure(net.clone(), &cfg.clone().with_fused(true));
        let composed = arch.configure(net, &cfg.with_fused(false));
        let y = arch.forward(&fused, x.clone());
        let y_ref = arch.forward(&composed, x);
        let what = format!("seed {seed}: {arch:?} B {b} m {m} f {f}");
        assert_close(
            &read(y.clone()).expect("f32"),
            &read(y_ref.clone()).expect("f32"),
            OUT_TOL,
            &format!("{what}: output"),
        );
        let g = gradients((y * w.clone()).sum(), &fused);
        let g_ref = gradients((y_ref * w).sum(), &composed);
        assert_eq!(g.len(), g_ref.len());
        for (k, (a, e)) in g.iter().zip(&g_ref).enumerate() {
            assert_param(a, e, &format!("{what}: parameter {k}"));
        }
    }
}

/// The whole unrolled KFU filter: fused against composed, the gradient of every parameter
/// (LSTM layers, head, `log Q`, `log R`) and of the observations, with and without
/// prediction steps past the last observation.
#[test]
fn kfu_gradients_equal_the_composed_reference() {
    let device = device();
    let acts = [Activation::Relu, Activation::Tanh, Activation::Sigmoid];
    for seed in 0..16u64 {
        let mut r = rng(seed, 9);
        let d = r.random_range(1..4);
        let cfg = KfuConfig {
            layers: (0..r.random_range(1..3))
                .map(|_| r.random_range(1..7))
                .collect(),
            fc: (0..r.random_range(0..3))
                .map(|_| r.random_range(1..6))
                .collect(),
            activation: acts[r.random_range(0..3)],
            ..KfuConfig::default()
        };
        let (b, c, extra) = (
            r.random_range(1..5),
            r.random_range(2..9),
            r.random_range(0..3),
        );
        let p0 = 0.2 + r.random::<f64>();
        let cell = KfuCell::new(&cfg, d, &device).map(&mut Fill {
            rng: &mut r,
            scale: 0.5,
        });
        let spec = kfu::Spec {
            d,
            layers: cfg.layers.clone(),
            fc: cfg.fc.clone(),
            activation: cfg.activation,
        };
        let zv = uniform(&mut r, b * c * d, 1.5);
        let n = c - 1;
        let wp = tensor(uniform(&mut r, b * n * d, 1.0), [b, n, d], &device);
        let wq = tensor(uniform(&mut r, b * n * d, 1.0), [b, n, d], &device);
        let wa: Vec<Tensor<2>> = (0..extra)
            .map(|_| tensor(uniform(&mut r, b * d, 1.0), [b, d], &device))
            .collect();
        let what = format!("seed {seed}: {cfg:?} d {d} B {b} c {c} extra {extra}");
        let mut results = Vec::new();
        for s in [Some(&spec), None] {
            let z = tensor(zv.clone(), [b, c, d], &device).require_grad();
            let run = cell.run(z.clone(), p0, extra, s);
            let mut outs = vec![
                read(run.priors.clone()).expect("f32"),
                read(run.posteriors.clone()).expect("f32"),
            ];
            let mut loss = (run.priors * wp.clone()).sum() + (run.posteriors * wq.clone()).sum();
            for (a, w) in run.ahead.into_iter().zip(&wa) {
                outs.push(read(a.clone()).expect("f32"));
                loss = loss + (a * w.clone()).sum();
            }
            let grads = loss.backward();
            let gz = read(z.grad(&grads).expect("observation gradient")).expect("f32");
            let gp = GradientsParams::from_grads(grads, &cell);
            results.push((outs, gz, collect(&gp, &cell)));
        }
        let (outs, gz, gp) = &results[0];
        let (outs_ref, gz_ref, gp_ref) = &results[1];
        for (k, (a, e)) in outs.iter().zip(outs_ref).enumerate() {
            assert_close(a, e, OUT_TOL, &format!("{what}: output {k}"));
        }
        assert_close(gz, gz_ref, GRAD_TOL, &format!("{what}: dz"));
        assert_eq!(gp.len(), gp_ref.len());
        for (k, (a, e)) in gp.iter().zip(gp_ref).enumerate() {
            assert_param(a, e, &format!("{what}: parameter {k}"));
        }
    }
}

/// Central differences of `loss(v) = Σ w ⊙ forward(v)` in f64, compared with an analytic
/// gradient: `|fd - analytic| <= 1e-6 (1 + |analytic|)`.
fn check_fd(what: &str, v: &[f64], analytic: &[f64], mut loss: impl FnMut(&[f64]) -> f64) {
    assert_eq!(v.len(), analytic.len(), "{what}: lengths");
    let eps = 1e-6;
    let mut p = v.to_vec();
    for i in 0..v.len() {
        p[i] = v[i] + eps;
        let up = loss(&p);
        p[i] = v[i] - eps;
        let down = loss(&p);
        p[i] = v[i];
        let fd = (up - down) / (2.0 * eps);
        assert!(
            (fd - analytic[i]).abs() <= 1e-6 * (1.0 + analytic[i].abs()),
            "{what}: element {i}: finite difference {fd} vs backward {}",
            analytic[i]
        );
    }
}

fn uniform64(rng: &mut ChaCha8Rng, n: usize, scale: f64) -> Vec<f64> {
    (0..n)
        .map(|_| (rng.random::<f64>() * 2.0 - 1.0) * scale)
        .collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The recurrent layer's backward pass equals finite differences of its forward pass (f64),
/// from the gradient of every hidden state (even seeds) or of the last step's only (odd
/// seeds); LSTM cells for the first six seeds, Elman cells for the next six.
#[test]
fn recurrent_backward_equals_finite_differences() {
    for seed in 0..12u64 {
        let mut r = rng(seed, 10);
        let dims = recurrent::Dims {
            batch: r.random_range(1..4),
            steps: r.random_range(1..5),
            input: r.random_range(1..4),
            hidden: r.random_range(1..4),
            cell: if seed < 6 { Cell::Lstm } else { Cell::Elman },
        };
        let (b, t, d, h) = (dims.batch, dims.steps, dims.input, dims.hidden);
        let g = dims.cell.blocks() * h;
        let x = uniform64(&mut r, b * t * d, 1.5);
        let w_ih = uniform64(&mut r, d * g, 0.7);
        let bias = uniform64(&mut r, g, 0.7);
        let w_hh = uniform64(&mut r, h * g, 0.7);
        let last = seed % 2 == 1;
        let w = uniform64(&mut r, b * if last { 1 } else { t } * h, 1.0);
        let cache = recurrent::forward(dims, &x, &w_ih, &bias, &w_hh).expect("shapes");
        let dh = if last {
            recurrent::OutGrad::Last(&w)
        } else {
            recurrent::OutGrad::All(&w)
        };
        let g = recurrent::backward(&cache, &w_ih, &w_hh, dh, true).expect("shapes");
        let what = format!("seed {seed}: {dims:?}, last step only: {last}");
        let f = |x: &[f64], wi: &[f64], bb: &[f64], wh: &[f64]| {
            let c = recurrent::forward(dims, x, wi, bb, wh).expect("shapes");
            if last {
                dot(c.last(), &w)
            } else {
                dot(&c.output(), &w)
            }
        };
        check_fd(&format!("{what}: dx"), &x, &g.dx.unwrap_or_default(), |p| {
            f(p, &w_ih, &bias, &w_hh)
        });
        check_fd(&format!("{what}: dW_ih"), &w_ih, &g.dw_ih, |p| {
            f(&x, p, &bias, &w_hh)
        });
        check_fd(&format!("{what}: db"), &bias, &g.db, |p| {
            f(&x, &w_ih, p, &w_hh)
        });
        check_fd(&format!("{what}: dW_hh"), &w_hh, &g.dw_hh, |p| {
            f(&x, &w_ih, &bias, p)
        });
    }
}

/// The windowed LSTM model's training loss: the fused path (stacked layers, the top one
/// returning its last step, then the head and the mean squared error as one op) against
/// burn's autodiff through the composed network and `mse`: the loss, and the gradient of
/// every parameter, of the input windows and of the targets.
#[test]
fn lstm_loss_gradients_equal_the_composed_reference() {
    loss_gradients_equal_the_composed_reference(LstmArch, 14);
}

/// [`lstm_loss_gradients_equal_the_composed_reference`] for the windowed Elman RNN model.
#[test]
fn rnn_loss_gradients_equal_the_composed_reference() {
    loss_gradients_equal_the_composed_reference(RnnArch, 19);
}

fn loss_gradients_equal_the_composed_reference<A: Architecture>(
    make: fn(RecurrentLayers) -> A,
    stream: u64,
) {
    let device = device();
    let acts = [Activation::Relu, Activation::Tanh, Activation::Sigmoid];
    for seed in 0..12u64 {
        let mut r = rng(seed, stream);
        let arch = make(RecurrentLayers {
            layers: (0..r.random_range(1..4))
                .map(|_| r.random_range(1..9))
                .collect(),
            fc: (0..r.random_range(0..3))
                .map(|_| r.random_range(1..6))
                .collect(),
            activation: acts[r.random_range(0..3)],
        });
        let (b, m, f, out) = (
            r.random_range(1..6),
            r.random_range(1..7),
            r.random_range(1..4),
            r.random_range(1..5),
        );
        let net = arch.build(f, m, out, &device).map(&mut Fill {
            rng: &mut r,
            scale: 0.5,
        });
        let (xv, yv) = (
            uniform(&mut r, b * m * f, 1.5),
            uniform(&mut r, b * out, 1.0),
        );
        let what = format!("seed {seed}: {arch:?} B {b} m {m} f {f} out {out}");
        let mut results = Vec::new();
        for fused in [true, false] {
            let net = arch.configure(net.clone(), &TrainConfig::new(1e-3).with_fused(fused));
            let x = tensor(xv.clone(), [b, m, f], &device).require_grad();
            let y = tensor(yv.clone(), [b, out], &device).require_grad();
            let loss = arch.loss(&net, x.clone(), y.clone());
            let value = read(loss.clone()).expect("f32");
            let grads = loss.backward();
            let gx = read(x.grad(&grads).expect("input gradient")).expect("f32");
            let gy = read(y.grad(&grads).expect("target gradient")).expect("f32");
            let gp = GradientsParams::from_grads(grads, &net);
            results.push((value, gx, gy, collect(&gp, &net)));
        }
        let (value, gx, gy, gp) = &results[0];
        let (value_ref, gx_ref, gy_ref, gp_ref) = &results[1];
        assert_close(value, value_ref, OUT_TOL, &format!("{what}: loss"));
        assert_close(gx, gx_ref, GRAD_TOL, &format!("{what}: dx"));
        assert_close(gy, gy_ref, GRAD_TOL, &format!("{what}: dy"));
        assert_eq!(gp.len(), gp_ref.len());
        for (k, (a, e)) in gp.iter().zip(gp_ref).enumerate() {
            assert_param(a, e, &format!("{what}: parameter {k}"));
        }
    }
}

/// The fused head's backward pass equals finite differences of its loss (f64), for the
/// input, every packed parameter and the targets.
#[test]
fn head_backward_equals_finite_differences() {
    let acts = [Activation::Relu, Activation::Tanh, Activation::Sigmoid];
    for seed in 0..6u64 {
        let mut r = rng(seed, 15);
        let spec = head::Spec {
            input: r.random_range(1..5),
            fc: (0..r.random_range(0..3))
                .map(|_| r.random_range(1..5))
                .collect(),
            output: r.random_range(1..4),
            activation: acts[(seed % 3) as usize],
        };
        let batch = r.random_range(1..4);
        let h = uniform64(&mut r, batch * spec.input, 1.5);
        let params = uniform64(&mut r, spec.n_params(), 0.7);
        let y = uniform64(&mut r, batch * spec.output, 1.0);
        let g = 0.5 + r.random::<f64>();
        let (_, cache) = head::forward(&spec, batch, &h, &params, &y).expect("shapes");
        let grads = head::backward(&spec, &cache, &params, g).expect("shapes");
        let what = format!("seed {seed}: {spec:?} B {batch}");
        let f = |h: &[f64], p: &[f64], y: &[f64]| {
            g * head::forward(&spec, batch, h, p, y).expect("shapes").0
        };
        check_fd(&format!("{what}: dh"), &h, &grads.h, |v| f(v, &params, &y));
        check_fd(
            &format!("{what}: parameters"),
            &params,
            &grads.params,
            |v| f(&h, v, &y),
        );
        check_fd(&format!("{what}: dy"), &y, &grads.y, |v| f(&h, &params, v));
    }
}

/// The KFU filter's backward pass equals finite differences of its forward pass (f64), for
/// every packed parameter and every observation.
#[test]
fn kfu_backward_equals_finite_differences() {
    let acts = [Activation::Relu, Activation::Tanh, Activation::Sigmoid];
    for seed in 0..6u64 {
        let mut r = rng(seed, 11);
        let d = r.random_range(1..3);
        let spec = kfu::Spec {
            d,
            layers: (0..r.random_range(1..3))
                .map(|_| r.random_range(1..4))
                .collect(),
            fc: (0..r.random_range(0..2))
                .map(|_| r.random_range(1..4))
                .collect(),
            activation: acts[(seed % 3) as usize],
        };
        let (b, c, extra) = (
            r.random_range(1..3),
            r.random_range(2..5),
            r.random_range(0..2),
        );
        let p0 = 0.5;
        let params = uniform64(&mut r, spec.n_params(), 0.6);
        let z = uniform64(&mut r, b * c * d, 1.5);
        let w = uniform64(&mut r, b * (c - 1 + extra) * 2 * d, 1.0);
        let (_, cache) = kfu::forward(&spec, &z, b, c, &params, p0, extra).expect("shapes");
        let g = kfu::backward(&spec, &cache, &z, &params, &w, true).expect("shapes");
        let what = format!("seed {seed}: {spec:?} B {b} c {c} extra {extra}");
        let f = |z: &[f64], p: &[f64]| {
            dot(
                &kfu::forward(&spec, z, b, c, p, p0, extra)
                    .expect("shapes")
                    .0,
                &w,
            )
        };
        check_fd(&format!("{what}: parameters"), &params, &g.params, |p| {
            f(&z, p)
        });
        check_fd(&format!("{what}: dz"), &z, &g.z.unwrap_or_default(), |p| {
            f(p, &params)
        });
    }
}

/// Inference: a network of plain weights (`Module::valid`) reading data on the autodiff
/// device runs through the fused ops (no fallback to the composed path), with the outputs of
/// the composed path.
#[test]
fn plain_weights_with_autodiff_data_run_fused() {
    let device = device();
    let mut r = rng(1, 12);
    let layer = FusedLstm::new(2, 3, &device)
        .map(&mut Fill {
            rng: &mut r,
            scale: 0.5,
        })
        .valid();
    let x = tensor(uniform(&mut r, 2 * 4 * 2, 1.0), [2, 4, 2], &device);
    let (w_ih, bias, w_hh) = layer.fused_params();
    let out = recurrent::layer(Cell::Lstm, x.clone(), w_ih, bias, w_hh).expect("runs fused");
    let (out_ref, _) = layer.forward(x, None);
    assert_close(
        &read(out).expect("f32"),
        &read(out_ref).expect("f32"),
        OUT_TOL,
        "LSTM layer",
    );
    let cfg = KfuConfig {
        layers: vec![3],
        fc: vec![],
        ..KfuConfig::default()
    };
    let cell = KfuCell::new(&cfg, 2, &device)
        .map(&mut Fill {
            rng: &mut r,
            scale: 0.5,
        })
        .valid();
    let spec = kfu::Spec {
        d: 2,
        layers: vec![3],
        fc: vec![],
        activation: cfg.activation,
    };
    let z = tensor(uniform(&mut r, 2 * 5 * 2, 1.0), [2, 5, 2], &device);
    let run = cell
        .run_fused(z.clone(), &spec, 1.0, 2)
        .expect("runs fused");
    let run_ref = cell.run(z, 1.0, 2, None);
    assert_close(
        &read(run.posteriors).expect("f32"),
        &read(run_ref.posteriors).expect("f32"),
        OUT_TOL,
        "KFU posteriors",
    );
    for (a, e) in run.ahead.into_iter().zip(run_ref.ahead) {
        assert_close(
            &read(a).expect("f32"),
            &read(e).expect("f32"),
            OUT_TOL,
            "ahead",
        );
    }
}

/// The gates' `exp` ([`super::exp_f32`]) is within 1 ulp of the standard library's on
/// `[-87, 88]`, clamps outside it (staying finite and positive), and keeps NaN.
#[test]
fn exp_f32_matches_the_standard_library() {
    let ulp = |v: f32| f32::from_bits(v.to_bits() + 1) - v;
    let mut worst = 0f32;
    let mut x = -87.0f32;
    while x <= 88.0 {
        let (fast, exact) = (super::exp_f32(x), x.exp());
        worst = worst.max((fast - exact).abs() / ulp(exact));
        x += 0.001_3;
    }
    for x in [0.0f32, 1e-8, -1e-8, 0.5, -0.5, 1.0, -1.0, 20.0, -20.0] {
        let (fast, exact) = (super::exp_f32(x), x.exp());
        worst = worst.max((fast - exact).abs() / ulp(exact));
    }
    assert!(worst <= 1.0, "max error {worst} ulp");
    assert_eq!(super::exp_f32(-1e4), super::exp_f32(-87.0));
    assert_eq!(super::exp_f32(1e4), super::exp_f32(88.0));
    assert!(super::exp_f32(f32::INFINITY).is_finite());
    assert!(super::exp_f32(f32::NEG_INFINITY) > 0.0);
    assert!(super::exp_f32(f32::NAN).is_nan());
}

/// Collects the values of every parameter, in visiting order.
struct Values(Vec<Vec<f32>>);

impl ModuleVisitor for Values {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        self.0.push(read(param.val()).unwrap_or_default());
    }
}

/// Five Adam steps of `fused` and burn's `Adam` from the same module, each on the gradient
/// of `loss` at its own parameters and input `k`: every parameter stays bit for bit equal.
fn assert_adam_steps<M: Module>(
    what: &str,
    module: M,
    clip: Option<f32>,
    loss: impl Fn(&M, u64) -> Tensor<1>,
) {
    let optimizer = |fused: bool| {
        let o = if fused {
            ModuleOptimizer::from(adam::FusedAdam::new(1e-8))
        } else {
            adam::FusedAdam::config(1e-8).init()
        };
        match clip {
            Some(c) => o.with_grad_clipping(GradientClippingConfig::Norm(c).init()),
            None => o,
        }
    };
    let mut modules = [module.clone(), module];
    let mut optims = [optimizer(true), optimizer(false)];
    for step in 0..5 {
        for (m, o) in modules.iter_mut().zip(&mut optims) {
            let grads = GradientsParams::from_grads(loss(m, step).backward(), m);
            *m = o.step(1e-2, m.clone(), grads);
        }
        let [fused, reference] = modules.each_ref().map(|m| {
            let mut v = Values(Vec::new());
            m.visit(&mut v);
            v.0
        });
        assert_eq!(fused.len(), reference.len());
        for (k, (a, b)) in fused.iter().zip(&reference).enumerate() {
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert!(
                !a.is_empty() && bits(a) == bits(b),
                "{what}, clip {clip:?}, step {step}: parameter {k} differs"
            );
        }
    }
}

/// [`adam::FusedAdam`] updates every parameter bit for bit as burn's `Adam` of the same
/// configuration, first step included, with and without gradient clipping: on an LSTM
/// network (every parameter shape of the windowed models, whole gradients) and on the fused
/// KFU filter (gradients that are views into the packed parameters' gradient).
#[test]
fn fused_adam_equals_burns_adam_bit_for_bit() {
    let device = device();
    for (seed, clip) in [(0u64, None), (1, Some(0.05f32))] {
        let mut r = rng(seed, 13);
        let arch = LstmArch(RecurrentLayers {
            layers: vec![5, 4],
            fc: vec![3],
            activation: Activation::Relu,
        });
        let net = arch.build(2, 4, 3, &device).map(&mut Fill {
            rng: &mut r,
            scale: 0.5,
        });
        let xs: Vec<Tensor<3>> = (0..5)
            .map(|_| tensor(uniform(&mut r, 3 * 4 * 2, 1.5), [3, 4, 2], &device))
            .collect();
        assert_adam_steps("LSTM", net, clip, |n, k| {
            let y = arch.forward(n, xs[k as usize].clone());
            (y.clone() * y).sum()
        });
        let cfg = KfuConfig {
            layers: vec![4],
            fc: vec![3],
            ..KfuConfig::default()
        };
        let spec = kfu::Spec {
            d: 2,
            layers: cfg.layers.clone(),
            fc: cfg.fc.clone(),
            activation: cfg.activation,
        };
        let cell = KfuCell::new(&cfg, 2, &device).map(&mut Fill {
            rng: &mut r,
            scale: 0.5,
        });
        let zs: Vec<Tensor<3>> = (0..5)
            .map(|_| tensor(uniform(&mut r, 3 * 5 * 2, 1.5), [3, 5, 2], &device))
            .collect();
        assert_adam_steps("KFU", cell, clip, |c, k| {
            let run = c
                .run_fused(zs[k as usize].clone(), &spec, 1.0, 0)
                .expect("runs fused");
            (run.priors.clone() * run.priors).sum()
        });
    }
}
