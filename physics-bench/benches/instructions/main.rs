//! Instruction counts of the per-entity costs (Valgrind's Callgrind, through `gungraun`):
//! each benchmark runs one operation at two sizes, so the cost per entity is the slope
//! between them, and counts do not swing with the machine's load as wall time does.
//!
//! ```sh
//! .ci/instructions            # run them and check against the baselines (±2 %)
//! .ci/instructions --update   # write the new counts into baseline.json
//! ```
//!
//! One file per subject: `step` (a step per body: settled pile, awake pile, free bodies),
//! `publish` (a tick written into shared memory per body), `codec` (encoding and decoding
//! per command), `apply` (applying per command), `controllers` (a controller tick),
//! `history` (a snapshot and a rollback tick per body), `events` (an event record per
//! contact), `lua` (a Luau `part.CFrame` read, first and repeated, and a property write),
//! `record` (a frame of writes and a step with a recording running and without).
//! Every measured call runs on the benchmark's main thread (see [`common::one_thread`]),
//! which is the one Callgrind counts.

mod apply;
mod codec;
mod common;
mod controllers;
mod events;
mod history;
mod lua;
mod publish;
mod record;
mod step;

use apply::apply_group;
use codec::codec_group;
use controllers::controllers_group;
use events::events_group;
use history::history_group;
use lua::lua_group;
use publish::publish_group;
use record::record_group;
use step::step_group;

gungraun::main!(
    // The Lua benchmarks start a daemon: it runs natively, outside what is counted.
    config = gungraun::LibraryBenchmarkConfig::default().valgrind_args(["--trace-children=no"]);
    library_benchmark_groups = step_group,
    publish_group,
    codec_group,
    apply_group,
    controllers_group,
    history_group,
    events_group,
    lua_group,
    record_group
);
