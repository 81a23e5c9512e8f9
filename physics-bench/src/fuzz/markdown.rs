//! The human-readable `fuzz.md`.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::fuzz_report::FuzzReport;
use crate::report::{mib, num, Table};

/// How the run is made (also stored in the JSON).
pub fn method() -> BTreeMap<&'static str, &'static str> {
    BTreeMap::from([
        (
            "daemon",
            "a real physics-daemon process in a throw-away domain, with the quota flags listed \
             (the per-request quotas and the per-object mesh size at their defaults, the \
             per-client totals lowered so a quota round reaches them in milliseconds); its \
             stderr goes to fuzz-daemon.log.",
        ),
        (
            "clients",
            "several client-sdk clients in one thread, taking turns at random; every frame \
             goes through Client::raw_request (raw bytes in, raw reply out).",
        ),
        (
            "structured frames",
            "well-formed frames (codec::encode_request) of 1 to 1,000 commands, every \
             Command / PlaneOp / ObjectOp variant with every PlaneProp / ObjectProp; each \
             command is valid (own planes, live handles, realistic values: steps of 1 µs to \
             1 s, objects of every shape, property changes) or wild (NaN, ±inf, ±0, \
             1e-45, ±1e38, random bits; stale, neighbouring, random and out-of-range \
             handles; unknown and destroyed plane ids; meshes with 0-3, coplanar, \
             collinear, coincident, huge, tiny or 1,000-4,000 vertices, triangle indices \
             past the end, 20,000 triangles). Valid planes are kept small (120 objects).",
        ),
        (
            "raw frames",
            "a quarter of the batches: random bytes (up to 4 KiB), the magic and version \
             followed by random bytes, a four-billion command count, or a structured frame \
             truncated, bit-flipped, with bytes inserted, deleted or set to boundary values, \
             doubled, with a wrong magic or another layout version.",
        ),
        (
            "quota rounds",
            "every 150 batches, requests built to exceed the next quota in turn: 262,145 \
             commands; a 16 MiB + 1 frame; a mesh of max + 1 vertices; max + 1 objects; \
             max + 1 planes; meshes past the per-client vertex total.",
        ),
        (
            "checks",
            "after every frame: the daemon process still runs, and the reply decodes as a \
             Response of the shape the frame calls for: the codec (the same one the daemon \
             uses) predicts one result per command, a Malformed or Quota rejection, or the \
             version-neutral reply, which is then followed by an empty request whose reply \
             must decode. A crash is a daemon exit or an undecodable reply.",
        ),
        (
            "determinism",
            "the input is a function of the seed and of earlier replies (the planes and \
             handles they returned); one thread sends everything, so with manual planes a \
             seed replays the same run; planes the fuzzer set ticking add wall-clock timing.",
        ),
    ])
}

pub fn render(r: &FuzzReport) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# physics-bench fuzz\n\nSeed {} (`physics-bench fuzz --seed {}` replays the input), \
         {} clients, {:.0} s. Daemon flags: `{}`.\n",
        r.seed,
        r.seed,
        r.clients,
        r.seconds,
        r.daemon_flags.join(" ")
    );
    let _ = writeln!(
        md,
        "## Frames\n\n\
         - batches: {}\n\
         - frames: {} ({} frames/s): {} structured, {} raw, {} in quota rounds, {} probes\n\
         - commands (in frames the daemon decoded, each with its own result): {} ({} \
         commands/s)\n\
         - fuzzed commands that succeeded: {:.1} %\n\
         - daemon RSS: {} MiB at start, {} MiB at the end",
        r.batches,
        r.frames,
        num(Some(r.frames_per_s)),
        r.structured_frames,
        r.raw_frames,
        r.quota_frames,
        r.probe_frames,
        r.commands,
        num(Some(r.commands_per_s)),
        r.ok_fraction * 100.0,
        mib(r.daemon_rss_start_bytes as f64),
        r.daemon_rss_end_bytes.map_or("—".into(), |b| mib(b as f64)),
    );

    md.push_str("\n## Replies by kind\n\n");
    let mut t = Table::new(&["reply", "kind", "count"]);
    for (k, v) in &r.ok {
        t.row(&["Ok".into(), k.clone(), v.to_string()]);
    }
    for (k, v) in &r.errors {
        t.row(&["command error".into(), k.clone(), v.to_string()]);
    }
    for (k, v) in &r.rejected {
        t.row(&["request rejected".into(), k.clone(), v.to_string()]);
    }
    t.row(&[
        "version-neutral reply".into(),
        "VersionMismatch".into(),
        r.version_replies.to_string(),
    ]);
    t.row(&[
        "crash".into(),
        "exit or undecodable".into(),
        r.crashes.to_string(),
    ]);
    t.row(&["no reply".into(), "".into(), r.unanswered.to_string()]);
    t.row(&[
        "wrong shape".into(),
        "".into(),
        r.protocol_errors.to_string(),
    ]);
    md.push_str(&t.finish());

    md.push_str("\n## Quotas\n\n");
    let mut t = Table::new(&[
        "quota",
        "rounds",
        "rounds refused",
        "quota errors (all frames)",
    ]);
    for flag in physics_fuzz::QUOTA_FLAGS {
        let q = r.quota_rounds.get(flag);
        t.row(&[
            format!("`{flag}`"),
            q.map_or(0, |q| q.runs).to_string(),
            q.map_or(0, |q| q.hit).to_string(),
            r.quota_hits.get(flag).copied().unwrap_or(0).to_string(),
        ]);
    }
    md.push_str(&t.finish());

    md.push_str("\n## Ops (fuzzed commands)\n\n");
    let mut t = Table::new(&["op", "sent", "ok", "ok %"]);
    for (op, c) in &r.ops {
        t.row(&[
            op.clone(),
            c.sent.to_string(),
            c.ok.to_string(),
            num(Some(c.ok as f64 / c.sent.max(1) as f64 * 100.0)),
        ]);
    }
    md.push_str(&t.finish());
    if !r.ops_not_sent.is_empty() {
        let _ = writeln!(md, "\nNever sent: {}.", r.ops_not_sent.join(", "));
    }

    md.push_str("\n## Findings\n\n");
    if r.findings.is_empty() && r.daemon_panics.is_empty() {
        md.push_str("None.\n");
    }
    for f in &r.findings {
        let _ = writeln!(
            md,
            "- {} in batch {} (client {}): {}{}",
            f.kind,
            f.batch,
            f.client,
            f.detail,
            f.frame_file
                .as_ref()
                .map_or(String::new(), |p| format!(" — frame: `{p}`"))
        );
    }
    if !r.daemon_panics.is_empty() {
        md.push_str("\nPanics in the daemon log (caught; each removed one plane):\n\n");
        for (what, n) in &r.daemon_panics {
            let _ = writeln!(md, "- {n} × {what}");
        }
    }

    md.push_str("\n## Method\n\n");
    for (name, text) in &r.method {
        let _ = writeln!(md, "- **{name}**: {text}");
    }
    md
}
