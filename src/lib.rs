//! Placeholder library so the root package (cross-crate tests and benches) builds.
