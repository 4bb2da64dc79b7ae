//! CPU reference of `kernels/scan.cl`: exclusive prefix sum of `u32` values
//! with the running sum in `u64`, so a total above `u32::MAX` is an error
//! (and the values are left unchanged), never a wrap. One serial loop; the
//! device's chunking does not change the result.

use crate::error::{Error, Result};

/// Replaces `values[i]` by `values[0] + … + values[i-1]` and returns the sum
/// of all values (0 for an empty slice). Errors with [`Error::InvalidInput`],
/// leaving `values` unchanged, when that sum exceeds `u32::MAX`.
pub fn exclusive(values: &mut [u32]) -> Result<u64> {
    let total: u64 = values.iter().map(|&v| u64::from(v)).sum();
    if total > u64::from(u32::MAX) {
        return Err(Error::input(
            "exclusive scan",
            format!("sum of {} values", values.len()),
            format!(
                "{total} exceeds u32::MAX ({}); the output was left unchanged",
                u32::MAX
            ),
        ));
    }
    let mut run = 0u32;
    for v in values.iter_mut() {
        let x = *v;
        *v = run;
        run += x; // cannot overflow: run <= total <= u32::MAX
    }
    Ok(total)
}
