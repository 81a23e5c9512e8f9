//! Migration of a plane between the daemons of a cluster (`plane:MoveTo("DAEMON")`,
//! docs/cluster.md "Migration"): what the owner daemon hands to the target (a
//! [`MovingPlane`]: the plane's snapshot and what the snapshot does not hold), and the
//! refusal every later command for the plane gets on the old daemon ([`Moved`]), which tells
//! a client where the plane went so that it switches over and sends the command again.

use serde::{Deserialize, Serialize};

use crate::command::PlaneId;
use crate::error::{CommandError, ErrorKind};
use crate::plane_name::PlaneName;
use crate::plane_op::PlaneKind;

/// The key a daemon answers migrations on: `physics/<cluster>/migrate/<daemon>`.
pub fn migrate_key(cluster: &str, daemon: &str) -> String {
    format!("{}/{cluster}/migrate/{daemon}", crate::cluster::ROOT)
}

/// A plane on its way from one daemon to another: the payload of the migration query.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MovingPlane {
    /// The daemon it leaves.
    pub from: String,
    /// Its id there.
    pub from_id: PlaneId,
    /// Its kind (only [`PlaneKind::Rapier3d`] moves).
    pub kind: PlaneKind,
    /// Its `Name`, kept on the target.
    pub name: Option<PlaneName>,
    /// Whether it is persistent (kept so on a target with a state directory).
    pub persistent: bool,
    /// The key its owner claims it with on the target (the plane belongs to nobody else
    /// there until then).
    pub claim: u128,
    /// Its snapshot ([`crate::snapshot`] framing): same objects, same handles, same tick.
    pub bytes: Vec<u8>,
    /// It was recording: the target records it on (a file of its own, in its recordings
    /// folder), the recording here having ended saying where the plane went.
    pub recording: bool,
}

/// The target's answer to a [`MovingPlane`]: the plane's id there, or why it was refused.
pub type MoveAnswer = Result<PlaneId, String>;

/// Where a plane went: carried by the refusal ([`ErrorKind::Moved`]) of a command that
/// reached the daemon the plane left.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Moved {
    /// The plane's id on the daemon it left.
    pub from_id: PlaneId,
    /// The daemon it lives on now.
    pub daemon: String,
    /// Its id there.
    pub plane: PlaneId,
    /// The cluster.
    pub cluster: String,
    /// An endpoint of the cluster that routes for clients (the old daemon's own).
    pub endpoint: String,
    /// The key the plane's owner claims it with there; 0 in the refusal of anyone else's
    /// command (a plane moved by `--rebalance` tells its owner this way).
    pub key: u128,
}

/// Marks the machine-readable form in [`CommandError::field`].
const TAG: &str = "moved";

impl Moved {
    /// The refusal of a command for the moved plane (not applied: send it to the new
    /// daemon). Its message is for people; its `field` holds the same for the SDK.
    pub fn to_error(&self) -> CommandError {
        CommandError {
            kind: ErrorKind::Moved,
            field: Some(format!(
                "{TAG}\t{}\t{}\t{}\t{}\t{:x}",
                self.daemon, self.plane, self.cluster, self.endpoint, self.key
            )),
            message: format!(
                "plane {} moved to daemon {:?} (plane {} there, cluster {:?}): the command \
                 was not applied here",
                self.from_id, self.daemon, self.plane, self.cluster
            ),
        }
    }

    /// Reads a [`Moved`] refusal of a command for plane `from_id`; `None` for any other
    /// error (or a malformed one).
    pub fn from_error(from_id: PlaneId, e: &CommandError) -> Option<Moved> {
        if e.kind != ErrorKind::Moved {
            return None;
        }
        let mut parts = e.field.as_deref()?.split('\t');
        if parts.next()? != TAG {
            return None;
        }
        let daemon = parts.next()?.to_string();
        let plane = parts.next()?.parse().ok()?;
        let cluster = parts.next()?.to_string();
        let endpoint = parts.next()?.to_string();
        let key = u128::from_str_radix(parts.next().unwrap_or("0"), 16).ok()?;
        crate::cluster::check_name("daemon", &daemon).ok()?;
        crate::cluster::check_name("cluster", &cluster).ok()?;
        Some(Moved {
            from_id,
            daemon,
            plane,
            cluster,
            endpoint,
            key,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_moved_refusal_reads_back() {
        let moved = Moved {
            from_id: 3,
            daemon: "b".into(),
            plane: 7,
            cluster: "demo".into(),
            endpoint: "tcp/127.0.0.1:7447".into(),
            key: 0xabc,
        };
        let e = moved.to_error();
        assert!(e.message.contains("moved to daemon \"b\""), "{}", e.message);
        assert_eq!(Moved::from_error(3, &e), Some(moved));
        let other = CommandError::new(ErrorKind::UnknownPlane, "plane 3 does not exist");
        assert_eq!(Moved::from_error(3, &other), None);
        let forged = CommandError {
            kind: ErrorKind::Moved,
            field: Some("moved\tb/*\t7\tdemo\tx".into()),
            message: String::new(),
        };
        assert_eq!(Moved::from_error(3, &forged), None);
    }
}
