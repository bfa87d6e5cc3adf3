//! The crate's examples run.

#[path = "../examples/list_papers.rs"]
#[allow(dead_code)]
mod list_papers;

#[test]
fn list_papers_names_every_paper_with_a_consistent_spec() {
    let lines = list_papers::summary().expect("every spec reads");
    assert_eq!(lines.len(), 4);
    for (line, paper) in lines.iter().zip(trajpred_repro::Paper::ALL) {
        assert!(line.starts_with(paper.slug()), "{line}");
        assert!(line.ends_with(", 0 problems"), "{line}");
    }
}
