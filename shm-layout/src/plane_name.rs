//! Plane names: the `Name` option of a plane (unique within a domain, so that any process
//! of the same user can `Open` the plane by it), and what `ListPlanes` reports about each
//! named plane. A name is also a file name in the daemon's state directory
//! (`<state-dir>/<domain>/<name>.physnap`), hence its short length and narrow charset.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::CommandError;
use crate::ids::PlaneId;
use crate::plane_kind::PlaneKind;
use crate::settings::row::{PropKind, PropValue, Range};

/// Longest plane name, in bytes.
pub const MAX_NAME_LEN: usize = 32;

/// A plane's name: 1 to [`MAX_NAME_LEN`] ASCII letters, digits, `_`, `-` or `.`, starting
/// with a letter or a digit; or none ([`PlaneName::NONE`], the default: the plane has no
/// name and behaves as an unnamed plane always did). Fixed-size so plane settings stay
/// `Copy`.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct PlaneName {
    len: u8,
    bytes: [u8; MAX_NAME_LEN],
    /// Decoded from bytes that are no plane name (a forged request): `bytes` hold its first
    /// characters, and every check refuses it naming the field (see `Deserialize`).
    forged: bool,
}

impl PlaneName {
    /// No name.
    pub const NONE: PlaneName = PlaneName {
        len: 0,
        bytes: [0; MAX_NAME_LEN],
        forged: false,
    };

    /// What the wire held when it was no plane name: its first characters, kept so the
    /// check's error can show them.
    fn forged(text: &str) -> PlaneName {
        let mut end = text.len().min(MAX_NAME_LEN);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let mut bytes = [0; MAX_NAME_LEN];
        bytes[..end].copy_from_slice(&text.as_bytes()[..end]);
        PlaneName {
            len: end as u8,
            bytes,
            forged: true,
        }
    }

    /// `name` checked: an error naming the field `Name` and the value when it is empty,
    /// too long, or holds a character outside the set.
    pub fn new(name: &str) -> Result<PlaneName, CommandError> {
        check_text(name)?;
        let mut bytes = [0; MAX_NAME_LEN];
        bytes[..name.len()].copy_from_slice(name.as_bytes());
        Ok(PlaneName {
            len: name.len() as u8,
            bytes,
            forged: false,
        })
    }

    /// The name (empty for [`PlaneName::NONE`]).
    pub fn as_str(&self) -> &str {
        let len = (self.len as usize).min(MAX_NAME_LEN);
        std::str::from_utf8(&self.bytes[..len]).unwrap_or("")
    }

    /// Whether the plane has no name.
    pub fn is_none(&self) -> bool {
        self.len == 0
    }
}

impl Default for PlaneName {
    fn default() -> Self {
        PlaneName::NONE
    }
}

impl std::fmt::Debug for PlaneName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}", self.as_str())
    }
}

impl std::fmt::Display for PlaneName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Whether `name` is a valid plane name; the error names the field and the value.
pub fn check_text(name: &str) -> Result<(), CommandError> {
    let bad = |why: &str| {
        let shown: String = name.chars().take(64).collect();
        let more = if name.chars().count() > 64 { "..." } else { "" };
        Err(CommandError::invalid_field(
            "Name",
            format!(
                "Name must be 1 to {MAX_NAME_LEN} characters of A-Z a-z 0-9 _ - . starting \
                 with a letter or digit ({why}), got {shown:?}{more}"
            ),
        ))
    };
    if name.is_empty() {
        return bad("it is empty");
    }
    if name.len() > MAX_NAME_LEN {
        return bad(&format!("it is {} bytes long", name.len()));
    }
    if let Some(c) = name
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.')))
    {
        return bad(&format!("{c:?} is not allowed"));
    }
    if !name.as_bytes()[0].is_ascii_alphanumeric() {
        return bad("it must start with a letter or digit");
    }
    Ok(())
}

/// On the wire a name is a string. Decoding takes any string (a bad one is kept marked, cut
/// to its first characters), so a forged name is refused by the check with an error naming
/// the field and the value, for that command alone, instead of the whole request failing to
/// decode.
impl Serialize for PlaneName {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

impl<'de> Deserialize<'de> for PlaneName {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = <&str>::deserialize(d)?;
        if text.is_empty() {
            return Ok(PlaneName::NONE);
        }
        Ok(PlaneName::new(text).unwrap_or_else(|_| PlaneName::forged(text)))
    }
}

impl PropValue for PlaneName {
    const KIND: PropKind = PropKind::Other;
    /// Names are checked when made ([`PlaneName::new`], decoding); checked again here so a
    /// value built any other way cannot pass.
    fn check(self, _name: &str, _range: &Range) -> Result<PlaneName, CommandError> {
        if self.forged {
            return Err(CommandError::invalid_field(
                "Name",
                format!(
                    "Name must be 1 to {MAX_NAME_LEN} characters of A-Z a-z 0-9 _ - . \
                     starting with a letter or digit, got {:?}... (not a plane name)",
                    self.as_str()
                ),
            ));
        }
        if self.is_none() {
            return Ok(self);
        }
        PlaneName::new(self.as_str())
    }
    fn text(&self) -> String {
        format!("{:?}", self.as_str())
    }
}

/// One named plane as `ListPlanes` reports it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NamedPlane {
    /// Its name.
    pub name: String,
    /// Its id on this daemon.
    pub id: PlaneId,
    /// Its kind.
    pub kind: PlaneKind,
    /// Written to the daemon's state directory and restored by the next daemon.
    pub persistent: bool,
    /// The tick it has reached.
    pub tick: u64,
    /// No client owns it now (a persistent plane whose owner left, or one restored from a
    /// file): the next client that opens it becomes its owner.
    pub orphaned: bool,
}

/// What `Open` answers: the plane, whether the opener owns it now, and, for a plane that
/// came back from a file and is opened for the first time since, the ticks it lost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OpenedPlane {
    /// Its id on this daemon.
    pub id: PlaneId,
    /// Its kind.
    pub kind: PlaneKind,
    /// The opener owns it (it was orphaned, or the opener created it).
    pub owner: bool,
    /// `Some(lost)` once, for the first `Open` after the plane was restored from its file:
    /// the last tick the old daemon recorded for it minus the snapshot's tick.
    pub recovered: Option<u64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_checked_and_round_trip() {
        for good in ["arena-1", "a", "A.b_c-9", &"x".repeat(MAX_NAME_LEN)] {
            let n = PlaneName::new(good).unwrap();
            assert_eq!(n.as_str(), good);
            let bytes = postcard::to_allocvec(&n).unwrap();
            assert_eq!(postcard::from_bytes::<PlaneName>(&bytes).unwrap(), n);
        }
        for bad in [
            "",
            ".hidden",
            "-x",
            "a/b",
            "../x",
            "a b",
            "é",
            &"x".repeat(33),
        ] {
            let e = PlaneName::new(bad).unwrap_err();
            assert_eq!(e.field.as_deref(), Some("Name"), "{bad:?}");
            assert!(e.message.contains("Name must be"), "{}", e.message);
            // A forged wire value decodes, and its check refuses it naming the field.
            let bytes = postcard::to_allocvec(&bad).unwrap();
            if !bad.is_empty() {
                let forged = postcard::from_bytes::<PlaneName>(&bytes).unwrap();
                let e = forged.check("Name", &Range::Any).unwrap_err();
                assert_eq!(e.field.as_deref(), Some("Name"), "{bad:?}");
                assert!(e.message.contains("not a plane name"), "{}", e.message);
            }
        }
        assert!(PlaneName::NONE.is_none());
    }
}
