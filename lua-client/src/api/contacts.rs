//! Contact events for scripts: `part.Touched(otherPart, contact)` and
//! `part.TouchEnded(otherPart)` (the other side is a Map when the part touches one), fired from the plane's per-tick event stream in tick order,
//! once per contact start and end; and `joint.Broke(force, position)`, once when a joint
//! breaks. A plane reads its events only while one of its parts has touch handlers or one
//! of its joints has Broke handlers; `plane.EventsLost(n)` (or, with no handler, a line on stderr) says when a
//! script fell so far behind that the daemon's queue dropped events.

use std::cell::Cell;
use std::rc::{Rc, Weak};

use client_sdk::{Contact, Handle, JointBroke};
use mlua::{Lua, MultiValue, Value};

use super::contact_points::body_value;
use super::plane::state::{Broke, PlaneState};
use crate::host::signal::Signal;
use crate::host::Watched;
use crate::values::{new_vector, sdk_error};

/// What `Touched` reports of a contact start: point, normal (toward the part told), impulse,
/// the manifold's points and whether their normals (from the record's first object toward
/// the second) must be turned around.
type TouchContact<'a> = (
    [f32; 3],
    [f32; 3],
    f32,
    &'a [client_sdk::ContactPoint],
    bool,
);

/// `joint.Broke` of joint `joint` of `plane` joining the objects `ends`, created on first
/// access; the plane starts reading its events when the signal gets its first handler.
pub fn joint_broke_signal(
    plane: &Rc<PlaneState>,
    joint: Handle,
    ends: &[Handle],
    name: &str,
) -> Signal {
    let mut map = plane.contacts.broke.borrow_mut();
    map.entry(joint)
        .or_insert_with(|| {
            let signal = Signal::new(format!("{name}.Broke"));
            let weak: Weak<PlaneState> = Rc::downgrade(plane);
            signal.on_listeners(move |n| {
                if n > 0 {
                    if let Some(plane) = weak.upgrade() {
                        plane.listen_for_contacts();
                    }
                }
            });
            Broke {
                signal,
                ends: ends.to_vec(),
                fired: Cell::new(false),
            }
        })
        .signal
        .clone()
}

impl PlaneState {
    /// `plane.EventsLost`: fired with the number of events lost when the script fell behind.
    pub fn events_lost_signal(&self) -> Signal {
        self.contacts
            .lost
            .borrow_mut()
            .get_or_insert_with(|| {
                Signal::new(format!("PhysicsPlane {}.EventsLost", self.plane.id()))
            })
            .clone()
    }

    /// Whether anyone listens to the plane's events: a part's touch handlers, a
    /// controller's signals or a joint's Broke.
    fn touch_handlers(&self) -> bool {
        self.listening(|_| true)
    }

    /// Whether some handler of the plane can still fire: the plane lives and a simulated
    /// part has touch handlers, a controller has handlers, or a joint that has not broken
    /// yet has Broke handlers.
    fn handlers_can_fire(&self) -> bool {
        self.alive() && self.listening(|b| !b.fired.get())
    }

    /// A part's touch handlers (the cached answer), a controller's signals, or the Broke
    /// handlers of a joint `counts`.
    fn listening(&self, counts: impl Fn(&Broke) -> bool) -> bool {
        let parts = self
            .contacts
            .parts_listen
            .get(|| self.any_part(|p| p.touch_listeners() > 0));
        parts
            || self.controller_listeners()
            || self
                .contacts
                .broke
                .borrow()
                .values()
                .any(|b| b.signal.listeners() > 0 && counts(b))
    }

    /// Delivers the events published since the last call to the parts' touch handlers.
    pub(crate) fn deliver_contacts(&self, lua: &Lua) -> mlua::Result<()> {
        if !self.alive() || !self.touch_handlers() {
            self.contacts.reading.set(false);
            return Ok(());
        }
        let events = self
            .plane
            .events()
            .map_err(|e| sdk_error("PhysicsPlane contact events", e))?;
        // Events queued while nobody listened are not news: drop them, lost or not.
        if !self.contacts.reading.replace(true) {
            return Ok(());
        }
        if events.lost > 0 {
            self.report_lost(lua, events.lost)?;
        }
        for record in &events.records {
            if let Some(broke) = JointBroke::from_record(record) {
                self.joint_broke(lua, &broke)?;
                continue;
            }
            match Contact::from_record(record) {
                Some(Contact::Started {
                    a,
                    b,
                    position,
                    normal,
                    impulse,
                    ..
                }) => {
                    let flipped = normal.map(|c| -c);
                    let points = record.contact_points();
                    // Each side gets the other part, and the normal of the other's surface
                    // pointing toward itself.
                    self.touch(lua, a, b, Some((position, flipped, impulse, points, true)))?;
                    self.touch(lua, b, a, Some((position, normal, impulse, points, false)))?;
                }
                Some(Contact::Ended { a, b, .. }) => {
                    self.touch(lua, a, b, None)?;
                    self.touch(lua, b, a, None)?;
                }
                None => self.controller_event(lua, record)?,
            }
        }
        Ok(())
    }

    fn touch(
        &self,
        lua: &Lua,
        this: Handle,
        other: Handle,
        contact: Option<TouchContact<'_>>,
    ) -> mlua::Result<()> {
        let Some(part) = self.part_of(this) else {
            return Ok(());
        };
        if part.touch_listeners() == 0 {
            return Ok(());
        }
        let other = body_value(lua, self, other)?;
        let contact = match contact {
            Some((position, normal, impulse, points, flip)) => {
                let t = lua.create_table()?;
                t.set("Position", new_vector(position))?;
                t.set("Normal", new_vector(normal))?;
                t.set("Impulse", impulse)?;
                t.set(
                    "Points",
                    super::contact_points::points_table(lua, points, flip)?,
                )?;
                Some(Value::Table(t))
            }
            None => None,
        };
        part.fire_touch(lua, other, contact)
    }

    /// Fires the controller signal a record carries (Jumped, Landed, Moved(vx, vy, vz),
    /// WaypointReached(index), PathFinished).
    fn controller_event(&self, lua: &Lua, r: &client_sdk::EventRecord) -> mlua::Result<()> {
        let Some(c) = self.controller_of(r.a()) else {
            return Ok(());
        };
        let num = |x: f32| crate::values::lua_number(x);
        let (name, args): (&str, Vec<Value>) = match r.kind {
            client_sdk::EVENT_CONTROLLER_JUMPED => ("Jumped", vec![]),
            client_sdk::EVENT_CONTROLLER_LANDED => ("Landed", vec![]),
            client_sdk::EVENT_CONTROLLER_MOVED => {
                ("Moved", r.normal.iter().map(|v| num(*v)).collect())
            }
            client_sdk::EVENT_WAYPOINT_REACHED => {
                ("WaypointReached", vec![crate::values::lua_number(r.b_slot)])
            }
            client_sdk::EVENT_PATH_FINISHED => ("PathFinished", vec![]),
            _ => return Ok(()),
        };
        c.fire(lua, name, MultiValue::from_iter(args))
    }

    /// Fires the joint's Broke with the force that broke it and the world anchor on A.
    fn joint_broke(&self, lua: &Lua, broke: &JointBroke) -> mlua::Result<()> {
        let signal = self.contacts.broke.borrow().get(&broke.joint).map(|b| {
            b.fired.set(true);
            b.signal.clone()
        });
        match signal {
            Some(s) if s.listeners() > 0 => s.fire(
                lua,
                MultiValue::from_iter([
                    crate::values::lua_number(broke.force),
                    new_vector(broke.position),
                ]),
            ),
            _ => Ok(()),
        }
    }

    fn report_lost(&self, lua: &Lua, n: u64) -> mlua::Result<()> {
        let signal = self.contacts.lost.borrow().clone();
        match signal {
            Some(s) if s.listeners() > 0 => {
                s.fire(lua, MultiValue::from_iter([crate::values::lua_number(n)]))
            }
            _ => {
                eprintln!(
                    "PhysicsPlane {}: events lost: {n} (the script fell more than {} ticks \
                     with events behind)",
                    self.plane.id(),
                    client_sdk::EVENT_BUFFER_TICKS
                );
                Ok(())
            }
        }
    }
}

/// Each frame, a plane with touch handlers delivers its new contact events.
impl Watched for PlaneState {
    fn listeners(&self) -> usize {
        usize::from(self.touch_handlers())
    }

    fn fire_if_changed(&self, lua: &Lua) -> mlua::Result<()> {
        self.deliver_contacts(lua)
    }

    fn keeps_running(&self) -> bool {
        self.handlers_can_fire()
    }
}
