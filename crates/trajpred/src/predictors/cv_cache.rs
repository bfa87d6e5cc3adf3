//! The candidates' forecasts on held-out folds, which `auto` ranks and `blend` combines:
//! computed once per candidate and fold, and shared between the two within one run when
//! their [`MethodOptions`] carry a [`HeldOutCache`].

use super::auto::fold_split;
use crate::harness::{self, EvalConfig};
use crate::registry::MethodOptions;
use std::collections::HashMap;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::sync::{Arc, Mutex};
use trajpred_core::{Predictor, Result, Trajectory};

/// One candidate's forecasts on one held-out fold, every origin's `horizon` points
/// flattened (`horizon * dim` values an origin), beside the true points likewise; or why
/// the candidate failed on that fold (a fit error, a refused forecast).
pub(crate) type FoldForecasts = std::result::Result<(Vec<f64>, Vec<f64>), String>;

/// The held-out forecasts of one training set, shared by the methods of one run that
/// cross-validate the same candidates on the same folds (`auto` and `blend`: fitting each
/// candidate on four folds of the training users is most of their time, and both do the
/// same fits). Put one in [`MethodOptions::held_out`] and every method built with those
/// options uses it; the CLI does so for each run.
///
/// An entry is keyed by the candidate, the fold and a fingerprint of everything else the
/// forecasts depend on: the training trajectories and their groups, the deal of folds,
/// the evaluation settings and the options the candidate is built with. Only one training
/// set is kept: entries of another fingerprint are dropped when a new one comes (an outer
/// cross-validation moves on to its next fold), which bounds the memory to one set of
/// candidates' forecasts. Sharing changes no result: an entry holds exactly what the
/// candidate would forecast again.
#[derive(Default)]
pub struct HeldOutCache {
    inner: Mutex<Inner>,
}

#[derive(Default)]
struct Inner {
    /// The fingerprint the entries belong to.
    data: u64,
    entries: HashMap<(String, usize), Arc<FoldForecasts>>,
    hits: usize,
}

impl HeldOutCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// How many held-out folds were read from the cache instead of fitted again.
    pub fn hits(&self) -> usize {
        self.inner.lock().map_or(0, |i| i.hits)
    }

    /// How many candidate-fold entries it holds.
    pub fn len(&self) -> usize {
        self.inner.lock().map_or(0, |i| i.entries.len())
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl std::fmt::Debug for HeldOutCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "HeldOutCache {{ entries: {}, hits: {} }}",
            self.len(),
            self.hits()
        )
    }
}

/// Two caches are equal when they are the same cache.
impl PartialEq for HeldOutCache {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
    }
}

/// Everything but the candidate and the fold that the held-out forecasts depend on.
pub(crate) fn fingerprint(
    train: &[Trajectory],
    groups: &[usize],
    fold: &[usize],
    eval: &EvalConfig,
    options: &MethodOptions,
) -> u64 {
    let mut h = DefaultHasher::new();
    for tr in train {
        tr.len().hash(&mut h);
        tr.dim().hash(&mut h);
        for v in tr.times() {
            v.to_bits().hash(&mut h);
        }
        for a in 0..tr.dim() {
            for v in tr.axis(a) {
                v.to_bits().hash(&mut h);
            }
        }
    }
    groups.hash(&mut h);
    fold.hash(&mut h);
    format!("{eval:?}").hash(&mut h);
    // the options as saved: everything but the cache itself
    serde_json::to_string(options)
        .unwrap_or_default()
        .hash(&mut h);
    h.finish()
}

/// What one fold's forecasts are computed from.
pub(crate) struct FoldJob<'a> {
    pub name: &'a str,
    pub build: &'a dyn Fn() -> Result<Box<dyn Predictor>>,
    pub train: &'a [Trajectory],
    pub groups: &'a [usize],
    pub fold: &'a [usize],
    pub eval: &'a EvalConfig,
    /// The cache and the [`fingerprint`] of this job's training set, if shared.
    pub shared: Option<(&'a HeldOutCache, u64)>,
}

impl<'a> FoldJob<'a> {
    /// The job of candidate `name` (made by `build`) on the folds `fold` of `train`, shared
    /// through `options.held_out` when it holds a cache (the fingerprint is then computed
    /// here).
    pub fn new(
        name: &'a str,
        build: &'a dyn Fn() -> Result<Box<dyn Predictor>>,
        (train, groups): (&'a [Trajectory], &'a [usize]),
        fold: &'a [usize],
        eval: &'a EvalConfig,
        options: &'a MethodOptions,
    ) -> Self {
        let shared = options
            .held_out
            .as_deref()
            .map(|c| (c, fingerprint(train, groups, fold, eval, options)));
        FoldJob {
            name,
            build,
            train,
            groups,
            fold,
            eval,
            shared,
        }
    }
}

/// The forecasts of `job.name` (made by `job.build`) fitted on the folds other than `f` and
/// run over fold `f` (the harness's rolling origins, [`harness::collect_forecasts`]), from
/// the cache when it holds them.
pub(crate) fn fold_forecasts(job: &FoldJob<'_>, f: usize) -> Result<Arc<FoldForecasts>> {
    let key = (job.name.to_string(), f);
    if let Some((cache, data)) = job.shared
        && let Ok(mut inner) = cache.inner.lock()
    {
        if inner.data != data {
            inner.entries.clear();
            inner.data = data;
        }
        if let Some(hit) = inner.entries.get(&key).cloned() {
            inner.hits += 1;
            return Ok(hit);
        }
    }
    let (fit, fit_groups, held) = fold_split(job.train, job.groups, job.fold, f);
    let mut p = (job.build)()?;
    let got = match p.fit_grouped(&fit, &fit_groups) {
        Err(e) => Err(format!("fold {f}: fit: {e}")),
        Ok(()) => match harness::collect_forecasts(p.as_ref(), &held, job.eval)? {
            Ok(pairs) => {
                let flat = |pick: fn(&harness::ForecastPair) -> &Vec<trajpred_core::Point>| {
                    pairs
                        .iter()
                        .flat_map(|pair| pick(pair).iter())
                        .flat_map(|x| x.as_ref().to_vec())
                        .collect::<Vec<f64>>()
                };
                Ok((flat(|p| &p.0), flat(|p| &p.1)))
            }
            Err(why) => Err(format!("fold {f}: {why}")),
        },
    };
    let got = Arc::new(got);
    if let Some((cache, data)) = job.shared
        && let Ok(mut inner) = cache.inner.lock()
        && inner.data == data
    {
        inner.entries.insert(key, got.clone());
    }
    Ok(got)
}
