//! Placeholder: the hand-written matcher of `rules/outdoor.situ`.
fn main() {}
