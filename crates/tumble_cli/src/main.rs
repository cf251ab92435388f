//! The `tumble` command line. Work in progress.
fn main() {}
