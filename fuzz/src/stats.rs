//! What a fuzz run counts: frames, commands, replies by kind, quota hits, per-op coverage and
//! the failures (crashes, unanswered requests, replies of the wrong shape).

use std::collections::BTreeMap;

use shm_layout::{
    Command, CommandResult, ControllerOp, ErrorKind, GuiControllerOp, GuiObjectOp, GuiOp, GuiShape,
    JointOp, MapOp, ObjectOp, ObjectProp, PlaneOp, PlaneProp, QueryOp, RecordOp, Reply, Response,
    Shape, TransferOp,
};

/// How many failures a run keeps in full (the counters count all of them).
pub const MAX_FINDINGS: usize = 20;

/// Counters of one fuzz run.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct FuzzStats {
    /// The seed the run was generated from.
    pub seed: u64,
    /// Wall time of the run.
    pub seconds: f64,
    /// Clients that sent frames.
    pub clients: usize,
    /// Batches (one or more frames each).
    pub batches: u64,
    /// Frames sent, all kinds together.
    pub frames: u64,
    /// Frames of well-formed requests built from generated commands.
    pub structured_frames: u64,
    /// Frames of random or mutated bytes.
    pub raw_frames: u64,
    /// Frames sent by quota rounds (requests built to exceed one quota).
    pub quota_frames: u64,
    /// Empty requests sent to check that the daemon still answers.
    pub probe_frames: u64,
    /// Commands in the frames the daemon could decode (each gets a result).
    pub commands: u64,
    /// Successful command results by reply variant.
    pub ok: BTreeMap<String, u64>,
    /// Failed command results by error kind.
    pub errors: BTreeMap<String, u64>,
    /// Whole requests refused, by error kind.
    pub rejected: BTreeMap<String, u64>,
    /// Replies in the version-neutral form (to frames of another layout version).
    pub version_replies: u64,
    /// Quota errors (command or request) by the daemon flag they name.
    pub quota_hits: BTreeMap<String, u64>,
    /// Quota rounds run and how many of them met the quota, by quota.
    pub quota_rounds: BTreeMap<String, QuotaRound>,
    /// Fuzzed commands (structured and raw frames) sent and how many succeeded, by op
    /// (`Plane.Step`, `Object.Set.Velocity`).
    pub ops: BTreeMap<String, OpCount>,
    /// Planes that failed inside the daemon (a caught panic) and were removed, as reported
    /// in replies.
    pub plane_panics: u64,
    /// The daemon exited, or a reply could not be decoded.
    pub crashes: u64,
    /// A request got no reply (timeout, stall, transport failure) while the daemon lived.
    pub unanswered: u64,
    /// A reply of the wrong shape: a result count that differs from the command count, or
    /// results for a frame that cannot be decoded.
    pub protocol_errors: u64,
    /// The first failures in full (crashes, unanswered, protocol errors, plane panics).
    #[serde(skip)]
    pub findings: Vec<Finding>,
}

/// Commands of one op sent, and how many succeeded.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct OpCount {
    /// Commands sent.
    pub sent: u64,
    /// Of those, succeeded.
    pub ok: u64,
}

/// Rounds of one quota.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct QuotaRound {
    /// Rounds run.
    pub runs: u64,
    /// Rounds in which the daemon refused with this quota's error.
    pub hit: u64,
}

/// One failure, with the frame that caused it.
#[derive(Debug, Clone)]
pub struct Finding {
    /// What went wrong: `crash`, `unanswered`, `protocol` or `plane panic`.
    pub kind: &'static str,
    /// The batch it happened in (0-based).
    pub batch: u64,
    /// The client that sent the frame.
    pub client: usize,
    /// A description (error message, reply summary).
    pub detail: String,
    /// The request frame, byte for byte (empty when it was larger than 1 MiB).
    pub frame: Vec<u8>,
}

impl FuzzStats {
    /// Whether the run met its goals: no crash, every request answered, every reply of the
    /// right shape.
    pub fn clean(&self) -> bool {
        self.crashes == 0 && self.unanswered == 0 && self.protocol_errors == 0
    }

    /// Successful command results.
    pub fn ok_total(&self) -> u64 {
        self.ok.values().sum()
    }

    /// Failed command results.
    pub fn error_total(&self) -> u64 {
        self.errors.values().sum()
    }

    /// Of the fuzzed commands (structured and raw frames; not the quota rounds, whose
    /// thousands of adds would swamp the figure), the fraction that succeeded: how often
    /// the fuzzer gets past validation into the engine.
    pub fn ok_fraction(&self) -> f64 {
        let (sent, ok) = self
            .ops
            .values()
            .fold((0, 0), |(s, o), c| (s + c.sent, o + c.ok));
        if sent == 0 {
            0.0
        } else {
            ok as f64 / sent as f64
        }
    }

    /// The ops of [`all_op_names`] never sent.
    pub fn ops_not_sent(&self) -> Vec<String> {
        all_op_names()
            .into_iter()
            .filter(|op| self.ops.get(op).is_none_or(|c| c.sent == 0))
            .collect()
    }

    pub(crate) fn finding(
        &mut self,
        kind: &'static str,
        batch: u64,
        client: usize,
        detail: String,
        frame: &[u8],
    ) {
        match kind {
            "crash" => self.crashes += 1,
            "unanswered" => self.unanswered += 1,
            "protocol" => self.protocol_errors += 1,
            _ => {}
        }
        if self.findings.len() < MAX_FINDINGS {
            let frame = if frame.len() <= 1 << 20 {
                frame.to_vec()
            } else {
                Vec::new()
            };
            self.findings.push(Finding {
                kind,
                batch,
                client,
                detail,
                frame,
            });
        }
    }

    /// Counts a decoded response; `commands` are the request's commands when it could be
    /// decoded here and the frame was fuzzed input (they are then counted per op).
    pub(crate) fn count_response(&mut self, response: &Response, commands: Option<&[Command]>) {
        match response {
            Response::Rejected(e) => {
                *self.rejected.entry(kind_name(e.kind)).or_default() += 1;
                self.count_quota(e);
            }
            Response::Results(results) => {
                self.commands += results.len() as u64;
                for (i, r) in results.iter().enumerate() {
                    let op = commands.and_then(|c| c.get(i)).map(op_name);
                    self.count_result(r, op);
                }
            }
        }
    }

    fn count_result(&mut self, result: &CommandResult, op: Option<String>) {
        if let Some(op) = op {
            let count = self.ops.entry(op).or_default();
            count.sent += 1;
            count.ok += result.is_ok() as u64;
        }
        match result {
            Ok(reply) => *self.ok.entry(reply_name(reply).to_string()).or_default() += 1,
            Err(e) => {
                *self.errors.entry(kind_name(e.kind)).or_default() += 1;
                self.count_quota(e);
                if e.kind == ErrorKind::Internal && e.message.contains("failed and was removed") {
                    self.plane_panics += 1;
                }
            }
        }
    }

    fn count_quota(&mut self, e: &shm_layout::CommandError) {
        if e.kind != ErrorKind::Quota {
            return;
        }
        let flag = e
            .message
            .split_once("daemon flag ")
            .and_then(|(_, rest)| rest.split([')', ' ', ',']).next())
            .unwrap_or("(daemon-wide limit)");
        *self.quota_hits.entry(flag.to_string()).or_default() += 1;
    }
}

/// Every op name [`op_name`] gives: each `Command`, `PlaneOp`, `ObjectOp`, `PlaneProp`,
/// `ObjectProp` and shape variant.
pub fn all_op_names() -> Vec<String> {
    let mut names: Vec<String> = [
        "Hello",
        "Goodbye",
        "ListPlanes",
        "CreatePlane",
        "Plane.Info",
        "Plane.Step",
        "Plane.Destroy",
        "Plane.AddObject.Cube",
        "Plane.AddObject.Sphere",
        "Plane.AddObject.Mesh",
        "Plane.AddObject.Capsule",
        "Plane.AddObject.Cylinder",
        "Plane.AddObject.Wedge",
        "Object.ApplyImpulse",
        "Object.Info",
        "Object.RecalculateCenterOfMass",
        "Object.Wake",
        "Object.Destroy",
    ]
    .map(String::from)
    .to_vec();
    // One op per row of the plane and object settings tables (GUI plane options are
    // counted under their own names when a GUI plane gets them).
    names.extend(
        PlaneProp::DEFAULTS
            .iter()
            .filter(|p| !matches!(p, PlaneProp::Gui(_)))
            .map(|p| format!("Plane.Set.{}", p.name())),
    );
    names.extend(
        ObjectProp::ROWS
            .iter()
            .map(|r| format!("Object.Set.{}", r.name)),
    );
    names.push("Plane.CollisionGroups".into());
    for q in [
        "Raycast",
        "Spherecast",
        "Blockcast",
        "Shapecast",
        "BoundsInRadius",
        "BoundsInBox",
        "InPart",
        "ProbeGround",
        "ClosestPoint",
        "Clearance",
        "ProbeWall",
    ] {
        names.push(format!("Plane.Query.{q}"));
    }
    names.push("Plane.Explode".into());
    names.push("Plane.Snapshot".into());
    names.push("Plane.Restore".into());
    for c in [
        "Create",
        "Set",
        "Info",
        "SetPath",
        "AppendWaypoint",
        "StopWalking",
        "Jump",
        "Teleport",
        "Destroy",
    ] {
        names.push(format!("Plane.Controller.{c}"));
    }
    names.push("Gui.Info".into());
    names.push("Gui.Raycast".into());
    for shape in GuiShape::ALL {
        names.push(format!("Gui.Add.{}", shape.name()));
    }
    for o in ["ApplyImpulse", "Wake", "Info", "Destroy"] {
        names.push(format!("Gui.Object.{o}"));
    }
    for c in [
        "Create",
        "Set",
        "Move",
        "Jump",
        "SetWaypoints",
        "ClearWaypoints",
        "Info",
        "Destroy",
    ] {
        names.push(format!("Gui.Controller.{c}"));
    }
    names
}

/// The name of an error kind (`InvalidValue`).
pub fn kind_name(kind: ErrorKind) -> String {
    format!("{kind:?}")
}

/// The name of a reply variant (`Stepped`).
pub fn reply_name(reply: &Reply) -> &'static str {
    match reply {
        Reply::Done => "Done",
        Reply::Welcome { .. } => "Welcome",
        Reply::Plane(_) => "Plane",
        Reply::Object { .. } => "Object",
        Reply::Applied { .. } => "Applied",
        Reply::Stepped { .. } => "Stepped",
        Reply::ObjectInfo(_) => "ObjectInfo",
        Reply::CenterOfMass(_) => "CenterOfMass",
        Reply::Hits(_) => "Hits",
        Reply::Objects(_) => "Objects",
        Reply::Controller(_) => "Controller",
        Reply::Flag(_) => "Flag",
        Reply::Gui(_) => "Gui",
        Reply::Joint { .. } => "Joint",
        Reply::JointInfo(_) => "JointInfo",
        Reply::Map(_) => "Map",
        Reply::PlaneIds(_) => "PlaneIds",
        Reply::Velocity { .. } => "Velocity",
        Reply::Probe(_) => "Probe",
        Reply::Contacts(_) => "Contacts",
        Reply::ObjectPage { .. } => "ObjectPage",
        Reply::Snapshot(_) => "Snapshot",
        Reply::NamedPlanes(_) => "NamedPlanes",
        Reply::Opened(_) => "Opened",
        Reply::Saved { .. } => "Saved",
        Reply::Transfer(_) => "Transfer",
        Reply::Moved { .. } => "Moved",
        Reply::Recording(_) => "Recording",
        Reply::Joints(_) => "Joints",
    }
}

/// The op a command performs, by variant path (`Plane.AddObject.Mesh`, `Object.Set.Size`).
pub fn op_name(command: &Command) -> String {
    match command {
        Command::Hello { .. } => "Hello".into(),
        Command::Goodbye => "Goodbye".into(),
        Command::ListPlanes => "ListPlanes".into(),
        Command::ListNamedPlanes => "ListNamedPlanes".into(),
        Command::OpenPlane { .. } => "OpenPlane".into(),
        Command::CreatePlane { .. } => "CreatePlane".into(),
        Command::Plane { op, .. } => match op {
            PlaneOp::Info => "Plane.Info".into(),
            PlaneOp::Set(p) => format!("Plane.Set.{}", p.name()),
            PlaneOp::Step { .. } => "Plane.Step".into(),
            PlaneOp::Destroy => "Plane.Destroy".into(),
            PlaneOp::AddObject { shape, .. } => format!(
                "Plane.AddObject.{}",
                match shape {
                    Shape::Cube { .. } => "Cube",
                    Shape::Sphere { .. } => "Sphere",
                    Shape::Mesh { .. } => "Mesh",
                    Shape::Capsule { .. } => "Capsule",
                    Shape::Cylinder { .. } => "Cylinder",
                    Shape::Wedge { .. } => "Wedge",
                }
            ),
            PlaneOp::Object { op, .. } => match op {
                ObjectOp::Set(p) => format!("Object.Set.{}", p.name()),
                ObjectOp::ApplyImpulse(_) => "Object.ApplyImpulse".into(),
                ObjectOp::Info => "Object.Info".into(),
                ObjectOp::RecalculateCenterOfMass => "Object.RecalculateCenterOfMass".into(),
                ObjectOp::Wake => "Object.Wake".into(),
                ObjectOp::Destroy => "Object.Destroy".into(),
                ObjectOp::Contacts => "Object.Contacts".into(),
            },
            PlaneOp::Query(q) => format!("Plane.Query.{}", query_name(q)),
            PlaneOp::CollisionGroups(_) => "Plane.CollisionGroups".into(),
            PlaneOp::Controller(c) => format!("Plane.Controller.{}", controller_op_name(c)),
            PlaneOp::Gui(op) => gui_op_name(op),
            PlaneOp::Joint(j) => match j {
                JointOp::Create { kind, .. } => format!("Plane.Joint.Create.{}", kind.name()),
                JointOp::Set { prop, .. } => format!("Plane.Joint.Set.{}", prop.name()),
                JointOp::Info { .. } => "Plane.Joint.Info".into(),
                JointOp::Destroy { .. } => "Plane.Joint.Destroy".into(),
                JointOp::List { .. } => "Plane.Joint.List".into(),
            },
            PlaneOp::Map(m) => match m {
                MapOp::Upload { .. } => "Plane.Map.Upload".into(),
                MapOp::Build { .. } => "Plane.Map.Build".into(),
                MapOp::Discard => "Plane.Map.Discard".into(),
            },
            PlaneOp::Explode(_) => "Plane.Explode".into(),
            PlaneOp::Snapshot => "Plane.Snapshot".into(),
            PlaneOp::Restore { .. } => "Plane.Restore".into(),
            PlaneOp::Rewind(_) => "Plane.Rewind".into(),
            PlaneOp::Save => "Plane.Save".into(),
            PlaneOp::RestoreUploaded { .. } => "Plane.RestoreUploaded".into(),
            PlaneOp::MoveTo { .. } => "Plane.MoveTo".into(),
            PlaneOp::ClaimMoved { .. } => "Plane.ClaimMoved".into(),
            PlaneOp::Pin => "Plane.Pin".into(),
            PlaneOp::Record(RecordOp::Start { .. }) => "Plane.Record.Start".into(),
            PlaneOp::Record(RecordOp::Stop) => "Plane.Record.Stop".into(),
        },
        Command::Transfer(op) => match op {
            TransferOp::Open { .. } => "Transfer.Open".into(),
            TransferOp::Put { .. } => "Transfer.Put".into(),
            TransferOp::Get { .. } => "Transfer.Get".into(),
            TransferOp::Close { .. } => "Transfer.Close".into(),
        },
    }
}

/// The name of a controller op (`Create`).
pub fn controller_op_name(op: &ControllerOp) -> &'static str {
    match op {
        ControllerOp::Create { .. } => "Create",
        ControllerOp::Set { .. } => "Set",
        ControllerOp::Info { .. } => "Info",
        ControllerOp::SetPath { .. } => "SetPath",
        ControllerOp::AppendWaypoint { .. } => "AppendWaypoint",
        ControllerOp::StopWalking { .. } => "StopWalking",
        ControllerOp::Jump { .. } => "Jump",
        ControllerOp::Teleport { .. } => "Teleport",
        ControllerOp::Destroy { .. } => "Destroy",
    }
}

/// The name of a GUI-plane op (`Gui.Object.Set.Position`, `Gui.Controller.Move`).
pub fn gui_op_name(op: &GuiOp) -> String {
    match op {
        GuiOp::Info => "Gui.Info".into(),
        GuiOp::Add { shape, .. } => format!("Gui.Add.{}", shape.name()),
        GuiOp::Object { op, .. } => match op {
            GuiObjectOp::Set(p) => format!("Gui.Object.Set.{}", p.name()),
            GuiObjectOp::ApplyImpulse(_) => "Gui.Object.ApplyImpulse".into(),
            GuiObjectOp::Wake => "Gui.Object.Wake".into(),
            GuiObjectOp::Info => "Gui.Object.Info".into(),
            GuiObjectOp::Destroy => "Gui.Object.Destroy".into(),
        },
        GuiOp::Controller { op, .. } => format!(
            "Gui.Controller.{}",
            match op {
                GuiControllerOp::Create { .. } => "Create",
                GuiControllerOp::Set(_) => "Set",
                GuiControllerOp::Move(_) => "Move",
                GuiControllerOp::Jump => "Jump",
                GuiControllerOp::SetWaypoints(_) => "SetWaypoints",
                GuiControllerOp::ClearWaypoints => "ClearWaypoints",
                GuiControllerOp::Info => "Info",
                GuiControllerOp::Destroy => "Destroy",
            }
        ),
        GuiOp::Raycast { .. } => "Gui.Raycast".into(),
    }
}

/// The name of a query (`Raycast`).
pub fn query_name(query: &QueryOp) -> &'static str {
    match query {
        QueryOp::Raycast { .. } => "Raycast",
        QueryOp::Spherecast { .. } => "Spherecast",
        QueryOp::Blockcast { .. } => "Blockcast",
        QueryOp::Shapecast { .. } => "Shapecast",
        QueryOp::BoundsInRadius { .. } => "BoundsInRadius",
        QueryOp::BoundsInBox { .. } => "BoundsInBox",
        QueryOp::InPart { .. } => "InPart",
        QueryOp::ProbeGround { .. } => "ProbeGround",
        QueryOp::ClosestPoint { .. } => "ClosestPoint",
        QueryOp::Clearance { .. } => "Clearance",
        QueryOp::ProbeWall { .. } => "ProbeWall",
        QueryOp::Page { .. } => "Page",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_layout::CommandError;

    #[test]
    fn quota_errors_are_counted_by_flag() {
        let mut s = FuzzStats::default();
        let e = CommandError::new(
            ErrorKind::Quota,
            "quota exceeded: objects per client is limited to 10 (daemon flag \
             --max-objects-per-client), this would make 11",
        );
        s.count_response(&Response::Rejected(e.clone()), None);
        s.count_response(&Response::Results(vec![Err(e), Ok(Reply::Done)]), None);
        assert_eq!(s.quota_hits["--max-objects-per-client"], 2);
        assert_eq!(s.rejected["Quota"], 1);
        assert_eq!(s.errors["Quota"], 1);
        assert_eq!(s.ok["Done"], 1);
        assert_eq!(s.commands, 2);
        assert_eq!(s.ok_fraction(), 0.0);
        let cmds = [Command::Goodbye, Command::Goodbye];
        s.count_response(
            &Response::Results(vec![Ok(Reply::Done), Err(CommandError::invalid("x"))]),
            Some(&cmds),
        );
        assert!((s.ok_fraction() - 0.5).abs() < 1e-9);
        assert_eq!(s.ops_not_sent().len(), all_op_names().len() - 1);
    }
}
