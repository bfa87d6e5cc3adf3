#!/usr/bin/env python3
"""PyTorch CPU reference for one KFU-LSTM-Net training iteration (`examples/profile_speed.rs kfu`,
criterion bench `kfu_iteration_200_b16`).

The same network, data and loss as our `KfuLstmNet::fit_observed` in that bench:

- data: 16 noisy 3-D sine trajectories of 200 steps, trajectory i with phase 0.4 i:
  sin(0.05 k + ph), sin(0.065 k + 0.5 + ph), sin(0.035 k + 1 + ph) plus the deterministic
  wobble 0.1 (((k 31 + a 17) mod 13) / 6 - 1) on axis a; z-scored per axis over all points;
  one batch of 16 sequences;
- network (`KfuConfig::default()`): LSTMCell(3 -> 64) -> LSTMCell(64 -> 64), then
  Linear(64, 64) + ReLU and Linear(64, 3); Xavier-uniform weights, zero biases;
  learnable log Q = -4 and log R = -2 per axis, P(0|0) = 1;
- per step t = 1..199: prior = x + f(x) (the LSTM states carried), P- = P + Q,
  K = P- / (P- + R), x = prior + K (z_t - prior), P = (1 - K) P-; x(0) = z(0);
- loss: MSE(prior, z[:, 1:]) (training on observations only);
- Adam eps 1e-8, lr 1e-4 for the network and 1e-2 for log Q, log R; float32; the loss is
  read back every iteration (`loss.item()`).

Timing: `--warmup` iterations are dropped, then median, quartiles, min and max of the
wall times (time.perf_counter) of `--repeat` iterations are printed.

    python pytorch_kfu_iteration.py --threads 1 --json
"""

import argparse

import torch
from torch import nn

from torch_timing import add_common_args, emit, set_threads, spread, summary, timed


def data(n=200, batch=16, noise=0.1):
    k = torch.arange(n, dtype=torch.float64)
    trajs = []
    for i in range(batch):
        ph = 0.4 * i
        axes = []
        for a, (w, p) in enumerate([(0.05, 0.0), (0.065, 0.5), (0.035, 1.0)]):
            wob = torch.tensor(
                [noise * ((((j * 31 + a * 17) % 13) / 6.0) - 1.0) for j in range(n)],
                dtype=torch.float64,
            )
            axes.append(torch.sin(w * k + p + ph) + wob)
        trajs.append(torch.stack(axes, dim=1))
    z = torch.stack(trajs)  # [16, 200, 3]
    flat = z.reshape(-1, 3)
    z = (z - flat.mean(0)) / flat.std(0, unbiased=False)
    return z.float()


class Kfu(nn.Module):
    def __init__(self, d=3, h=64):
        super().__init__()
        self.l0 = nn.LSTMCell(d, h)
        self.l1 = nn.LSTMCell(h, h)
        self.fc = nn.Linear(h, h)
        self.out = nn.Linear(h, d)
        for p in self.parameters():
            if p.dim() >= 2:
                nn.init.xavier_uniform_(p)
            else:
                nn.init.zeros_(p)
        self.log_q = nn.Parameter(torch.full((d,), -4.0))
        self.log_r = nn.Parameter(torch.full((d,), -2.0))

    def forward(self, z, p0=1.0):
        b, c, d = z.shape
        q, r = self.log_q.exp(), self.log_r.exp()
        x = z[:, 0]
        p = torch.full((b, d), p0)
        s0 = s1 = None
        priors = []
        for t in range(1, c):
            s0 = self.l0(x, s0)
            s1 = self.l1(s0[0], s1)
            prior = x + self.out(torch.relu(self.fc(s1[0])))
            pp = p + q
            k = pp / (pp + r)
            x = prior + k * (z[:, t] - prior)
            p = (1 - k) * pp
            priors.append(prior)
        return torch.stack(priors, 1)


def main():
    ap = argparse.ArgumentParser()
    add_common_args(ap, repeat=10)
    a = ap.parse_args()
    set_threads(a)
    torch.manual_seed(0)
    z = data()
    net = Kfu()
    noise = [net.log_q, net.log_r]
    rest = [p for n, p in net.named_parameters() if n not in ("log_q", "log_r")]
    opt = torch.optim.Adam(
        [{"params": rest, "lr": 1e-4}, {"params": noise, "lr": 1e-2}], eps=1e-8
    )

    def iteration():
        opt.zero_grad(set_to_none=True)
        loss = nn.functional.mse_loss(net(z), z[:, 1:])
        loss.backward()
        opt.step()
        return loss.item()

    times, losses = timed(iteration, a.warmup, a.repeat)
    res = {
        "impl": "torch",
        "workload": "kfu",
        "torch": torch.__version__,
        "threads": torch.get_num_threads(),
        "repeat": a.repeat,
        **summary(times, losses),
    }
    emit(
        res,
        a.json,
        f"torch {res['torch']}, {res['threads']} thread(s): {spread(res, 'iter')} "
        f"over {a.repeat} iterations after {a.warmup} warm-up; "
        f"loss {losses[0]:.4f} -> {losses[-1]:.4f}",
    )


if __name__ == "__main__":
    main()
