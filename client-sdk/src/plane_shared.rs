//! What a client keeps per plane, shared by every handle to it: the body subscriber and the
//! newest sample, the overlay of writes not yet published, the event reader, the mirror of
//! its properties. `Client` keeps one per attached plane; `Plane` handles point at it.

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use shm_layout::{Handle, PlaneId};

use crate::error::Error;
use crate::members::Members;
use crate::mirror::Mirror;
use crate::overlay::Overlay;
use crate::transport::{BodySample, BodySubscriber, EventSubscriber, TickListener, Transport};

/// What a client keeps per plane: the subscriber, the newest sample, the overlay.
pub(crate) struct PlaneShared {
    pub(crate) id: PlaneId,
    /// Replaced when the plane moves to another daemon (`moving`).
    pub(crate) bodies: RefCell<BodySubscriber>,
    pub(crate) latest: RefCell<Option<Rc<BodySample>>>,
    pub(crate) overlay: RefCell<Overlay>,
    /// Created on the first wait: readers that never wait pay nothing for it.
    pub(crate) ticks: RefCell<Option<TickListener>>,
    pub(crate) events: RefCell<Option<EventReader>>,
    pub(crate) alive: Cell<bool>,
    /// The client frame in which `latest` was last refreshed.
    pub(crate) refreshed_in: Cell<u64>,
    /// The plane's options and its objects' properties as this process knows them.
    pub(crate) mirror: RefCell<Mirror>,
    /// Adds and removals the newest header may not count yet ([`Plane::object_count`]).
    pub(crate) members: RefCell<Members>,
    /// Where the plane went when it moved to another daemon (`moving`).
    pub(crate) route: RefCell<Option<Route>>,
    /// The name of a persistent plane (`failover_switch` opens it by name elsewhere).
    pub(crate) persistent_name: RefCell<Option<String>>,
    /// Ticks lost when the plane came back on another member (`Plane::take_recovered`).
    pub(crate) recovered: Cell<Option<u64>>,
    /// Where the plane's ticks land against their prediction (`Plane::wait_tick`).
    pub(crate) landing: RefCell<crate::spin::Landing>,
}

impl PlaneShared {
    pub(crate) fn open(transport: &Transport, id: PlaneId) -> Result<PlaneShared, Error> {
        let bodies = transport.plane_bodies(id)?;
        Ok(PlaneShared {
            id,
            bodies: RefCell::new(bodies),
            latest: RefCell::new(None),
            overlay: RefCell::default(),
            ticks: RefCell::new(None),
            events: RefCell::new(None),
            alive: Cell::new(true),
            refreshed_in: Cell::new(0),
            mirror: RefCell::default(),
            members: RefCell::default(),
            route: RefCell::new(None),
            persistent_name: RefCell::new(None),
            recovered: Cell::new(None),
            landing: RefCell::default(),
        })
    }

    /// The daemon applied this process's writes to `handle` after `tick`.
    pub(crate) fn confirm(&self, handle: Handle, tick: u64) {
        self.overlay.borrow_mut().confirm(handle, tick);
    }

    /// The daemon applied an impulse ([`Overlay::impulse_applied`]).
    pub(crate) fn impulse_applied(&self, handle: Handle, ticket: u32, linear: [f32; 3], tick: u64) {
        self.overlay
            .borrow_mut()
            .impulse_applied(handle, ticket, linear, tick);
    }

    /// The daemon refused a write to `handle`: it must not linger as if it had happened.
    pub(crate) fn discard(&self, handle: Handle) {
        self.overlay.borrow_mut().discard(handle);
    }

    /// Takes the newest sample if one arrived: a check of a shared-memory queue, no syscall.
    pub(crate) fn refresh(&self) -> Result<(), Error> {
        while let Some(sample) = self.bodies.borrow().receive()? {
            *self.latest.borrow_mut() = Some(Rc::new(sample));
        }
        Ok(())
    }

    pub(crate) fn latest(&self) -> Result<Option<Rc<BodySample>>, Error> {
        self.refresh()?;
        Ok(self.latest.borrow().clone())
    }

    /// Whether [`PlaneShared::refresh_in_frame`] looks for a newer sample in `frame`.
    pub(crate) fn looks_in(&self, frame: u64) -> bool {
        frame == 0 || self.refreshed_in.get() != frame
    }

    /// Looks for a newer sample once per client frame (`frame` 0: every time).
    pub(crate) fn refresh_in_frame(&self, frame: u64) -> Result<(), Error> {
        if self.looks_in(frame) {
            self.refresh()?;
            self.refreshed_in.set(frame);
        }
        Ok(())
    }

    /// Remembers what the client needs to find a persistent plane again after its daemon
    /// died (`failover_switch`).
    pub(crate) fn note_info(&self, info: &shm_layout::PlaneInfo) {
        let s = &info.settings;
        if s.persistent && !s.name.is_none() {
            *self.persistent_name.borrow_mut() = Some(s.name.as_str().to_string());
        }
    }

    pub(crate) fn current_tick(&self) -> Option<u64> {
        self.latest.borrow().as_ref().map(|s| s.user_header().tick)
    }
}

/// Where a moved plane's commands go (`moving`, `failover_switch`): the connection to its
/// daemon now (`Client::downgrade`: held weakly, it belongs to the client that switched
/// the plane) and the plane's id there.
#[derive(Clone)]
pub(crate) struct Route {
    pub(crate) peer: std::rc::Weak<dyn std::any::Any>,
    pub(crate) id: PlaneId,
}

/// A subscription to a plane's events and the number (modulo 2³²) of the next event it
/// expects.
pub(crate) struct EventReader {
    pub(crate) subscriber: EventSubscriber,
    pub(crate) next_seq: Cell<u32>,
}

impl EventReader {
    /// `start`: the plane's event count at its newest tick when the subscriber existed
    /// (events from there on reach it).
    pub(crate) fn new(subscriber: EventSubscriber, start: u32) -> EventReader {
        EventReader {
            subscriber,
            next_seq: Cell::new(start),
        }
    }
}
