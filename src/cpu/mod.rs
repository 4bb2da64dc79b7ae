//! Plain Rust reference implementations of the device stages, in f64, with
//! the same step names as the kernels. Deliberately simple: they are the
//! oracles the tests compare the device with.

pub mod curvature;
pub mod radix_sort;
pub mod scan;
