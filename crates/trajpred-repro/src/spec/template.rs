//! Templates: the titles, notes, claim statements and evidence of a spec, filled at run time.
//!
//! `{name}` is a variable (a protocol parameter, a budget entry, or a value the compute code
//! gives) or a quantity; `{table/rows/column}` is a reference to table cells (see
//! [`super::claim`]). After `|` a format: `.N` (N decimals), `gN` (the tables' format with N
//! decimals, [`crate::report::format_number`]), `e` (scientific), `?` (Rust's debug form),
//! `list.N` and `listgN` (a list joined with ", "). Without a format a number prints in Rust's
//! display form and a list as `[a, b, c]`. `{{` and `}}` are literal braces. A text variable
//! may itself be a template.

use super::claim::Lookup;
use crate::report::format_number;

/// A template variable's value.
#[derive(Debug, Clone, PartialEq)]
pub enum Var {
    /// Text (itself a template).
    Text(String),
    /// A real number.
    Num(f64),
    /// An integer.
    Int(i64),
    /// A list.
    List(Vec<Var>),
}

impl From<&toml::Value> for Var {
    fn from(v: &toml::Value) -> Self {
        match v {
            toml::Value::String(s) => Var::Text(s.clone()),
            toml::Value::Integer(i) => Var::Int(*i),
            toml::Value::Float(x) => Var::Num(*x),
            toml::Value::Array(a) => Var::List(a.iter().map(Var::from).collect()),
            other => Var::Text(other.to_string()),
        }
    }
}

impl From<crate::report::Value> for Var {
    fn from(v: crate::report::Value) -> Self {
        use crate::report::Value;
        match v {
            Value::Text(t) => Var::Text(t),
            Value::Num(x) => Var::Num(x),
            Value::Missing => Var::Text("—".into()),
        }
    }
}

/// Where a template's names are looked up.
pub trait Source: Lookup {
    /// The variable called `name`.
    fn var(&self, name: &str) -> Option<Var>;
}

fn number(x: f64, format: &str) -> Result<String, String> {
    Ok(match format {
        "" => format!("{x}"),
        "?" => format!("{x:?}"),
        "e" => format!("{x:e}"),
        f => {
            if let Some(d) = f.strip_prefix('.') {
                let d: usize = d.parse().map_err(|_| format!("bad format `{f}`"))?;
                format!("{x:.d$}")
            } else if let Some(d) = f.strip_prefix('g') {
                format_number(x, d.parse().map_err(|_| format!("bad format `{f}`"))?)
            } else {
                return Err(format!("unknown format `{f}`"));
            }
        }
    })
}

fn show(v: &Var, format: &str, src: &dyn Source, depth: usize) -> Result<String, String> {
    match v {
        Var::Text(t) if depth < 4 => render_at(t, src, depth + 1),
        Var::Text(t) => Ok(t.clone()),
        Var::Int(i) if format.is_empty() => Ok(i.to_string()),
        Var::Int(i) => number(*i as f64, format),
        Var::Num(x) => number(*x, format),
        Var::List(items) => match format.strip_prefix("list") {
            Some(f) => Ok(items
                .iter()
                .map(|i| show(i, f, src, depth))
                .collect::<Result<Vec<_>, _>>()?
                .join(", ")),
            None => {
                let items: Vec<String> = items
                    .iter()
                    .map(|i| match i {
                        Var::Num(x) => format!("{x:?}"),
                        Var::Text(t) => format!("{t:?}"),
                        other => show(other, "", src, depth).unwrap_or_default(),
                    })
                    .collect();
                Ok(format!("[{}]", items.join(", ")))
            }
        },
    }
}

fn resolve(name: &str, src: &dyn Source) -> Option<Var> {
    if !name.contains('/')
        && let Some(v) = src.var(name)
    {
        return Some(v);
    }
    match src.numbers(name)?.as_slice() {
        [x] => Some(Var::Num(*x)),
        xs => Some(Var::List(xs.iter().map(|&x| Var::Num(x)).collect())),
    }
}

/// Fills `text`; an unknown name, an unclosed brace or a bad format is an error naming it.
pub fn render(text: &str, src: &dyn Source) -> Result<String, String> {
    render_at(text, src, 0)
}

fn render_at(text: &str, src: &dyn Source, depth: usize) -> Result<String, String> {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        match c {
            '{' if chars.peek().map(|p| p.1) == Some('{') => {
                chars.next();
                out.push('{');
            }
            '}' if chars.peek().map(|p| p.1) == Some('}') => {
                chars.next();
                out.push('}');
            }
            '{' => {
                let rest = &text[i + 1..];
                let end = rest
                    .find('}')
                    .ok_or_else(|| format!("unclosed {{ in {text:?}"))?;
                let token = &rest[..end];
                let (name, format) = token.split_once('|').unwrap_or((token, ""));
                let v = resolve(name, src).ok_or_else(|| format!("unknown name `{name}`"))?;
                out.push_str(&show(&v, format, src, depth)?);
                for _ in 0..rest[..=end].chars().count() {
                    chars.next();
                }
            }
            c => out.push(c),
        }
    }
    Ok(out)
}

/// The names a template refers to (for the spec's consistency check).
pub fn names(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text.replace("{{", "").replace("}}", "");
    while let Some(i) = rest.find('{') {
        let after = rest[i + 1..].to_string();
        let Some(end) = after.find('}') else { break };
        let token = &after[..end];
        out.push(token.split_once('|').map_or(token, |p| p.0).to_string());
        rest = after[end + 1..].to_string();
    }
    out
}
