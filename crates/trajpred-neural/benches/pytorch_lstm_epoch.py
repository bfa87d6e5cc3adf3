#!/usr/bin/env python3
"""PyTorch CPU reference for the criterion benchmark `lstm_epoch_800x10_b16` (benches/training.rs).

The same network and data as our `LstmNet` bench:

- data: the 800-step 3-D sine x = sin(0.05 k), y = sin(0.065 k + 0.5), z = sin(0.035 k + 1),
  z-scored per axis (mean and population standard deviation of all points), cut into
  790 windows of 10 steps, each predicting the next step (horizon 1, all axes jointly);
- one epoch = a fresh shuffle of the 790 windows, batches of 16 with the last, smaller
  batch kept (49 x 16 + 1 x 6 = 50 optimizer steps), as our training loop does;
- network: LSTM(3 -> 64) -> LSTM(64 -> 64), the last step's hidden state through
  Linear(64, 64) + ReLU and Linear(64, 3) (`RecurrentLayers::default()`);
  Xavier-uniform weights and zero biases (our initialisation);
- Adam lr 1e-3, epsilon 1e-8, MSE loss, float32; the loss is read back every batch
  (`loss.item()`), as our loop does to detect divergence.

Timing: `--warmup` epochs are dropped, then the median, quartiles, min and max of the wall
times (time.perf_counter) of `--repeat` epochs are printed (never the minimum alone). Run each thread setting in its own process:

    python pytorch_lstm_epoch.py --threads 1
    python pytorch_lstm_epoch.py --threads 0      # 0 = PyTorch's default thread count

`--no-mkldnn` turns off oneDNN, so nn.LSTM runs op by op (as a framework without a fused
RNN kernel does).
"""

import argparse

import torch
from torch import nn

from torch_timing import add_common_args, emit, set_threads, spread, summary, timed


def data(n=800, m=10):
    k = torch.arange(n, dtype=torch.float64)
    axes = torch.stack(
        [torch.sin(0.05 * k), torch.sin(0.065 * k + 0.5), torch.sin(0.035 * k + 1.0)], dim=1
    )
    axes = (axes - axes.mean(0)) / axes.std(0, unbiased=False)
    xs = torch.stack([axes[i : i + m] for i in range(n - m)]).float()  # [790, 10, 3]
    ys = torch.stack([axes[i + m] for i in range(n - m)]).float()  # [790, 3]
    return xs, ys


class Net(nn.Module):
    def __init__(self):
        super().__init__()
        self.lstm = nn.LSTM(3, 64, num_layers=2, batch_first=True)
        self.fc = nn.Linear(64, 64)
        self.out = nn.Linear(64, 3)
        for name, p in self.named_parameters():
            if p.dim() >= 2:
                nn.init.xavier_uniform_(p)
            else:
                nn.init.zeros_(p)

    def forward(self, x):
        _, (h, _) = self.lstm(x)
        return self.out(torch.relu(self.fc(h[-1])))


def epoch(net, opt, xs, ys, batch, gen):
    order = torch.randperm(xs.shape[0], generator=gen)
    total, batches = 0.0, 0
    for start in range(0, xs.shape[0], batch):
        idx = order[start : start + batch]
        opt.zero_grad(set_to_none=True)
        loss = nn.functional.mse_loss(net(xs[idx]), ys[idx])
        loss.backward()
        opt.step()
        total += loss.item()
        batches += 1
    return total / batches, batches


def main():
    ap = argparse.ArgumentParser()
    add_common_args(ap, repeat=15)
    ap.add_argument("--batch", type=int, default=16)
    ap.add_argument("--no-mkldnn", action="store_true")
    a = ap.parse_args()
    set_threads(a)
    if a.no_mkldnn:
        torch.backends.mkldnn.enabled = False
    torch.manual_seed(0)
    gen = torch.Generator().manual_seed(0)
    xs, ys = data()
    net = Net()
    opt = torch.optim.Adam(net.parameters(), lr=1e-3, eps=1e-8)
    batches = 0

    def one_epoch():
        nonlocal batches
        loss, batches = epoch(net, opt, xs, ys, a.batch, gen)
        return loss

    times, losses = timed(one_epoch, a.warmup, a.repeat)
    res = {
        "impl": "torch",
        "workload": "lstm",
        "torch": torch.__version__,
        "threads": torch.get_num_threads(),
        "mkldnn": torch.backends.mkldnn.enabled,
        "batches_per_epoch": batches,
        "warmup": a.warmup,
        "repeat": a.repeat,
        **summary(times, losses),
    }
    emit(
        res,
        a.json,
        f"torch {res['torch']}, {res['threads']} thread(s), mkldnn {res['mkldnn']}, "
        f"{batches} batches/epoch: {spread(res, 'epoch')} over {a.repeat} epochs "
        f"after {a.warmup} warm-up; loss {losses[0]:.4f} -> {losses[-1]:.4f}",
    )


if __name__ == "__main__":
    main()
