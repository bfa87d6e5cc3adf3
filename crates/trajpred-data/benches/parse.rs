//! Parsing throughput.
fn main() {}
