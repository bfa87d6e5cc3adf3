//! How a claim is decided: a condition ([`Cond`]) on numbers ([`Expr`]) taken from the run's
//! table cells and quantities by reference.
//!
//! A reference is `table/rows/column` (a table id, a row selector and a column key) or the
//! name of a quantity. The row selector is a row key, a comma-separated list of keys, `*` (every
//! row, in table order) or a pattern with one `*` (`*:kfu`: every row whose key ends in `:kfu`).
//! A reference therefore gives a list of numbers; comparisons hold when they hold element by
//! element (a single number is compared with every element of the other side).

use serde::Deserialize;

/// A number, or a list of numbers.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum Expr {
    /// A constant.
    Num(f64),
    /// A reference to table cells or a quantity.
    Ref(String),
    /// An operation.
    Op(Box<Op>),
}

/// An operation on numbers.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Op {
    /// The smallest of every element of every argument.
    Min(Vec<Expr>),
    /// The largest of every element of every argument.
    Max(Vec<Expr>),
    /// Element-wise difference.
    Sub([Expr; 2]),
}

/// A condition.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Cond {
    /// `a < b`, element-wise.
    Lt([Expr; 2]),
    /// `a <= b`, element-wise.
    Le([Expr; 2]),
    /// `a > b`, element-wise.
    Gt([Expr; 2]),
    /// Every condition holds.
    All(Vec<Cond>),
    /// `|(value - target) / target| <= tol`.
    WithinRel {
        /// Our number.
        value: Expr,
        /// The paper's.
        target: Expr,
        /// Relative tolerance.
        tol: f64,
    },
    /// `|value - target| <= tol`.
    WithinAbs {
        /// Our number.
        value: Expr,
        /// The paper's.
        target: Expr,
        /// Absolute tolerance.
        tol: f64,
    },
    /// `target / factor <= value <= target * factor`.
    WithinFactor {
        /// Our number.
        value: Expr,
        /// The paper's.
        target: Expr,
        /// The factor.
        factor: f64,
    },
    /// The row selected by `of` with the smallest value (the first one on ties) has key `is`.
    Argmin {
        /// A reference selecting several rows of one column.
        of: String,
        /// The row key expected.
        is: String,
    },
    /// Each element is larger than the one before.
    Increasing(Expr),
    /// Each element is no larger than the one before.
    NonIncreasing(Expr),
}

/// Where references are looked up.
pub trait Lookup {
    /// The numbers a reference gives, `None` when a table, row or quantity is not in the run.
    fn numbers(&self, reference: &str) -> Option<Vec<f64>>;
    /// The row keys a reference selects, in table order.
    fn row_keys(&self, reference: &str) -> Option<Vec<String>>;
}

type MapRef<'a, E> = dyn FnMut(&str) -> Result<String, E> + 'a;

impl Expr {
    fn map_refs<E>(&self, f: &mut MapRef<'_, E>) -> Result<Expr, E> {
        Ok(match self {
            Expr::Num(x) => Expr::Num(*x),
            Expr::Ref(r) => Expr::Ref(f(r)?),
            Expr::Op(op) => Expr::Op(Box::new(match op.as_ref() {
                Op::Min(v) => Op::Min(map_all(v, f)?),
                Op::Max(v) => Op::Max(map_all(v, f)?),
                Op::Sub([a, b]) => Op::Sub([a.map_refs(f)?, b.map_refs(f)?]),
            })),
        })
    }

    /// Every reference of the expression.
    pub fn refs(&self, out: &mut Vec<String>) {
        match self {
            Expr::Num(_) => {}
            Expr::Ref(r) => out.push(r.clone()),
            Expr::Op(op) => match op.as_ref() {
                Op::Min(v) | Op::Max(v) => v.iter().for_each(|e| e.refs(out)),
                Op::Sub([a, b]) => {
                    a.refs(out);
                    b.refs(out);
                }
            },
        }
    }

    /// The numbers of the expression, `None` when a reference is not in the run.
    pub fn eval(&self, l: &dyn Lookup) -> Option<Vec<f64>> {
        match self {
            Expr::Num(x) => Some(vec![*x]),
            Expr::Ref(r) => l.numbers(r),
            Expr::Op(op) => match op.as_ref() {
                Op::Min(v) => Some(vec![flat(v, l)?.into_iter().fold(f64::INFINITY, f64::min)]),
                Op::Max(v) => Some(vec![
                    flat(v, l)?.into_iter().fold(f64::NEG_INFINITY, f64::max),
                ]),
                Op::Sub([a, b]) => pairs(&a.eval(l)?, &b.eval(l)?)
                    .map(|p| p.into_iter().map(|(x, y)| x - y).collect()),
            },
        }
    }
}

fn map_all<E>(v: &[Expr], f: &mut MapRef<'_, E>) -> Result<Vec<Expr>, E> {
    v.iter().map(|e| e.map_refs(f)).collect()
}

fn flat(v: &[Expr], l: &dyn Lookup) -> Option<Vec<f64>> {
    let mut out = Vec::new();
    for e in v {
        out.extend(e.eval(l)?);
    }
    Some(out)
}

/// Element pairs of two lists of equal length, or of a single number and a list.
fn pairs(a: &[f64], b: &[f64]) -> Option<Vec<(f64, f64)>> {
    match (a.len(), b.len()) {
        (0, _) | (_, 0) => None,
        (1, n) => Some(b.iter().map(|&y| (a[0], y)).take(n).collect()),
        (n, 1) => Some(a.iter().map(|&x| (x, b[0])).take(n).collect()),
        (n, m) if n == m => Some(a.iter().copied().zip(b.iter().copied()).collect()),
        _ => None,
    }
}

fn compare(a: &Expr, b: &Expr, l: &dyn Lookup, op: fn(f64, f64) -> bool) -> Option<bool> {
    Some(
        pairs(&a.eval(l)?, &b.eval(l)?)?
            .into_iter()
            .all(|(x, y)| op(x, y)),
    )
}

fn scalar(e: &Expr, l: &dyn Lookup) -> Option<f64> {
    match e.eval(l)?.as_slice() {
        [x] => Some(*x),
        _ => None,
    }
}

impl Cond {
    /// The condition with every reference passed through `f` (instance variables).
    pub fn map_refs<E>(&self, f: &mut MapRef<'_, E>) -> Result<Cond, E> {
        let two = |[a, b]: &[Expr; 2], f: &mut MapRef<'_, E>| -> Result<[Expr; 2], E> {
            Ok([a.map_refs(f)?, b.map_refs(f)?])
        };
        Ok(match self {
            Cond::Lt(p) => Cond::Lt(two(p, f)?),
            Cond::Le(p) => Cond::Le(two(p, f)?),
            Cond::Gt(p) => Cond::Gt(two(p, f)?),
            Cond::All(v) => Cond::All(v.iter().map(|c| c.map_refs(f)).collect::<Result<_, E>>()?),
            Cond::WithinRel { value, target, tol } => Cond::WithinRel {
                value: value.map_refs(f)?,
                target: target.map_refs(f)?,
                tol: *tol,
            },
            Cond::WithinAbs { value, target, tol } => Cond::WithinAbs {
                value: value.map_refs(f)?,
                target: target.map_refs(f)?,
                tol: *tol,
            },
            Cond::WithinFactor {
                value,
                target,
                factor,
            } => Cond::WithinFactor {
                value: value.map_refs(f)?,
                target: target.map_refs(f)?,
                factor: *factor,
            },
            Cond::Argmin { of, is } => Cond::Argmin {
                of: f(of)?,
                is: is.clone(),
            },
            Cond::Increasing(e) => Cond::Increasing(e.map_refs(f)?),
            Cond::NonIncreasing(e) => Cond::NonIncreasing(e.map_refs(f)?),
        })
    }

    /// Every reference of the condition.
    pub fn refs(&self) -> Vec<String> {
        let mut out = Vec::new();
        let mut exprs: Vec<&Expr> = Vec::new();
        match self {
            Cond::Lt([a, b]) | Cond::Le([a, b]) | Cond::Gt([a, b]) => exprs.extend([a, b]),
            Cond::All(v) => v.iter().for_each(|c| out.extend(c.refs())),
            Cond::WithinRel { value, target, .. }
            | Cond::WithinAbs { value, target, .. }
            | Cond::WithinFactor { value, target, .. } => exprs.extend([value, target]),
            Cond::Argmin { of, .. } => out.push(of.clone()),
            Cond::Increasing(e) | Cond::NonIncreasing(e) => exprs.push(e),
        }
        exprs.into_iter().for_each(|e| e.refs(&mut out));
        out
    }

    /// Whether the condition holds, `None` when a reference is not in the run.
    pub fn eval(&self, l: &dyn Lookup) -> Option<bool> {
        match self {
            Cond::Lt([a, b]) => compare(a, b, l, |x, y| x < y),
            Cond::Le([a, b]) => compare(a, b, l, |x, y| x <= y),
            Cond::Gt([a, b]) => compare(a, b, l, |x, y| x > y),
            Cond::All(v) => {
                let mut holds = true;
                for c in v {
                    holds &= c.eval(l)?;
                }
                Some(holds)
            }
            Cond::WithinRel { value, target, tol } => {
                let (v, t) = (scalar(value, l)?, scalar(target, l)?);
                Some(((v - t) / t).abs() <= *tol)
            }
            Cond::WithinAbs { value, target, tol } => {
                let (v, t) = (scalar(value, l)?, scalar(target, l)?);
                Some((v - t).abs() <= *tol)
            }
            Cond::WithinFactor {
                value,
                target,
                factor,
            } => {
                let (v, t) = (scalar(value, l)?, scalar(target, l)?);
                Some((t / factor..=t * factor).contains(&v))
            }
            Cond::Argmin { of, is } => {
                let values = l.numbers(of)?;
                let keys = l.row_keys(of)?;
                let best = values
                    .iter()
                    .enumerate()
                    .min_by(|a, b| a.1.total_cmp(b.1))
                    .map(|(i, _)| i)?;
                Some(keys.get(best) == Some(is))
            }
            Cond::Increasing(e) => Some(e.eval(l)?.windows(2).all(|w| w[1] > w[0])),
            Cond::NonIncreasing(e) => Some(e.eval(l)?.windows(2).all(|w| w[1] <= w[0])),
        }
    }
}
