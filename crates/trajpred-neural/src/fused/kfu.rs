//! The whole unrolled KFU-LSTM-Net filter over a sequence as one autodiff op.
//!
//! Per step `s` (from `x_0 = z_0`, `P_0 = p0`): the stacked LSTM layers read `x_s`, the fully
//! connected head maps the last hidden state to `f(x_s)`, the prior is `x_s + f(x_s)`, and
//! while observations remain the diagonal Kalman update with `Q = exp(log_q)`,
//! `R = exp(log_r)` gives the posterior `x_{s+1}` (see [`crate::kalman_update`]); after the
//! last observation, `extra` steps iterate the transition without update. The op's output
//! is `[B, S, 2d]`: the prior of every step, then its posterior (the prior again on the
//! steps without update). The parameters come packed into one vector (see [`Spec`]); the
//! backward pass goes through the steps in reverse, carrying the gradients of the
//! posterior, of `P` and of every layer's `h` and `c`, and takes the weight gradients as one
//! matrix product per weight at the end.

use super::bridge;
use super::{
    Mat, Real, activate, activate_backward, add_column_sums, cell_backward, cell_forward, gemm,
};
use crate::config::Activation;
use crate::error::{CoreError, NeuralError, Result};
use burn::backend::flex::FlexTensor;
use burn::tensor::Tensor;

/// The network's sizes; the packed parameter vector holds, in this order and each
/// row-major: per LSTM layer `W_ih` `[in, 4h]`, `b` `[4h]`, `W_hh` `[h, 4h]`; per fully
/// connected layer (the hidden ones, then the output layer to `d`) `W` `[in, out]`, `b`
/// `[out]`; then `log_q` `[d]` and `log_r` `[d]`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Spec {
    /// Axes of the state.
    pub d: usize,
    /// Hidden sizes of the LSTM layers.
    pub layers: Vec<usize>,
    /// Hidden sizes of the fully connected layers (the output layer is extra).
    pub fc: Vec<usize>,
    /// Activation of the fully connected hidden layers.
    pub activation: Activation,
}

#[derive(Debug, Clone, Copy)]
struct LstmAt {
    w_ih: usize,
    b: usize,
    w_hh: usize,
    input: usize,
    hidden: usize,
}

#[derive(Debug, Clone, Copy)]
struct LinearAt {
    w: usize,
    b: usize,
    input: usize,
    output: usize,
}

#[derive(Debug, Clone)]
struct Offsets {
    lstm: Vec<LstmAt>,
    head: Vec<LinearAt>,
    log_q: usize,
    log_r: usize,
    total: usize,
}

impl Spec {
    fn offsets(&self) -> Offsets {
        let mut at = 0;
        let mut input = self.d;
        let mut lstm = Vec::with_capacity(self.layers.len());
        for &hidden in &self.layers {
            let g4 = 4 * hidden;
            lstm.push(LstmAt {
                w_ih: at,
                b: at + input * g4,
                w_hh: at + input * g4 + g4,
                input,
                hidden,
            });
            at += input * g4 + g4 + hidden * g4;
            input = hidden;
        }
        let mut head = Vec::with_capacity(self.fc.len() + 1);
        for &output in self.fc.iter().chain(std::iter::once(&self.d)) {
            head.push(LinearAt {
                w: at,
                b: at + input * output,
                input,
                output,
            });
            at += input * output + output;
            input = output;
        }
        Offsets {
            lstm,
            head,
            log_q: at,
            log_r: at + self.d,
            total: at + 2 * self.d,
        }
    }

    /// Length of the packed parameter vector.
    #[cfg(test)]
    pub(crate) fn n_params(&self) -> usize {
        self.offsets().total
    }
}

/// Kept per LSTM layer (step-major: rows `s B + b`).
#[derive(Debug, Clone)]
struct LayerCache<T> {
    inp: Vec<T>,
    gates: Vec<T>,
    cs: Vec<T>,
    tcs: Vec<T>,
    hs: Vec<T>,
}

/// What the forward pass keeps for the backward pass.
#[derive(Debug, Clone)]
pub(crate) struct Cache<T> {
    batch: usize,
    c: usize,
    steps: usize,
    lstm: Vec<LayerCache<T>>,
    /// Activated outputs of the hidden fully connected layers, `[S B, out]` each.
    head: Vec<Vec<T>>,
    /// Priors `[S B, d]`.
    prior: Vec<T>,
    /// `K`, `P + Q` and `P + Q + R` per update step, `[updates, d]`.
    gain: Vec<T>,
    p_prior: Vec<T>,
    den: Vec<T>,
    q: Vec<T>,
    r: Vec<T>,
}

/// The forward pass over `z` `[B, c, d]`: returns `[B, c - 1 + extra, 2d]` and the cache.
pub(crate) fn forward<T: Real>(
    spec: &Spec,
    z: &[T],
    batch: usize,
    c: usize,
    params: &[T],
    p0: T,
    extra: usize,
) -> Result<(Vec<T>, Cache<T>)> {
    let d = spec.d;
    let off = spec.offsets();
    let mismatch = |what, expected, got| {
        NeuralError::Core(CoreError::DimensionMismatch {
            what,
            expected,
            got,
        })
    };
    if params.len() != off.total {
        return Err(mismatch("fused KFU parameters", off.total, params.len()));
    }
    if c == 0 || z.len() != batch * c * d {
        return Err(mismatch(
            "fused KFU observations",
            batch * c.max(1) * d,
            z.len(),
        ));
    }
    let steps = c - 1 + extra;
    let rows = steps * batch;
    let zero = T::zero();
    let mut lstm: Vec<LayerCache<T>> = off
        .lstm
        .iter()
        .map(|l| LayerCache {
            inp: vec![zero; rows * l.input],
            gates: vec![zero; rows * 4 * l.hidden],
            cs: vec![zero; rows * l.hidden],
            tcs: vec![zero; rows * l.hidden],
            hs: vec![zero; rows * l.hidden],
        })
        .collect();
    let n_hidden_fc = off.head.len() - 1;
    let mut head: Vec<Vec<T>> = off.head[..n_hidden_fc]
        .iter()
        .map(|l| vec![zero; rows * l.output])
        .collect();
    let q: Vec<T> = params[off.log_q..off.log_q + d]
        .iter()
        .map(|v| v.exp())
        .collect();
    let r: Vec<T> = params[off.log_r..off.log_r + d]
        .iter()
        .map(|v| v.exp())
        .collect();
    let updates = c - 1;
    let mut prior = vec![zero; rows * d];
    let mut gain = vec![zero; updates * d];
    let mut p_prior = vec![zero; updates * d];
    let mut den = vec![zero; updates * d];
    let mut out = vec![zero; batch * steps * 2 * d];
    let mut x: Vec<T> = (0..batch)
        .flat_map(|b| z[b * c * d..b * c * d + d].iter().copied())
        .collect();
    let mut p = vec![p0; d];
    let mut f = vec![zero; batch * d];
    for s in 0..steps {
        for (l, at) in off.lstm.iter().enumerate() {
            let (h, g4) = (at.hidden, 4 * at.hidden);
            let (bh, bg) = (batch * h, batch * g4);
            let (before, rest) = lstm.split_at_mut(l);
            let cur = &mut rest[0];
            let inp = &mut cur.inp[s * batch * at.input..(s + 1) * batch * at.input];
            match before.last() {
                Some(prev) => inp.copy_from_slice(&prev.hs[s * batch * at.input..][..inp.len()]),
                None => inp.copy_from_slice(&x),
            }
            let a = &mut cur.gates[s * bg..(s + 1) * bg];
            for row in a.chunks_exact_mut(g4) {
                row.copy_from_slice(&params[at.b..at.b + g4]);
            }
            T::step_mul_add(inp, &params[at.w_ih..at.b], (batch, at.input, g4), a)?;
            let (h_done, h_rest) = cur.hs.split_at_mut(s * bh);
            let (c_done, c_rest) = cur.cs.split_at_mut(s * bh);
            let c_prev = if s > 0 {
                T::step_mul_add(
                    &h_done[(s - 1) * bh..],
                    &params[at.w_hh..at.w_hh + h * g4],
                    (batch, h, g4),
                    a,
                )?;
                Some(&c_done[(s - 1) * bh..])
            } else {
                None
            };
            cell_forward(
                h,
                a,
                c_prev,
                &mut c_rest[..bh],
                &mut cur.tcs[s * bh..(s + 1) * bh],
                &mut h_rest[..bh],
            );
        }
        for (k, at) in off.head.iter().enumerate() {
            let (before, rest) = head.split_at_mut(k);
            let u: &[T] = match (before.last(), lstm.last()) {
                (Some(prev), _) => &prev[s * batch * at.input..(s + 1) * batch * at.input],
                (None, Some(top)) => &top.hs[s * batch * at.input..(s + 1) * batch * at.input],
                (None, None) => &x,
            };
            let o: &mut [T] = match rest.first_mut() {
                Some(o) => &mut o[s * batch * at.output..(s + 1) * batch * at.output],
                None => &mut f,
            };
            for row in o.chunks_exact_mut(at.output) {
                row.copy_from_slice(&params[at.b..at.b + at.output]);
            }
            T::step_mul_add(u, &params[at.w..at.b], (batch, at.input, at.output), o)?;
            if k < n_hidden_fc {
                activate(spec.activation, o);
            }
        }
        let pr = &mut prior[s * batch * d..(s + 1) * batch * d];
        for ((pv, xv), fv) in pr.iter_mut().zip(&x).zip(&f) {
            *pv = *xv + *fv;
        }
        if s < updates {
            for k in 0..d {
                let pp = p[k] + q[k];
                let dn = pp + r[k];
                let kg = pp / dn;
                gain[s * d + k] = kg;
                p_prior[s * d + k] = pp;
                den[s * d + k] = dn;
                p[k] = (T::one() - kg) * pp;
            }
        }
        for b in 0..batch {
            let o = &mut out[(b * steps + s) * 2 * d..(b * steps + s + 1) * 2 * d];
            for k in 0..d {
                let pv = pr[b * d + k];
                let post = if s < updates {
                    let kg = gain[s * d + k];
                    pv + kg * (z[(b * c + s + 1) * d + k] - pv)
                } else {
                    pv
                };
                o[k] = pv;
                o[d + k] = post;
                x[b * d + k] = post;
            }
        }
    }
    Ok((
        out,
        Cache {
            batch,
            c,
            steps,
            lstm,
            head,
            prior,
            gain,
            p_prior,
            den,
            q,
            r,
        },
    ))
}

/// The gradients of one run: of the packed parameters, and of `z` when asked for.
#[derive(Debug, Clone)]
pub(crate) struct Grads<T> {
    pub params: Vec<T>,
    pub z: Option<Vec<T>>,
}

/// The backward pass from the gradient `g` of the output `[B, S, 2d]`.
pub(crate) fn backward<T: Real>(
    spec: &Spec,
    cache: &Cache<T>,
    z: &[T],
    params: &[T],
    g: &[T],
    need_dz: bool,
) -> Result<Grads<T>> {
    let d = spec.d;
    let off = spec.offsets();
    let Cache {
        batch, c, steps, ..
    } = *cache;
    if g.len() != batch * steps * 2 * d || params.len() != off.total {
        return Err(NeuralError::Core(CoreError::DimensionMismatch {
            what: "fused KFU output gradient",
            expected: batch * steps * 2 * d,
            got: g.len(),
        }));
    }
    let updates = c - 1;
    let rows = steps * batch;
    let zero = T::zero();
    let one = T::one();
    let mut da: Vec<Vec<T>> = off
        .lstm
        .iter()
        .map(|l| vec![zero; rows * 4 * l.hidden])
        .collect();
    let mut dh_next: Vec<Vec<T>> = off
        .lstm
        .iter()
        .map(|l| vec![zero; batch * l.hidden])
        .collect();
    let mut dc: Vec<Vec<T>> = dh_next.clone();
    let mut gpre: Vec<Vec<T>> = off
        .head
        .iter()
        .map(|l| vec![zero; rows * l.output])
        .collect();
    let mut gq = vec![zero; d];
    let mut gr = vec![zero; d];
    let mut g_p = vec![zero; d];
    let mut g_x_next = vec![zero; batch * d];
    let mut g_x = vec![zero; batch * d];
    let mut dz = need_dz.then(|| vec![zero; batch * c * d]);
    let widest = off
        .lstm
        .iter()
        .map(|l| l.input.max(l.hidden))
        .chain(off.head.iter().map(|l| l.input))
        .max()
        .unwrap_or(d);
    let mut g_in = vec![zero; batch * widest];
    let mut g_h = vec![zero; batch * widest];
    let last = off.head.len() - 1;
    for s in (0..steps).rev() {
        // the Kalman update, and the gradient of the prior
        let go = &mut gpre[last][s * batch * d..(s + 1) * batch * d];
        for b in 0..batch {
            let gs = &g[(b * steps + s) * 2 * d..(b * steps + s + 1) * 2 * d];
            for k in 0..d {
                let g_post = gs[d + k] + g_x_next[b * d + k];
                go[b * d + k] = gs[k] + g_post;
            }
        }
        if s < updates {
            for k in 0..d {
                let (kg, pp, dn) = (
                    cache.gain[s * d + k],
                    cache.p_prior[s * d + k],
                    cache.den[s * d + k],
                );
                let mut g_k = -g_p[k] * pp;
                for b in 0..batch {
                    let gs = &g[(b * steps + s) * 2 * d..];
                    let g_post = gs[d + k] + g_x_next[b * d + k];
                    let i = b * d + k;
                    let pv = cache.prior[s * batch * d + i];
                    let zv = z[(b * c + s + 1) * d + k];
                    // go held g_prior + g_post; the prior's share of the posterior is 1 - K
                    go[i] = go[i] - g_post * kg;
                    g_k = g_k + g_post * (zv - pv);
                    if let Some(dz) = dz.as_mut() {
                        dz[(b * c + s + 1) * d + k] = g_post * kg;
                    }
                }
                let dn2 = dn * dn;
                let g_pp = g_p[k] * (one - kg) + g_k * cache.r[k] / dn2;
                gr[k] = gr[k] - g_k * pp / dn2;
                gq[k] = gq[k] + g_pp;
                g_p[k] = g_pp;
            }
        }
        // prior = x + f(x)
        g_x.copy_from_slice(go);
        // the head, from the output layer down
        for k in (0..off.head.len()).rev() {
            let at = off.head[k];
            let gi = &mut g_in[..batch * at.input];
            T::step_mul_t(
                &gpre[k][s * batch * at.output..],
                &params[at.w..at.b],
                (batch, at.output, at.input),
                gi,
            )?;
            if k > 0 {
                let below = off.head[k - 1];
                let y = &cache.head[k - 1][s * batch * below.output..][..batch * below.output];
                let dst = &mut gpre[k - 1][s * batch * below.output..][..batch * below.output];
                dst.copy_from_slice(gi);
                activate_backward(spec.activation, y, dst);
            } else {
                g_h[..gi.len()].copy_from_slice(gi);
            }
        }
        // the LSTM layers, from the top down
        for l in (0..off.lstm.len()).rev() {
            let at = off.lstm[l];
            let (h, g4) = (at.hidden, 4 * at.hidden);
            let (bh, bg) = (batch * h, batch * g4);
            let lc = &cache.lstm[l];
            for (gv, nv) in g_h[..bh].iter_mut().zip(&dh_next[l]) {
                *gv = *gv + *nv;
            }
            let c_prev = (s > 0).then(|| &lc.cs[(s - 1) * bh..s * bh]);
            let da_s = &mut da[l][s * bg..(s + 1) * bg];
            cell_backward(
                h,
                &lc.gates[s * bg..(s + 1) * bg],
                c_prev,
                &lc.tcs[s * bh..(s + 1) * bh],
                &g_h[..bh],
                &mut dc[l],
                da_s,
            );
            if s > 0 {
                T::step_mul_t(
                    da_s,
                    &params[at.w_hh..at.w_hh + h * g4],
                    (batch, g4, h),
                    &mut dh_next[l],
                )?;
            }
            let gi = &mut g_in[..batch * at.input];
            T::step_mul_t(da_s, &params[at.w_ih..at.b], (batch, g4, at.input), gi)?;
            if l > 0 {
                g_h[..gi.len()].copy_from_slice(gi);
            } else {
                for (gx, gv) in g_x.iter_mut().zip(gi.iter()) {
                    *gx = *gx + *gv;
                }
            }
        }
        g_x_next.copy_from_slice(&g_x);
    }
    if let Some(dz) = dz.as_mut() {
        // x_0 = z_0
        for b in 0..batch {
            dz[b * c * d..b * c * d + d].copy_from_slice(&g_x_next[b * d..(b + 1) * d]);
        }
    }
    // the weight gradients: one product per weight over every step
    let mut gp = vec![zero; off.total];
    for (l, at) in off.lstm.iter().enumerate() {
        let g4 = 4 * at.hidden;
        let lc = &cache.lstm[l];
        gemm(
            Mat::new(&lc.inp, rows, at.input).t(),
            Mat::new(&da[l], rows, g4),
            zero,
            &mut gp[at.w_ih..at.b],
        )?;
        add_column_sums(&da[l], g4, &mut gp[at.b..at.b + g4]);
        if steps > 1 {
            let r = rows - batch;
            gemm(
                Mat::new(&lc.hs[..r * at.hidden], r, at.hidden).t(),
                Mat::new(&da[l][batch * g4..], r, g4),
                zero,
                &mut gp[at.w_hh..at.w_hh + at.hidden * g4],
            )?;
        }
    }
    for (k, at) in off.head.iter().enumerate() {
        let u: &[T] = match (k, cache.lstm.last()) {
            (0, Some(top)) => &top.hs,
            (0, None) => &[],
            _ => &cache.head[k - 1],
        };
        gemm(
            Mat::new(u, rows, at.input).t(),
            Mat::new(&gpre[k], rows, at.output),
            zero,
            &mut gp[at.w..at.b],
        )?;
        add_column_sums(&gpre[k], at.output, &mut gp[at.b..at.b + at.output]);
    }
    for k in 0..d {
        gp[off.log_q + k] = gq[k] * cache.q[k];
        gp[off.log_r + k] = gr[k] * cache.r[k];
    }
    Ok(Grads { params: gp, z: dz })
}

/// The state the autodiff node keeps.
#[derive(Debug, Clone)]
pub(crate) struct State {
    spec: Spec,
    cache: Cache<f32>,
    z: Vec<f32>,
    params: Vec<f32>,
}

/// The fused filter's inputs: `z`, the packed parameters.
impl bridge::FusedState<2> for State {
    const WHAT: &'static str = "KFU output gradient";

    fn shapes(&self) -> [Vec<usize>; 2] {
        let (batch, c, d) = (self.cache.batch, self.cache.c, self.spec.d);
        [vec![batch, c, d], vec![self.params.len()]]
    }

    fn gradients(&self, g: &[f32], [need_z, _]: [bool; 2]) -> Result<[Vec<f32>; 2]> {
        let g = backward(&self.spec, &self.cache, &self.z, &self.params, g, need_z)?;
        Ok([g.z.unwrap_or_default(), g.params])
    }
}

/// Runs the filter over `z` `[B, c, d]` with the packed `params` (see [`Spec`]) as one op;
/// returns `[B, c - 1 + extra, 2d]` (priors, then posteriors).
///
/// Errors when the tensors are not `f32` tensors of the flex backend or the sizes disagree
/// with `spec` (then the composed filter is the way).
pub(crate) fn sequence(
    z: Tensor<3>,
    params: Tensor<1>,
    spec: &Spec,
    p0: f64,
    extra: usize,
) -> Result<Tensor<3>> {
    let [batch, c, d] = z.dims();
    if d != spec.d {
        return Err(NeuralError::Core(CoreError::DimensionMismatch {
            what: "fused KFU axes",
            expected: spec.d,
            got: d,
        }));
    }
    let prims = vec![
        bridge::prim(z, "KFU observations")?,
        bridge::prim(params, "KFU parameters")?,
    ];
    let shape = [batch, (c.max(1) - 1) + extra, 2 * d];
    let run = |t: &[FlexTensor]| -> Result<(Vec<f32>, State)> {
        let zv = bridge::values(&t[0], "KFU observations")?;
        let pv = bridge::values(&t[1], "KFU parameters")?;
        let (out, cache) = forward(spec, &zv, batch, c, &pv, p0 as f32, extra)?;
        Ok((
            out,
            State {
                spec: spec.clone(),
                cache,
                z: zv.into_owned(),
                params: pv.into_owned(),
            },
        ))
    };
    bridge::apply(
        bridge::FusedBackward::<State>::new(),
        prims,
        &shape,
        "fused KFU",
        run,
    )
}
