//! What each paper's spec (`papers/<slug>.toml`) holds: the section of `docs/papers.md`, the
//! methods compared, the tables and the claims, and whether the spec is consistent.
//!
//! ```text
//! cargo run -p trajpred-repro --example list_papers
//! ```
#![allow(clippy::print_stdout)]

use trajpred_repro::Paper;

/// One line per paper: slug, section, methods, tables, claims and the spec's problems.
pub fn summary() -> Result<Vec<String>, Box<dyn std::error::Error>> {
    let mut out = Vec::new();
    for paper in Paper::ALL {
        let spec = paper.spec()?;
        let tables: usize = spec.sections.iter().map(|s| s.tables.len()).sum();
        let claims: usize = spec.sections.iter().map(|s| s.claims.len()).sum();
        let methods: Vec<&str> = spec.methods.iter().map(|m| m.label.as_str()).collect();
        out.push(format!(
            "{} (docs/papers.md {}): {} methods [{}], {tables} table specs, {claims} claim specs, {} problems",
            paper.slug(),
            spec.anchor,
            methods.len(),
            methods.join(", "),
            spec.problems().len()
        ));
    }
    Ok(out)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    for line in summary()? {
        println!("{line}");
    }
    Ok(())
}
