//! Boosted regression trees read off `forust-ml`'s boosters after fitting: evaluated without
//! allocation and saved compactly (`aligned-gbm`'s forecasts and parameters).

use super::fitted::{At, exact};
use forust_ml::GradientBooster;
use serde_json::{Value, json};
use trajpred_core::Result;

/// One tree, node by node (node 0 is the root; children come after their parent).
#[derive(Debug, Clone, PartialEq)]
struct Tree {
    /// The feature a node splits on; `None` for a leaf.
    feature: Vec<Option<u32>>,
    /// Rows with `x[feature] < threshold` go left, the others right.
    threshold: Vec<f64>,
    left: Vec<u32>,
    right: Vec<u32>,
    /// A leaf's value (0 for a split).
    value: Vec<f64>,
}

impl Tree {
    fn eval(&self, row: &[f64]) -> f64 {
        let mut i = 0usize;
        while let Some(f) = self.feature[i] {
            i = if row[f as usize] < self.threshold[i] {
                self.left[i]
            } else {
                self.right[i]
            } as usize;
        }
        self.value[i]
    }
}

/// A boosted ensemble: the base score plus every tree's leaf value, summed in the order
/// `forust-ml` sums them, so a prediction is the same number its `predict` gives.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ensemble {
    base: f64,
    trees: Vec<Tree>,
    features: usize,
}

impl Ensemble {
    /// The trees of a fitted booster over `features` features (rows without missing values:
    /// the missing-value branches are not kept).
    pub(crate) fn from_booster(b: &GradientBooster, features: usize) -> Self {
        let trees = b
            .trees
            .iter()
            .map(|t| {
                let mut tree = Tree {
                    feature: Vec::with_capacity(t.nodes.len()),
                    threshold: Vec::with_capacity(t.nodes.len()),
                    left: Vec::with_capacity(t.nodes.len()),
                    right: Vec::with_capacity(t.nodes.len()),
                    value: Vec::with_capacity(t.nodes.len()),
                };
                for n in &t.nodes {
                    let leaf = n.is_leaf;
                    tree.feature.push((!leaf).then_some(n.split_feature as u32));
                    tree.threshold.push(if leaf { 0.0 } else { n.split_value });
                    tree.left.push(if leaf { 0 } else { n.left_child as u32 });
                    tree.right.push(if leaf { 0 } else { n.right_child as u32 });
                    tree.value
                        .push(if leaf { f64::from(n.weight_value) } else { 0.0 });
                }
                tree
            })
            .collect();
        Ensemble {
            base: b.base_score,
            trees,
            features,
        }
    }

    /// The prediction for one row of [`Self::features`] values.
    pub(crate) fn predict(&self, row: &[f64]) -> f64 {
        debug_assert_eq!(row.len(), self.features);
        let mut p = self.base;
        for t in &self.trees {
            p += t.eval(row);
        }
        p
    }

    pub(crate) fn trees(&self) -> usize {
        self.trees.len()
    }

    /// `{"base", "trees": [{"feature", "threshold", "left", "right", "value"}]}`, node by
    /// node (`feature` -1 and `value` for a leaf; thresholds and values as exact strings).
    pub(crate) fn to_json(&self) -> Value {
        let trees: Vec<Value> = self
            .trees
            .iter()
            .map(|t| {
                json!({
                    "feature": t.feature.iter().map(|f| f.map_or(-1, i64::from)).collect::<Vec<_>>(),
                    "threshold": t.threshold.iter().map(|&x| exact(x)).collect::<Vec<_>>(),
                    "left": t.left,
                    "right": t.right,
                    "value": t.value.iter().map(|&x| exact(x)).collect::<Vec<_>>(),
                })
            })
            .collect();
        json!({ "base": exact(self.base), "trees": trees })
    }

    /// Reads [`Self::to_json`]'s form back, checking that every split names one of
    /// `features` and sends rows only to later nodes (so every row reaches a leaf).
    pub(crate) fn from_json(at: &At<'_>, features: usize, max_trees: usize) -> Result<Self> {
        let [base, trees] = at.fields(["base", "trees"])?;
        let base = base.f64()?;
        let trees = trees
            .items(None, max_trees)?
            .iter()
            .map(|t| read_tree(t, features))
            .collect::<Result<_>>()?;
        Ok(Ensemble {
            base,
            trees,
            features,
        })
    }
}

/// At most this many nodes a tree.
const MAX_NODES: usize = 1 << 16;

fn read_tree(at: &At<'_>, features: usize) -> Result<Tree> {
    let [feature, threshold, left, right, value] =
        at.fields(["feature", "threshold", "left", "right", "value"])?;
    let feature = feature.items(None, MAX_NODES)?;
    let n = feature.len();
    let (threshold, left, right, value) = (
        threshold.items(Some(n), n)?,
        left.items(Some(n), n)?,
        right.items(Some(n), n)?,
        value.items(Some(n), n)?,
    );
    let int = |a: &At<'_>| {
        a.value()
            .as_i64()
            .ok_or_else(|| a.error("expected a whole number"))
    };
    let mut t = Tree {
        feature: Vec::with_capacity(n),
        threshold: Vec::with_capacity(n),
        left: Vec::with_capacity(n),
        right: Vec::with_capacity(n),
        value: Vec::with_capacity(n),
    };
    for i in 0..n {
        let f = int(&feature[i])?;
        if f == -1 {
            t.feature.push(None);
            t.threshold.push(0.0);
            t.left.push(0);
            t.right.push(0);
            t.value.push(value[i].f64()?);
            continue;
        }
        if !(0..features as i64).contains(&f) {
            return Err(feature[i].error(format!(
                "a split's feature must be in 0..{features} (or -1 for a leaf), got {f}"
            )));
        }
        let child = |a: &At<'_>| -> Result<u32> {
            let c = int(a)?;
            if c > i as i64 && c < n as i64 {
                Ok(c as u32)
            } else {
                Err(a.error(format!(
                    "node {i}'s child must be a later node of the tree ({} to {}), got {c}",
                    i + 1,
                    n - 1
                )))
            }
        };
        t.feature.push(Some(f as u32));
        t.threshold.push(threshold[i].f64()?);
        t.left.push(child(&left[i])?);
        t.right.push(child(&right[i])?);
        t.value.push(0.0);
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use forust_ml::Matrix;
    use forust_ml::objective::ObjectiveType;

    #[test]
    fn predictions_and_their_json_round_trip_equal_forust_bit_for_bit() {
        // a deterministic, non-linear target of three features
        let rows = 2000;
        let x: Vec<f64> = (0..3 * rows)
            .map(|i| ((i * 7919) % 1000) as f64 / 100.0 - 5.0)
            .collect();
        let y: Vec<f64> = (0..rows)
            .map(|r| (x[r] * x[rows + r]).sin() + x[2 * rows + r].abs())
            .collect();
        let data = Matrix::new(&x, rows, 3);
        let mut b = GradientBooster::default()
            .set_objective_type(ObjectiveType::SquaredLoss)
            .set_iterations(30)
            .set_parallel(false);
        b.fit_unweighted(&data, &y, None).expect("fits");
        let ours = Ensemble::from_booster(&b, 3);
        let theirs = b.predict(&data, false);
        let json = ours.to_json();
        let back = Ensemble::from_json(&At::root("t", &json), 3, 100).expect("reads");
        assert_eq!(back, ours);
        for (r, want) in theirs.iter().enumerate() {
            let row = [x[r], x[rows + r], x[2 * rows + r]];
            assert_eq!(ours.predict(&row).to_bits(), want.to_bits(), "row {r}");
        }
    }

    #[test]
    fn bad_trees_name_the_field() {
        let bad = |tree: Value| {
            let v = json!({ "base": "0.5", "trees": [tree] });
            match Ensemble::from_json(&At::root("t", &v), 2, 10) {
                Err(trajpred_core::Error::InvalidFitted { path, .. }) => path,
                other => panic!("{other:?}"),
            }
        };
        let cycle = json!({"feature": [0, -1], "threshold": ["1", "0"], "left": [0, 0], "right": [1, 0], "value": ["0", "1"]});
        assert_eq!(bad(cycle), "trees[0].left[0]");
        let feature = json!({"feature": [2, -1, -1], "threshold": ["1", "0", "0"], "left": [1, 0, 0], "right": [2, 0, 0], "value": ["0", "1", "2"]});
        assert_eq!(bad(feature), "trees[0].feature[0]");
        let short =
            json!({"feature": [-1], "threshold": [], "left": [0], "right": [0], "value": ["1"]});
        assert_eq!(bad(short), "trees[0].threshold");
    }
}
