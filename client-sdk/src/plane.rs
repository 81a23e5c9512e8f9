//! Planes: options, zero-copy snapshots of the newest tick, stepping and waiting for ticks.

use std::cell::{Cell, RefCell};
use std::rc::Rc;
use std::time::{Duration, Instant};

use shm_layout::{
    BodyState, Command, Handle, ObjectProp, PlaneId, PlaneInfo, PlaneOp, PlaneProp, Pose, Reply,
    Shape, TickHeader,
};

use crate::client::LIVENESS_PERIOD;
use crate::events::EventReader;
use crate::members::Members;
use crate::mirror::Mirror;
use crate::overlay::{Entry, Overlay};
use crate::transport::{BodySample, BodySubscriber, TickListener, Transport};
use crate::{Client, Error, Object};

/// Options of a new plane: declared with the plane settings table (one field per option,
/// a builder over [`PlaneProp`]).
pub use shm_layout::PlaneOptions;

/// What a client keeps per plane: the subscriber, the newest sample, the overlay.
pub(crate) struct PlaneShared {
    id: PlaneId,
    bodies: BodySubscriber,
    latest: RefCell<Option<Rc<BodySample>>>,
    overlay: RefCell<Overlay>,
    /// Created on the first wait: readers that never wait pay nothing for it.
    ticks: RefCell<Option<TickListener>>,
    pub(crate) events: RefCell<Option<EventReader>>,
    alive: Cell<bool>,
    /// The client frame in which `latest` was last refreshed.
    refreshed_in: Cell<u64>,
    /// The plane's options and its objects' properties as this process knows them.
    pub(crate) mirror: RefCell<Mirror>,
    /// Adds and removals the newest header may not count yet ([`Plane::object_count`]).
    pub(crate) members: RefCell<Members>,
}

impl PlaneShared {
    pub(crate) fn open(transport: &Transport, id: PlaneId) -> Result<PlaneShared, Error> {
        let bodies = transport.plane_bodies(id)?;
        Ok(PlaneShared {
            id,
            bodies,
            latest: RefCell::new(None),
            overlay: RefCell::default(),
            ticks: RefCell::new(None),
            events: RefCell::new(None),
            alive: Cell::new(true),
            refreshed_in: Cell::new(0),
            mirror: RefCell::default(),
            members: RefCell::default(),
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
    fn refresh(&self) -> Result<(), Error> {
        loop {
            match self.bodies.receive() {
                Ok(Some(sample)) => *self.latest.borrow_mut() = Some(Rc::new(sample)),
                Ok(None) => return Ok(()),
                // Every borrow slot is held by snapshots the caller keeps: keep the newest we have.
                Err(iceoryx2::port::ReceiveError::ExceedsMaxBorrows) => return Ok(()),
                Err(e) => return Err(Error::ipc("receive tick", e)),
            }
        }
    }

    fn latest(&self) -> Result<Option<Rc<BodySample>>, Error> {
        self.refresh()?;
        Ok(self.latest.borrow().clone())
    }

    /// Looks for a newer sample once per client frame (`frame` 0: every time).
    fn refresh_in_frame(&self, frame: u64) -> Result<(), Error> {
        if frame == 0 || self.refreshed_in.get() != frame {
            self.refresh()?;
            self.refreshed_in.set(frame);
        }
        Ok(())
    }

    fn current_tick(&self) -> Option<u64> {
        self.latest.borrow().as_ref().map(|s| s.user_header().tick)
    }
}

/// One tick of a plane, read in place from shared memory.
#[derive(Clone)]
pub struct Snapshot {
    sample: Rc<BodySample>,
}

impl Snapshot {
    /// The tick's header (tick number, time, step time, error figures).
    pub fn header(&self) -> &TickHeader {
        self.sample.user_header()
    }

    /// The tick number.
    pub fn tick(&self) -> u64 {
        self.header().tick
    }

    /// Every slot of the plane, indexed by [`Handle::slot`].
    pub fn bodies(&self) -> &[BodyState] {
        self.sample.payload()
    }

    /// The state of `handle`, or `None` when the slot is empty or reused.
    pub fn get(&self, handle: Handle) -> Option<&BodyState> {
        self.bodies()
            .get(handle.slot as usize)
            .filter(|s| s.matches(handle))
    }
}

/// A plane of the daemon. Cheap to clone.
#[derive(Clone)]
pub struct Plane {
    client: Client,
    pub(crate) shared: Rc<PlaneShared>,
}

impl Plane {
    pub(crate) fn new(client: Client, shared: Rc<PlaneShared>) -> Plane {
        Plane { client, shared }
    }

    /// The plane's id.
    pub fn id(&self) -> PlaneId {
        self.shared.id
    }

    /// The client this handle talks through.
    pub fn client(&self) -> &Client {
        &self.client
    }

    /// The newest published tick (zero-copy).
    pub fn snapshot(&self) -> Result<Snapshot, Error> {
        match self.shared.latest()? {
            Some(sample) => Ok(Snapshot { sample }),
            None => Err(Error::Protocol(format!(
                "plane {} has published nothing yet",
                self.id()
            ))),
        }
    }

    /// The state of `handle` as this process should see it: the newest sample with this
    /// process's unconfirmed writes on top. `None` when the object does not exist.
    pub(crate) fn body(&self, handle: Handle) -> Result<Option<BodyState>, Error> {
        let (tick, base) = {
            self.shared.refresh_in_frame(self.client.frame())?;
            let latest = self.shared.latest.borrow();
            let sample = latest.as_ref();
            (
                sample.map_or(0, |s| s.user_header().tick),
                sample
                    .and_then(|s| s.payload().get(handle.slot as usize).copied())
                    .filter(|s| s.matches(handle)),
            )
        };
        let mut overlay = self.shared.overlay.borrow_mut();
        Ok(match overlay.get(handle, tick) {
            Some(entry) if entry.impulse_pending => {
                // Only the daemon knows the velocity an impulse leaves (mass, locks,
                // anchoring): send the queue, whose reply carries it, then read again.
                drop(overlay);
                self.client.send_queue()?;
                let mut overlay = self.shared.overlay.borrow_mut();
                match overlay.get(handle, tick) {
                    Some(entry) if !entry.impulse_pending => entry.apply(handle, base),
                    // Gone, or not settled by that send: the sample, rather than a loop.
                    _ => base,
                }
            }
            Some(entry) => entry.apply(handle, base),
            None => base,
        })
    }

    /// Records an impulse queued on `handle` (read-your-writes: see [`Plane::body`]).
    pub(crate) fn impulse_queued(&self, handle: Handle) -> u32 {
        self.shared.overlay.borrow_mut().write_ticketed(handle)
    }

    /// [`Plane::object_count`] from the newest header and this process's pending changes;
    /// `None` when only the daemon can say.
    pub(crate) fn published_object_count(&self) -> Result<Option<u32>, Error> {
        if !self.shared.alive.get() {
            return Ok(None);
        }
        self.shared.refresh_in_frame(self.client.frame())?;
        let header = self
            .shared
            .latest
            .borrow()
            .as_ref()
            .map(|s| *s.user_header());
        Ok(header.and_then(|h| self.shared.members.borrow_mut().count(h.tick, h.body_count)))
    }

    /// Records this process's write to `handle` so reads see it until a tick shows it.
    pub(crate) fn overlay_write(&self, handle: Handle, f: impl FnOnce(&mut Entry)) {
        self.shared.overlay.borrow_mut().write(handle, f);
    }

    /// The daemon applied every write recorded for `handle` by tick `tick`.
    pub(crate) fn overlay_confirm(&self, handle: Handle, tick: u64) {
        self.shared.overlay.borrow_mut().confirm(handle, tick);
    }

    /// The determinism hash of the newest published tick ([`TickHeader::state_hash`]: every
    /// body's pose, velocities, flags and generation, bit for bit, in slot order). Two runs
    /// of the same commands agree on it tick by tick; a replay that diverges shows it on the
    /// first tick it differs. Reads shared memory only.
    pub fn state_hash(&self) -> Result<u64, Error> {
        Ok(self.snapshot()?.header().state_hash)
    }

    /// Every option and figure of the plane (sends the queue first).
    pub fn info(&self) -> Result<PlaneInfo, Error> {
        match self.client.call(Command::plane(self.id(), PlaneOp::Info))? {
            Reply::Plane(info) => {
                self.shared.mirror.borrow_mut().store_plane(&info);
                Ok(info)
            }
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// The plane's options without a round trip where this process mirrors them (a plane
    /// it created and did not share: filled by the creation reply and its own writes);
    /// otherwise [`Plane::info`]. `tick` is the newest published tick; `object_count` and
    /// `effective_solver_iterations` are as of the last `info` read: ask [`Plane::info`]
    /// for those.
    pub fn properties(&self) -> Result<PlaneInfo, Error> {
        let mirrored = self.shared.mirror.borrow().plane().cloned();
        match mirrored {
            Some(mut info) if self.shared.alive.get() => {
                if let Some(tick) = self.shared.current_tick() {
                    info.tick = tick;
                }
                Ok(info)
            }
            _ => self.info(),
        }
    }

    /// Changes a plane option (checked now, sent with the next flush).
    pub fn set(&self, prop: PlaneProp) -> Result<(), Error> {
        let prop = prop.checked().map_err(Error::invalid_value)?;
        self.shared.mirror.borrow_mut().plane_written(&prop);
        self.client
            .queue(Command::plane(self.id(), PlaneOp::Set(prop)), None);
        Ok(())
    }

    /// [`Plane::set`] applied at once: sends the queued writes and this one as one request
    /// and returns the daemon's verdict on it, for a write whose refusal depends on the
    /// plane's state (`DeferGpu = true` with a joint present or no adapter).
    pub fn set_now(&self, prop: PlaneProp) -> Result<(), Error> {
        let prop = prop.checked().map_err(Error::invalid_value)?;
        self.shared.mirror.borrow_mut().plane_written(&prop);
        let result = self
            .client
            .call(Command::plane(self.id(), PlaneOp::Set(prop)));
        if result.is_err() {
            // A refused write must not linger in the mirror.
            self.shared.mirror.borrow_mut().forget_plane();
        }
        result.map(|_| ())
    }

    /// Forgets what this process keeps of the plane's state (written values not yet
    /// published, counts, mirrored properties) and takes the newest sample: after a restore
    /// the daemon's state is the truth.
    pub(crate) fn forget_local_state(&self) {
        *self.shared.overlay.borrow_mut() = Default::default();
        *self.shared.members.borrow_mut() = Default::default();
        self.shared.mirror.borrow_mut().forget_all();
        let _ = self.shared.refresh();
    }

    /// False once this process destroyed the plane or the daemon no longer knows it.
    pub fn is_alive(&self) -> bool {
        if !self.shared.alive.get() {
            return false;
        }
        match self.info() {
            Err(Error::Command(e)) if e.kind == shm_layout::ErrorKind::UnknownPlane => {
                self.shared.alive.set(false);
                false
            }
            _ => true,
        }
    }

    /// Live objects of the plane (controllers and maps included), without a round trip:
    /// the newest tick header's count (taken once per client frame, like poses) with this
    /// process's adds and removals that tick does not show yet. Asks the daemon only when
    /// nothing was published yet, the plane is gone, or after a map build.
    pub fn object_count(&self) -> Result<u32, Error> {
        if let Some(n) = self.published_object_count()? {
            return Ok(n);
        }
        let info = self.info()?;
        self.shared.members.borrow_mut().asked(info.tick);
        Ok(info.object_count)
    }

    /// Adds an object; sends the queue and waits for the new handle.
    pub fn add(&self, shape: Shape, pose: Pose, props: &[ObjectProp]) -> Result<Object, Error> {
        shape.check().map_err(Error::invalid_value)?;
        let pose = shm_layout::validate::pose("CFrame", pose).map_err(Error::invalid_value)?;
        let props = props
            .iter()
            .map(|p| p.checked())
            .collect::<Result<Vec<_>, _>>()
            .map_err(Error::invalid_value)?;
        let hold = self.client.holds_adds();
        let mut sent = props.clone();
        if hold {
            sent.push(ObjectProp::Held(true));
        }
        let reply = self.client.call(Command::plane(
            self.id(),
            PlaneOp::AddObject {
                shape,
                pose,
                props: sent,
            },
        ))?;
        let Reply::Object { handle, tick } = reply else {
            return Err(Error::Protocol(format!("unexpected reply {reply:?}")));
        };
        if hold {
            // Released by the next flush, together with what the caller writes until then.
            let release = PlaneOp::Object {
                handle,
                op: shm_layout::ObjectOp::Set(ObjectProp::Held(false)),
            };
            self.client.queue(Command::plane(self.id(), release), None);
        }
        // Until a sample shows it, the object reads back as created.
        let mut overlay = self.shared.overlay.borrow_mut();
        overlay.write(handle, |e| {
            e.pose = Some(pose);
            e.velocity = Some([0.0; 3]);
            e.angular_velocity = Some([0.0; 3]);
            for p in &props {
                e.record(p);
            }
        });
        overlay.confirm(handle, tick);
        self.shared.members.borrow_mut().added(tick);
        Ok(Object::new(self.clone(), handle))
    }

    /// Advances a plane by `dt` seconds (with the queue sent first) and returns once the
    /// new tick is visible in [`Plane::snapshot`]. Returns the tick number.
    pub fn step(&self, dt: f32) -> Result<u64, Error> {
        match self
            .client
            .call(Command::plane(self.id(), PlaneOp::Step { dt }))?
        {
            Reply::Stepped { tick } => {
                // The daemon sends the sample before the reply, so it is already here.
                self.shared.refresh()?;
                Ok(tick)
            }
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// Waits until a tick newer than the one visible now is published. Returns its number.
    pub fn wait_tick(&self, timeout: Duration) -> Result<u64, Error> {
        self.wait_tick_spin(timeout, Duration::ZERO)
    }

    /// Like [`Plane::wait_tick`], but first polls the shared-memory queue for up to `spin`
    /// (no syscall, one core busy) before sleeping on the tick event. A reader that must
    /// react within microseconds trades that core for the scheduler's wake-up latency
    /// (tens to hundreds of microseconds on a loaded machine).
    pub fn wait_tick_spin(&self, timeout: Duration, spin: Duration) -> Result<u64, Error> {
        self.shared.refresh()?;
        let seen = self.shared.current_tick();
        let started = Instant::now();
        let deadline = started + timeout;
        let spin_until = started + spin.min(timeout);
        let mut last_check = started;
        loop {
            self.shared.refresh()?;
            match self.shared.current_tick() {
                Some(t) if Some(t) != seen => return Ok(t),
                _ => {}
            }
            let now = Instant::now();
            if now < spin_until {
                std::hint::spin_loop();
                continue;
            }
            if now >= deadline {
                return Err(Error::Timeout(timeout));
            }
            // Listing nodes costs a directory scan: check the daemon's liveness only when a
            // wait brought no tick for a while, never on the hot path of a delivered tick.
            if now.duration_since(last_check) >= LIVENESS_PERIOD {
                self.client.check_daemon()?;
                last_check = now;
            }
            // A failure to reach the tick event most likely means the daemon is gone.
            self.tick_listener()
                .map_err(|e| self.client.check_daemon().err().unwrap_or(e))?;
            let wait = (deadline - now).min(LIVENESS_PERIOD);
            if let Some(l) = self.shared.ticks.borrow().as_ref() {
                let _ = l.timed_wait(|_| {}, wait);
            }
        }
    }

    fn tick_listener(&self) -> Result<(), Error> {
        if self.shared.ticks.borrow().is_some() {
            return Ok(());
        }
        let listener = self.client.transport().plane_ticks(self.id())?;
        *self.shared.ticks.borrow_mut() = Some(listener);
        Ok(())
    }

    /// Destroys the plane and everything in it. Objects keep reading their last pose.
    pub fn destroy(&self) -> Result<(), Error> {
        self.client
            .call(Command::plane(self.id(), PlaneOp::Destroy))?;
        self.shared.alive.set(false);
        self.client.forget_plane(self.id());
        Ok(())
    }
}

impl std::fmt::Debug for Plane {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Plane").field("id", &self.id()).finish()
    }
}
