//! Does training on more of the training users' tracks help? Cross-validation by user on the
//! **training users only** of the leaderboard's by-user split (`docs/accuracy.md`, "What
//! helped, what did not"): every fold is tested on its users' segments of the leaderboard's
//! segmentation (`--max-gap`, `--min-points`), and a method is fitted on the other users'
//! segments of another segmentation (a shorter minimum, a longer gap: more training origins
//! from the same users).
//!
//! ```sh
//! cargo run --release -p trajpred --example shorter_training -- geolife ../shared/data/geolife \
//!     5 55 55:5,30:15 aligned-mlp
//! ```
//! (dataset, path, the leaderboard's `--max-gap` and `--min-points`, the training
//! segmentations as `min-points:max-gap` separated by commas, methods separated by commas;
//! the split is `--split by-user --train-fraction 0.3 --seed 0`, the evaluation `--history 20
//! --horizon 5`, 5 folds by user, seed 0.)

use std::collections::HashSet;
use trajpred::dataset::{Dataset, Segment, Segmentation, load};
use trajpred::harness::{EvalConfig, Split, drop_repeats, evaluate, group_folds, split_segments};
use trajpred::registry::{MethodOptions, build};
use trajpred_core::{Error, Result, Trajectory};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: &str| args.get(i).cloned().unwrap_or_else(|| d.to_string());
    let ds: Dataset = arg(1, "geolife").parse()?;
    let path = arg(2, "../shared/data/geolife");
    let max_gap: f64 = arg(3, "5").parse().unwrap_or(5.0);
    let min_points: usize = arg(4, "55").parse().unwrap_or(55);
    let bad = |v: &str| Error::invalid_parameter("training segmentation", v);
    let variants: Vec<(usize, f64)> = arg(5, "55:5,30:15")
        .split(',')
        .map(|v| {
            let (m, g) = v.split_once(':').ok_or_else(|| bad(v))?;
            Ok((
                m.parse().map_err(|_| bad(v))?,
                g.parse().map_err(|_| bad(v))?,
            ))
        })
        .collect::<Result<_>>()?;
    let methods = arg(6, "cv-time,aligned-mlp");
    let seg = |min_points, max_gap| Segmentation {
        max_gap: Some(max_gap),
        min_points,
        ..Default::default()
    };
    let long = load(
        ds,
        path.as_ref(),
        &ds.options(),
        &seg(min_points, max_gap),
        None,
    )?;
    let split = Split::ByGroup {
        train_fraction: 0.3,
        seed: 0,
    };
    // the test users are dropped here: nothing below sees them
    let (test_side, _) = split_segments(&long.segments, split)?;
    let (test_side, _, _) = drop_repeats(test_side, Vec::new());
    let mut users: Vec<String> = test_side.iter().map(|s| s.group.clone()).collect();
    users.sort_unstable();
    users.dedup();
    let keep: HashSet<&str> = users.iter().map(String::as_str).collect();
    let fold_of_user = group_folds(users.len(), 5, 0)?;
    let fold = |s: &Segment| fold_of_user[users.binary_search(&s.group).unwrap_or(0)];
    let tracks = |segs: &[Segment], f: usize, inside: bool| -> Vec<Trajectory> {
        segs.iter()
            .filter(|s| (fold(s) == f) == inside)
            .map(|s| s.trajectory.clone())
            .collect()
    };
    let eval = EvalConfig {
        history: 20,
        horizon: 5,
        ..Default::default()
    };
    let opts = MethodOptions {
        eval,
        ..Default::default()
    };
    eprintln!(
        "{} users; tested on {} segments of at least {min_points} points split at gaps over \
         {max_gap} s",
        users.len(),
        test_side.len(),
    );
    let mut pools = Vec::new();
    for &(m, g) in &variants {
        let loaded = load(ds, path.as_ref(), &ds.options(), &seg(m, g), None)?;
        let mine: Vec<Segment> = loaded
            .segments
            .into_iter()
            .filter(|s| keep.contains(s.group.as_str()))
            .collect();
        let (mine, _, _) = drop_repeats(mine, Vec::new());
        let points: usize = mine.iter().map(|s| s.trajectory.len()).sum();
        eprintln!(
            "training segmentation {m}:{g}: {} segments, {points} points",
            mine.len()
        );
        pools.push(((m, g), mine));
    }
    eprintln!(
        "| method | trained on (min points:max gap) | mean error (m), pooled | within 25 m | per fold |"
    );
    eprintln!("|---|---|---|---|---|");
    for name in methods.split(',') {
        for ((m, g), pool) in &pools {
            let (mut err, mut hits, mut n) = (0.0, 0.0, 0.0);
            let mut per_fold = Vec::new();
            for f in 0..5 {
                let mut p = build(name, &opts)?;
                p.fit(&tracks(pool, f, false))?;
                let r = evaluate(p.as_ref(), &tracks(&test_side, f, true), &eval, None)?;
                let w = (r.forecasts * eval.horizon) as f64;
                err += r.mean_euclidean_all * w;
                hits += r.hit_rate_all * w;
                n += w;
                per_fold.push(format!("{:.3}", r.mean_euclidean_all));
            }
            eprintln!(
                "| {name} | {m}:{g} | {:.3} | {:.2} % | {} |",
                err / n,
                100.0 * hits / n,
                per_fold.join(", ")
            );
        }
    }
    Ok(())
}
