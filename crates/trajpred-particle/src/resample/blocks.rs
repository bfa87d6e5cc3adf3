//! The residual remainder drawn block by block: binomial block totals, then rejection (or
//! search) within a block, the output written in one streaming pass.

use super::common::*;
use super::residual::{ACCEPT_MIN, BLOCK, ResidualSums, share, split};
use rand::Rng;

/// Residual resampling with the remainder drawn block by block, the output written in one
/// streaming pass, sorted by particle.
///
/// Requires `sums.copies < out.len() <= u32::MAX` and `sums.residual > 0`. With `m = n - copies`
/// remainder draws from the residuals `r_i in [0, 1)`, the multinomial counts are drawn as
/// 1. per block `b` of [`BLOCK`] particles (residual sum `S_b`), in order: the block's
///    number of draws `M_b ~ Binomial(m_left, S_b / S_left)` (`m_left`, `S_left`: the draws
///    and the residual sum of this block and the blocks after it; the block holding the
///    last positive residual takes all `m_left`), which is the conditional law of a
///    multinomial's block totals;
/// 2. within the block, `M_b` i.i.d. draws from `r_s / S_b`. By rejection when the
///    acceptance `S_b / BLOCK` is at least [`ACCEPT_MIN`] (the slots of a shorter last
///    block past its particles holding residual 0): a try is a slot `t` uniform on the
///    [`BLOCK`] slots and `v ~ U[0, 1)`, accepted when `v < r_t`, so it accepts slot `t` with
///    probability `r_t / BLOCK` and an accepted slot is distributed as `r_t / S_b`; half a
///    64-bit draw per try (see [`draw_by_rejection`]). Tries are repeated until `M_b` are
///    accepted: on average at most `1 / ACCEPT_MIN` per draw, and since `E[M_b] = S_b` up
///    to rounding (the residuals sum to `m`), about `BLOCK` per block however the residuals
///    are spread: no cumulative sums, no table, no search. Below that acceptance (few
///    particles carry the block's residual, and it has few draws), each draw
///    `u ~ U[0, S_b)` is located in the block's cumulative residuals by binary search.
///
/// Together that is exactly a multinomial draw of `m` places from `r_i / sum r`, up to the
/// rounding of `S_b / S_left` (a relative error of order `eps S / S_left`) and the
/// granularity of the uniforms (`2^-74` for `v`, `2^-53` for `u`). Then every
/// particle's `floor(n w_i) + count_i` copies are written in index order. `weights` are the
/// particles `first..first + weights.len()` (the indices written are offset by `first`;
/// `sums` are theirs).
pub(super) fn residual_blocks<R: Rng + ?Sized>(
    weights: &[f64],
    first: usize,
    scale: f64,
    sums: ResidualSums,
    rng: &mut R,
    out: &mut [usize],
) {
    let n = out.len();
    let mut m_left = (n - sums.copies) as u64;
    let mut s_left = sums.residual;
    let last_block = sums.last / BLOCK;
    let mut resid = [0.0f64; BLOCK];
    let mut coarse = [0u32; BLOCK];
    let mut count = [0u32; BLOCK];
    let mut pos = 0usize;
    for (b, chunk) in weights.chunks(BLOCK).enumerate() {
        let len = chunk.len();
        let sb = block_residuals(
            chunk,
            scale,
            &mut resid[..len],
            &mut coarse[..len],
            &mut count[..len],
        );
        let draws = share(b >= last_block, m_left, sb, s_left, rng);
        m_left -= draws;
        s_left -= sb;
        if draws > 0 {
            if sb >= ACCEPT_MIN * BLOCK as f64 {
                // a last, shorter block: its slots past the particles hold residual 0
                resid[len..].fill(0.0);
                coarse[len..].fill(0);
                draw_by_rejection(&resid, &coarse, draws, rng, &mut count);
            } else {
                draw_by_search(&mut resid[..len], draws, rng, &mut count[..len]);
            }
        }
        let base = first + b * BLOCK;
        for (s, &c) in count[..len].iter().enumerate() {
            let end = pos + c as usize;
            fill_run(out, pos, end, base + s);
            pos = end;
        }
    }
    debug_assert_eq!(pos, n);
}

/// Splits one block's `w_i scale` into copies (`count`) and residuals (`resid`), with each
/// residual's first [`COARSE`] binary digits (`coarse`: an integer `c` with
/// `r 2^COARSE - 1 <= c <= r 2^COARSE`, by the rounding of [`split`]), returning the residual
/// sum (in four interleaved partial sums, like [`residual_sums`]).
#[inline(always)]
pub(super) fn block_residuals(
    chunk: &[f64],
    scale: f64,
    resid: &mut [f64],
    coarse: &mut [u32],
    count: &mut [u32],
) -> f64 {
    let len = chunk.len();
    let body = len - len % 4;
    let mut acc = [0.0f64; 4];
    let digits = (1u64 << COARSE) as f64;
    let one = |w: f64, r: &mut f64, c: &mut u32, n: &mut u32| {
        let (f, x) = split(w, scale);
        *r = x;
        *c = rounded((x * digits - 0.5) + ROUND) as u32;
        *n = f as u32;
        x
    };
    for (((q, rq), cq), nq) in chunk[..body]
        .chunks_exact(4)
        .zip(resid[..body].chunks_exact_mut(4))
        .zip(coarse[..body].chunks_exact_mut(4))
        .zip(count[..body].chunks_exact_mut(4))
    {
        for l in 0..4 {
            acc[l] += one(q[l], &mut rq[l], &mut cq[l], &mut nq[l]);
        }
    }
    for s in body..len {
        acc[0] += one(chunk[s], &mut resid[s], &mut coarse[s], &mut count[s]);
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

/// Binary digits of `v` compared per try in [`draw_by_rejection`]: with the 11 bits of a
/// slot, a 64-bit draw makes two tries.
pub(super) const COARSE: u32 = 21;

/// `draws` i.i.d. draws from the residuals `resid` (each in `[0, 1)`, zero past the block's
/// particles; `coarse` their first [`COARSE`] digits), by rejection, each adding one to
/// `count` of its slot; see [`residual_blocks`].
///
/// Each half of a 64-bit draw is a try: its top 11 bits the slot `t` (`BLOCK = 2^11`), its
/// low [`COARSE`] bits the first digits `d` of `v in [0, 1)`. With `R = r_t 2^COARSE` and
/// `c = coarse[t]` (`R - 1 <= c <= R`), `v < r_t` is decided by `d < c` (accept) or `d > c`
/// (reject), and only for `d = c` (probability `2^-COARSE`) by the further digits `u` of `v`,
/// a fresh 53-bit uniform: `u < R - c` (exact in floating point). So each try accepts slot
/// `t` with probability `r_t / BLOCK` (to `2^-74`), as if `v` were drawn whole. Tries go in
/// pairs while two or more draws are left (both may be accepted), then one at a time.
#[inline]
pub(super) fn draw_by_rejection<R: Rng + ?Sized>(
    resid: &[f64; BLOCK],
    coarse: &[u32; BLOCK],
    draws: u64,
    rng: &mut R,
    count: &mut [u32; BLOCK],
) {
    const _: () = assert!(BLOCK == 1 << (32 - COARSE));
    let mut placed = 0u64;
    let mut one = |h: u32, rng: &mut R| {
        let t = (h >> COARSE) as usize;
        let d = h & ((1 << COARSE) - 1);
        let c = coarse[t];
        let mut hit = d < c;
        if d == c {
            let u = (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
            hit = u < resid[t] * (1u64 << COARSE) as f64 - c as f64;
        }
        count[t] += u32::from(hit);
        u64::from(hit)
    };
    // in batches of `(draws - placed) / 2` pairs, which cannot place more than are left:
    // the same tries as checking before every pair, without the check
    loop {
        let pairs = (draws - placed) / 2;
        if pairs == 0 {
            break;
        }
        for _ in 0..pairs {
            let x = rng.next_u64();
            placed += one(x as u32, rng);
            placed += one((x >> 32) as u32, rng);
        }
    }
    while placed < draws {
        placed += one(rng.next_u64() as u32, rng);
    }
}

/// `draws` i.i.d. draws from the residuals `resid` (positive sum; turned into their
/// cumulative sums in place), each located by binary search and adding one to `count` of
/// its particle; a draw that rounding puts at or past the total selects the last positive
/// residual.
pub(super) fn draw_by_search<R: Rng + ?Sized>(
    resid: &mut [f64],
    draws: u64,
    rng: &mut R,
    count: &mut [u32],
) {
    let last = resid.iter().rposition(|&r| r > 0.0).unwrap_or(0);
    let mut c = 0.0f64;
    for r in resid.iter_mut() {
        c += *r;
        *r = c;
    }
    let cum = &*resid;
    let unit = c * (1.0 / (1u64 << 53) as f64);
    for _ in 0..draws {
        let u = (rng.next_u64() >> 11) as f64 * unit;
        count[search(cum, u, last)] += 1;
    }
}
