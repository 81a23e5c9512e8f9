//! Applying a run of ops to a plane, inline or on its worker: each op under a panic guard,
//! a large snapshot staged as a download, and every result counted against the request's
//! reply bytes.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Instant;

use shm_layout::{CommandError, CommandResult, ErrorKind, PlaneId, PlaneOp, PlaneProp, Reply};

use crate::backend::{Backend, Usage};
use crate::publish::PlaneOutput;
use crate::server::quotas::limits::{exceeded, Limits};
use crate::server::requests::refusals::{self, unknown_plane};

use super::messages::{Budget, SharedUsage};

/// Applies a run of ops in order. A panic fails the plane: that op gets an error naming it,
/// the rest of the run find the plane gone. `out` is the plane's output (on its worker;
/// `None` inline, where runs hold no op that needs it).
pub(crate) fn run_ops(
    id: PlaneId,
    plane: &mut dyn Backend,
    ops: Vec<PlaneOp>,
    budget: &Budget,
    usage: &SharedUsage,
    out: Option<&PlaneOutput>,
    panic_on_step_dt: Option<f32>,
) -> (Vec<CommandResult>, bool) {
    let mut results = Vec::with_capacity(ops.len());
    let mut reply_left = budget.reply_left;
    let mut ops = ops.into_iter();
    for op in ops.by_ref() {
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            apply_op(id, plane, out, panic_on_step_dt, op, budget, usage)
        }));
        match outcome {
            Ok(result) => {
                let result = stage_large(result, reply_left, budget);
                let result = count_reply(result, &mut reply_left, &budget.limits);
                results.push(result)
            }
            Err(panic) => {
                let message = refusals::panic_message(panic.as_ref());
                tracing::error!(plane = id, "plane failed and was removed: {message}");
                results.push(Err(CommandError::new(
                    ErrorKind::Internal,
                    format!("plane {id} failed and was removed: {message}"),
                )));
                results.extend(ops.map(|_| Err(unknown_plane(id))));
                return (results, true);
            }
        }
    }
    (results, false)
}

fn apply_op(
    id: PlaneId,
    plane: &mut dyn Backend,
    out: Option<&PlaneOutput>,
    panic_on_step_dt: Option<f32>,
    op: PlaneOp,
    budget: &Budget,
    usage: &SharedUsage,
) -> CommandResult {
    let cost = op.cost();
    if let PlaneOp::Set(PlaneProp::SharedObjectLimit(limit)) = op {
        let result = apply_inner(plane, out, panic_on_step_dt, op);
        if result.is_ok() {
            usage.set_guest_limit(limit);
        }
        return result;
    }
    if let PlaneOp::Step { .. } = op {
        // Explicit steps are charged to the owner's CPU account (never postponed).
        let started = Instant::now();
        let result = apply_inner(plane, out, panic_on_step_dt, op);
        let now = Instant::now();
        usage.owner().cpu.charge(now - started, now);
        return result;
    }
    if cost == Default::default() {
        return apply_inner(plane, out, panic_on_step_dt, op);
    }
    // An object another process adds to this (shared) plane counts against that process,
    // within the owner's SharedObjectLimit, for as long as the object lives.
    if let (Some(guest), PlaneOp::AddObject { .. }) = (&budget.guest, &op) {
        usage.check_guest_room(id, cost.objects as u64)?;
        let reserved = guest.reserve(&budget.limits, cost)?;
        let result = apply_inner(plane, out, panic_on_step_dt, op);
        if let Ok(Reply::Object { handle, .. }) = &result {
            reserved.keep();
            let paid = Usage {
                objects: cost.objects as u64,
                mesh_vertices: cost.mesh_vertices,
                state_bytes: cost.state_bytes,
            };
            usage.add_guest(*handle, guest.clone(), paid);
        }
        usage.update(&*plane);
        return result;
    }
    // Reserved before the op runs, released after the plane's count holds what it added:
    // runs of the same process on other planes cannot overtake it.
    let _reserved = usage.owner().reserve(&budget.limits, cost)?;
    let result = apply_inner(plane, out, panic_on_step_dt, op);
    usage.update(&*plane);
    result
}

fn apply_inner(
    plane: &mut dyn Backend,
    out: Option<&PlaneOutput>,
    panic_on_step_dt: Option<f32>,
    op: PlaneOp,
) -> CommandResult {
    let needs_output = matches!(
        op,
        PlaneOp::Step { .. } | PlaneOp::Info | PlaneOp::Restore { .. } | PlaneOp::Rewind(_)
    );
    let out = match out {
        Some(out) => Some(out),
        None if needs_output => {
            return Err(CommandError::new(
                ErrorKind::Internal,
                format!("{} must run on the plane's worker", op_name(&op)),
            ))
        }
        None => None,
    };
    match op {
        PlaneOp::Step { dt } => {
            if panic_on_step_dt == Some(dt) {
                panic!("injected fault: Step({dt})");
            }
            if plane.step(dt)? {
                if let Some(out) = out {
                    out.publish(plane).map_err(refusals::internal)?;
                }
            }
            Ok(Reply::Stepped { tick: plane.tick() })
        }
        // Readers see the restored state at once, as after a step.
        op @ (PlaneOp::Restore { .. } | PlaneOp::Rewind(_)) => {
            let reply = plane.apply(op)?;
            if let Some(out) = out {
                out.publish(plane).map_err(refusals::internal)?;
            }
            Ok(reply)
        }
        op => {
            if op == PlaneOp::Info {
                // A reader that just subscribed gets the newest tick at once.
                if let Some(out) = out {
                    out.connect_readers();
                }
            }
            plane.apply(op)
        }
    }
}

/// The op's variant for messages (never its payload: a restore carries megabytes).
fn op_name(op: &PlaneOp) -> &'static str {
    match op {
        PlaneOp::Step { .. } => "Step",
        PlaneOp::Info => "Info",
        PlaneOp::Restore { .. } => "Restore",
        PlaneOp::Rewind(_) => "Rewind",
        _ => "this op",
    }
}

/// A snapshot larger than [`shm_layout::snapshot_transfer::STAGE_ABOVE`] (or than what the
/// reply may still hold) is kept as a download of the requester's and answered with its
/// number; everything else passes unchanged.
fn stage_large(result: CommandResult, reply_left: usize, budget: &Budget) -> CommandResult {
    match (result, &budget.transfers) {
        (Ok(Reply::Snapshot(bytes)), Some(transfers))
            if bytes.len() > shm_layout::snapshot_transfer::STAGE_ABOVE.min(reply_left) =>
        {
            transfers.stage(bytes)
        }
        (result, _) => result,
    }
}

/// Results up to this size always go out (an acknowledgement, a step's tick): they are
/// about as big as the commands that asked for them, so they amplify nothing.
const SMALL_RESULT: usize = 64;

/// `result`, or a `Quota` error when it would pass what the request's reply may still
/// hold; takes its size from `left`.
fn count_reply(result: CommandResult, left: &mut usize, limits: &Limits) -> CommandResult {
    let size = shm_layout::codec::result_size(&result);
    if size > *left && size > SMALL_RESULT {
        let used = limits.reply_bytes.saturating_sub(*left);
        return Err(exceeded(
            "reply bytes per request",
            limits.reply_bytes,
            "max-reply-bytes",
            used.saturating_add(size),
        ));
    }
    *left = left.saturating_sub(size);
    result
}
