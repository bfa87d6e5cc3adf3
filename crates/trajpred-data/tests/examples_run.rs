//! The crate's user example runs on the GeoLife-format fixture.

#[path = "../examples/load_geolife.rs"]
#[allow(dead_code)]
mod load_geolife;

#[test]
fn loading_the_geolife_fixture_accounts_for_every_line() {
    let dir = load_geolife::fixture();
    let s = load_geolife::run(&dir).expect("the example runs");
    // every line after a .plt file's 6 header lines is kept, counted as skipped (by reason)
    // or counted as blank
    let mut data_lines = 0;
    for f in std::fs::read_dir(dir.join("000/Trajectory")).expect("fixture folder") {
        let text = std::fs::read_to_string(f.expect("entry").path()).expect("plt");
        data_lines += text.lines().count() - 6;
    }
    assert_eq!(
        s.points + s.report.skipped_total() + s.report.blank_lines,
        data_lines,
        "{:?}",
        s.report
    );
    assert_eq!(s.tracks, 2);
    assert!(s.segments >= s.tracks);
}
