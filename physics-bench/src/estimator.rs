//! How a row judged on a noisy machine is measured: the named estimators (see
//! docs/benchmarks.md). Filled in by the rows that use it.
