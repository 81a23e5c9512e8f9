//! The shrinking steps of one parameter: toward its simplest value, then halfway.

use crate::rng::round3;

/// Shrinking steps of a positive parameter toward `simple`: the simple value itself, then
/// the geometric midpoint (3 significant digits), when different from `v`.
pub fn toward(v: f64, simple: f64) -> Vec<f64> {
    let mut out = Vec::new();
    if (v - simple).abs() > 1e-12 * simple.abs().max(1e-30) {
        out.push(simple);
        let mid = round3((v * simple).sqrt());
        if mid != v && mid != simple {
            out.push(mid);
        }
    }
    out
}

/// Shrinking steps of an integer toward `simple`: it, then the midpoint.
pub fn toward_int(v: u32, simple: u32) -> Vec<u32> {
    let mut out = Vec::new();
    if v != simple {
        out.push(simple);
        let mid = (v + simple) / 2;
        if mid != v && mid != simple {
            out.push(mid);
        }
    }
    out
}
