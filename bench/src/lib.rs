//! Benchmarks: see README Performance.
