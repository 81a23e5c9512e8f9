//! Fixed-size records written by the daemon straight into loaned shared-memory samples.

use iceoryx2::prelude::ZeroCopySend;

use crate::contact_points::{ContactPoint, MAX_CONTACT_POINTS};
use crate::geometry::Pose;
pub use crate::ids::Handle;

/// Body flag: the slot holds a live body.
pub const FLAG_ALIVE: u32 = 1 << 0;
/// Body flag: rapier put the body to sleep.
pub const FLAG_SLEEPING: u32 = 1 << 1;
/// Body flag: the body is anchored (fixed).
pub const FLAG_ANCHORED: u32 = 1 << 2;
/// Body flag: a character controller that stood on the ground after the tick.
pub const FLAG_ON_GROUND: u32 = 1 << 3;
/// Body flag: the body is a character controller's capsule.
pub const FLAG_CONTROLLER: u32 = 1 << 4;

/// The state of one slot after a tick. 64 bytes: one cache line per body.
#[derive(
    Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, serde::Serialize, serde::Deserialize,
)]
#[type_name("physics::BodyState")]
#[repr(C)]
pub struct BodyState {
    /// World-space position of the body's origin.
    pub position: [f32; 3],
    /// `FLAG_*` bits.
    pub flags: u32,
    /// Unit quaternion `[x, y, z, w]`.
    pub rotation: [f32; 4],
    /// Linear velocity (units/s).
    pub linear_velocity: [f32; 3],
    /// Generation of the body in this slot (matches [`Handle::generation`]).
    pub generation: u32,
    /// Angular velocity (rad/s).
    pub angular_velocity: [f32; 3],
    /// Padding to 64 bytes; always 0.
    pub _reserved: u32,
}

impl BodyState {
    /// Its position and rotation.
    pub fn pose(&self) -> Pose {
        Pose {
            position: self.position,
            rotation: self.rotation,
        }
    }

    /// Whether the slot holds a live body ([`FLAG_ALIVE`]).
    pub fn is_alive(&self) -> bool {
        self.flags & FLAG_ALIVE != 0
    }
    /// Whether the body is asleep ([`FLAG_SLEEPING`]).
    pub fn is_sleeping(&self) -> bool {
        self.flags & FLAG_SLEEPING != 0
    }
    /// Whether the body is anchored ([`FLAG_ANCHORED`]).
    pub fn is_anchored(&self) -> bool {
        self.flags & FLAG_ANCHORED != 0
    }
    /// Whether pose and velocities are all finite numbers.
    pub fn is_finite(&self) -> bool {
        self.position
            .iter()
            .chain(&self.rotation)
            .chain(&self.linear_velocity)
            .chain(&self.angular_velocity)
            .all(|x| x.is_finite())
    }
    /// True when this slot currently holds the body `handle` refers to.
    pub fn matches(&self, handle: Handle) -> bool {
        self.is_alive() && self.generation == handle.generation
    }
}

/// User header of every body sample: which tick this is and what it cost.
#[derive(
    Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, serde::Serialize, serde::Deserialize,
)]
#[type_name("physics::TickHeader")]
#[repr(C)]
pub struct TickHeader {
    /// `LAYOUT_VERSION` of the daemon that wrote the sample.
    pub layout_version: u32,
    /// The plane the sample belongs to.
    pub plane_id: u32,
    /// Number of steps taken so far (0 before the first step).
    pub tick: u64,
    /// Simulated seconds so far.
    pub sim_time: f64,
    /// CLOCK_MONOTONIC nanoseconds when the step ended and publishing began (delivery latency
    /// is measured from here: it includes the copy into shared memory).
    pub tick_end_ns: u64,
    /// Wall time of the last step, in microseconds.
    pub step_time_us: f32,
    /// The dt of the last step, in seconds.
    pub dt: f32,
    /// Number of slots in the sample (live or not).
    pub slot_count: u32,
    /// Number of live bodies.
    pub body_count: u32,
    /// Deepest contact penetration found by the step's collision detection (units, >= 0).
    pub max_penetration: f32,
    /// Largest joint / constraint error after the step (units, 0 without joints).
    pub max_joint_error: f32,
    /// Number of contact pairs with at least one contact point.
    pub contact_pairs: u32,
    /// Events the plane has published up to and including this tick, modulo 2³² (the next
    /// event's [`EventRecord::seq`], wrapped): a new event reader learns from the newest
    /// tick where its stream starts, so it can count losses from its very first read.
    pub event_count: u32,
    /// Hash of every slot's state as the step left it ([`StateHasher`] over the published
    /// [`BodyState`]s in slot order): two runs agree on a tick exactly when every body's
    /// pose, velocities, flags and generation agree to the bit. A game replaying a command
    /// log compares it tick by tick.
    pub state_hash: u64,
}

/// The hash of [`TickHeader::state_hash`]: 64-bit FNV-1a over the 32-bit words of each
/// [`BodyState`] (all 16 of them, in field order), slot after slot. Word-wise rather than
/// byte-wise to stay cheap (16 multiplies per body); any process can recompute it from a
/// sample's bodies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StateHasher(u64);

impl StateHasher {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;

    /// An empty hash.
    pub fn new() -> StateHasher {
        StateHasher(Self::OFFSET)
    }

    fn word(&mut self, w: u32) {
        self.0 = (self.0 ^ w as u64).wrapping_mul(Self::PRIME);
    }

    /// Adds the next slot's state.
    pub fn add(&mut self, s: &BodyState) {
        let f = |x: &f32| x.to_bits();
        for w in s.position.iter().map(f) {
            self.word(w);
        }
        self.word(s.flags);
        for w in s.rotation.iter().map(f) {
            self.word(w);
        }
        for w in s.linear_velocity.iter().map(f) {
            self.word(w);
        }
        self.word(s.generation);
        for w in s.angular_velocity.iter().map(f) {
            self.word(w);
        }
        self.word(s._reserved);
    }

    /// The hash of the states added so far.
    pub fn finish(&self) -> u64 {
        self.0
    }

    /// The hash of `states` in order (what a sample's bodies hash to).
    pub fn of(states: &[BodyState]) -> u64 {
        let mut h = StateHasher::new();
        for s in states {
            h.add(s);
        }
        h.finish()
    }

    /// The hash of `count` slots whose states `state(i)` gives, in slot order (a plane's
    /// states without copying them into a slice first).
    pub fn of_slots(count: usize, mut state: impl FnMut(usize) -> BodyState) -> u64 {
        let mut h = StateHasher::new();
        for i in 0..count {
            h.add(&state(i));
        }
        h.finish()
    }

    /// A hash that goes on from `state`, the [`StateHasher::finish`] of the slots before:
    /// adding the remaining slots gives the hash of them all. A writer that keeps each
    /// slot's running hash can then rehash from the first slot that changed only.
    pub fn resume(state: u64) -> StateHasher {
        StateHasher(state)
    }
}

impl Default for StateHasher {
    fn default() -> Self {
        StateHasher::new()
    }
}

/// Event kind: two objects started touching.
pub const EVENT_CONTACT_STARTED: u32 = 1;
/// Event kind: two objects stopped touching.
pub const EVENT_CONTACT_STOPPED: u32 = 2;
/// Controller event: a jump launched (`a` = the controller).
pub const EVENT_CONTROLLER_JUMPED: u32 = 16;
/// Controller event: it landed (OnGround became true).
pub const EVENT_CONTROLLER_LANDED: u32 = 17;
/// Controller event: it moved this tick; `normal` carries its velocity (only while asked,
/// `ReportMoved`).
pub const EVENT_CONTROLLER_MOVED: u32 = 18;
/// Controller event: waypoint `b_slot` (1-based) of its path was reached.
pub const EVENT_WAYPOINT_REACHED: u32 = 19;
/// Controller event: the last waypoint was reached.
pub const EVENT_PATH_FINISHED: u32 = 20;

/// Event kind: a GUI controller reached a waypoint. `a` is the controller's body,
/// `b_slot` the 1-based index of the waypoint, `position` the waypoint `[x, y, 0]`.
pub const EVENT_GUI_WAYPOINT_REACHED: u32 = 0x20;
/// Event kind: a GUI controller reached the last waypoint of its path (`a`: its body).
pub const EVENT_GUI_PATH_FINISHED: u32 = 0x21;
/// Event kind: a GUI controller moved in a tick; `position` is `[dx, dy, 0]` (px).
pub const EVENT_GUI_MOVED: u32 = 0x22;
/// Event kind: a GUI controller's OnGround flipped; `b_slot` is 1 (now on the ground) or 0.
pub const EVENT_GUI_GROUND_CHANGED: u32 = 0x23;
/// Event kind: a joint broke (its force exceeded BreakForce). `a` is the joint's handle,
/// `b` its object A, `position` the world anchor on A and `impulse` the force that broke
/// it.
pub const EVENT_JOINT_BROKE: u32 = 3;

/// One per-tick event (published in the plane's event service, one sample per tick that
/// has events). 200 bytes.
///
/// For contact events `a` and `b` are the two objects, `normal` points from `a` toward `b`,
/// `position` is the world-space contact point and `impulse` the total normal impulse the
/// solver applied in the tick the contact started (all zero for `EVENT_CONTACT_STOPPED`);
/// `points` holds the pair's contact manifold then (its first `point_count` entries).
#[derive(
    Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, serde::Serialize, serde::Deserialize,
)]
#[type_name("physics::EventRecord")]
#[repr(C)]
pub struct EventRecord {
    /// `EVENT_*` kind.
    pub kind: u32,
    /// Slot of the first object.
    pub a_slot: u32,
    /// Generation of the first object.
    pub a_generation: u32,
    /// Slot of the second object.
    pub b_slot: u32,
    /// Generation of the second object.
    pub b_generation: u32,
    /// Normal impulse magnitude (mass × velocity units).
    pub impulse: f32,
    /// World-space contact point.
    pub position: [f32; 3],
    /// Unit contact normal, from `a` toward `b`.
    pub normal: [f32; 3],
    /// The tick in which the event happened.
    pub tick: u64,
    /// The plane's running event number (0 for its first event): a reader that sees a gap
    /// knows exactly how many events it lost.
    pub seq: u64,
    /// Contact started: the manifold's points (normals from `a` toward `b`); the first
    /// `point_count` are set.
    pub points: [ContactPoint; MAX_CONTACT_POINTS],
    /// How many of `points` are set (0 to 4).
    pub point_count: u32,
    /// Zero; keeps the record a multiple of 8 bytes.
    pub _reserved: u32,
}

impl EventRecord {
    /// Handle of the first object.
    pub fn a(&self) -> Handle {
        Handle {
            slot: self.a_slot,
            generation: self.a_generation,
        }
    }
    /// Handle of the second object.
    pub fn b(&self) -> Handle {
        Handle {
            slot: self.b_slot,
            generation: self.b_generation,
        }
    }
    /// The contact points the record carries (none but for a contact start).
    pub fn contact_points(&self) -> &[ContactPoint] {
        &self.points[..(self.point_count as usize).min(MAX_CONTACT_POINTS)]
    }
}

/// Monotonic clock in nanoseconds, the same clock in every process of the machine.
pub fn monotonic_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime only writes into the provided timespec.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_sizes_are_fixed() {
        assert_eq!(core::mem::size_of::<BodyState>(), 64);
        assert_eq!(core::mem::size_of::<EventRecord>(), 200);
        assert_eq!(core::mem::size_of::<ContactPoint>(), 32);
        assert_eq!(core::mem::size_of::<TickHeader>(), 72);
    }

    #[test]
    fn state_hash_sees_every_bit_and_the_order() {
        let a = BodyState {
            position: [1.0, 2.0, 3.0],
            flags: FLAG_ALIVE,
            ..Default::default()
        };
        let mut b = a;
        b.linear_velocity[2] = f32::from_bits(1); // the smallest subnormal
        assert_ne!(StateHasher::of(&[a]), StateHasher::of(&[b]));
        assert_ne!(StateHasher::of(&[a, b]), StateHasher::of(&[b, a]));
        assert_eq!(StateHasher::of(&[a, b]), StateHasher::of(&[a, b]));
        // -0.0 and 0.0 differ in their bits, and so in the hash.
        let mut z = a;
        z.angular_velocity[1] = -0.0;
        assert_ne!(StateHasher::of(&[a]), StateHasher::of(&[z]));
        assert_eq!(StateHasher::of(&[]), StateHasher::new().finish());
    }

    #[test]
    fn a_resumed_hash_equals_the_whole_chain() {
        let a = BodyState {
            position: [1.0, 2.0, 3.0],
            flags: FLAG_ALIVE,
            ..Default::default()
        };
        let mut b = a;
        b.generation = 7;
        let mut h = StateHasher::resume(StateHasher::of(&[a]));
        h.add(&b);
        assert_eq!(h.finish(), StateHasher::of(&[a, b]));
        assert_ne!(h.finish(), StateHasher::of(&[b]));
    }

    #[test]
    fn handle_matching_checks_generation_and_liveness() {
        let s = BodyState {
            flags: FLAG_ALIVE,
            generation: 3,
            ..Default::default()
        };
        assert!(s.matches(Handle {
            slot: 0,
            generation: 3
        }));
        assert!(!s.matches(Handle {
            slot: 0,
            generation: 2
        }));
        let dead = BodyState {
            flags: 0,
            generation: 3,
            ..Default::default()
        };
        assert!(!dead.matches(Handle {
            slot: 0,
            generation: 3
        }));
    }
}
