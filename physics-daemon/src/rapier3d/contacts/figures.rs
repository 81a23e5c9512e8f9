//! The contact figures of the tick header: deepest penetration and touching pairs.

use rapier3d::prelude::*;
use rayon::prelude::*;

use crate::rapier3d::objects::body_pass::MIN_TASK;

/// Deepest penetration and number of touching pairs, for the tick header. `split`: in
/// pieces on the current rayon pool (the figures do not depend on the order pairs are
/// visited in).
pub(crate) fn contact_figures(narrow_phase: &NarrowPhase, split: bool) -> (f32, u32) {
    let edges = narrow_phase.contact_graph().raw_graph().raw_edges();
    if split {
        // One task per chunk: run beside the state hash, the figures are taken up by
        // whichever thread is free, chunk by chunk (rayon would otherwise split them in
        // two and leave the half it kept to one thread).
        edges
            .par_chunks(MIN_TASK)
            .with_max_len(1)
            .map(|chunk| pair_figures(chunk, |e| &e.weight))
            .reduce(|| (0.0, 0), |a, b| (deeper(a.0, b.0), a.1 + b.1))
    } else {
        pair_figures(edges, |e| &e.weight)
    }
}

/// Deepest penetration (0 without any) and number of touching pairs among `items`.
fn pair_figures<'a, T>(items: &'a [T], pair: impl Fn(&'a T) -> &'a ContactPair) -> (f32, u32) {
    items
        .iter()
        .filter_map(|item| pair(item).find_deepest_contact())
        .fold((0.0, 0), |(deepest, n), (_, c)| {
            (deeper(deepest, -c.dist), n + 1)
        })
}

/// The larger depth; a tie or a NaN keeps `a`, so any grouping of the pairs gives the same
/// bits.
fn deeper(a: f32, b: f32) -> f32 {
    if b > a {
        b
    } else {
        a
    }
}
