//! Planes: options, zero-copy snapshots of the newest tick, stepping and waiting for ticks.

use std::rc::Rc;
use std::time::{Duration, Instant};

use shm_layout::{
    BodyState, CollisionGroups, Command, Handle, PlaneId, PlaneInfo, PlaneOp, PlaneProp, Pose,
    Reply, TickHeader,
};

use crate::client::unexpected;
use crate::overlay::Entry;
use crate::plane_shared::PlaneShared;
use crate::transport::{BodySample, LIVENESS_PERIOD};
use crate::{client::Client, error::Error};

/// Options of a new plane: declared with the plane settings table (one field per option,
/// a builder over [`PlaneProp`]).
pub use shm_layout::PlaneOptions;

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

    /// The pose of `handle` as [`Plane::body`] gives it, reading only the pose from the
    /// sample when this process has no unconfirmed write on it (the common case: a game's
    /// pose reads, many a frame, copy 28 bytes instead of the whole state).
    pub(crate) fn pose(&self, handle: Handle) -> Result<Option<Pose>, Error> {
        let frame = self.client.frame();
        // What `body` would do first (collect a pipelined flush's reply), or a write of
        // this process on the object: the whole path.
        let collect = self.shared.looks_in(frame) && self.client.has_in_flight();
        if !(collect || self.shared.overlay.borrow().has(handle)) {
            self.shared.refresh_in_frame(frame)?;
            let latest = self.shared.latest.borrow();
            return Ok(latest
                .as_ref()
                .and_then(|s| s.payload().get(handle.slot as usize))
                .filter(|s| s.matches(handle))
                .map(|s| s.pose()));
        }
        Ok(self.body(handle)?.map(|s| s.pose()))
    }

    /// The state of `handle` as this process should see it: the newest sample with this
    /// process's unconfirmed writes on top. `None` when the object does not exist.
    pub(crate) fn body(&self, handle: Handle) -> Result<Option<BodyState>, Error> {
        let (tick, base) = {
            let frame = self.client.frame();
            if self.shared.looks_in(frame) && self.client.has_in_flight() {
                // A pipelined flush's reply says which tick applied its writes: with it, a
                // newer sample replaces them (`Client::flush`).
                self.client.collect_in_flight(false)?;
            }
            self.shared.refresh_in_frame(frame)?;
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
        // A removal in a pipelined flush counts until its reply says which tick applied it.
        self.client.collect_in_flight(true)?;
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

    /// Advances a plane by `dt` seconds (with the queue sent first) and returns once the
    /// new tick is visible in [`Plane::snapshot`]. Returns the tick number.
    pub fn step(&self, dt: f32) -> Result<u64, Error> {
        // The reply is due after about the last step's time: poll for it that long rather
        // than pay the scheduler's wake-up on top of a small step (`crate::spin`).
        let last = self
            .shared
            .latest
            .borrow()
            .as_ref()
            .map(|s| *s.user_header());
        self.client
            .spin_next_reply(crate::spin::step_reply(last.as_ref()));
        let reply = self
            .client
            .call(Command::plane(self.id(), PlaneOp::Step { dt }));
        self.client.spin_next_reply(Duration::ZERO);
        match reply? {
            Reply::Stepped { tick } => {
                // The daemon sends the sample before the reply, so it is already here.
                self.shared.refresh()?;
                Ok(tick)
            }
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// Queues a step of `dt` seconds after the writes queued so far: it runs when the queue
    /// is sent (the next [`Client::flush`] or call), and its tick is published as a
    /// [`Plane::step`]'s is. On a client connected with
    /// [`crate::ConnectOptions::refusals_at_next_call`] the flush does not wait for it, so a
    /// game loop that ends each frame with `queue_step` and `flush` has the daemon step
    /// while the game sleeps or renders, and reads the new tick in its next frame; a
    /// refused step (a bad `dt`, a daemon-side limit) is reported by the next call into the
    /// plane, as a refused write is.
    pub fn queue_step(&self, dt: f32) -> Result<(), Error> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::Invalid {
                field: "dt".into(),
                message: format!("a step needs a finite dt > 0 s, got {dt}"),
            });
        }
        self.client
            .queue(Command::plane(self.id(), PlaneOp::Step { dt }), None);
        Ok(())
    }

    /// Waits until a tick newer than the one visible now is published. Returns its number.
    ///
    /// On a timer-driven plane the next tick is due a period after the last one ended: the
    /// wait sleeps until shortly before that, polls shared memory until shortly after it,
    /// and only then sleeps on the tick event, so a tick on time reaches the reader without
    /// the scheduler's wake-up. The polling window starts as [`crate::spin::LEAD`] before
    /// to [`crate::spin::TAIL`] after the predicted moment and then follows where this
    /// plane's ticks actually land ([`crate::spin::Landing`]), polling at most
    /// [`crate::spin::MAX_SPIN`] of one core per tick. [`Plane::wait_tick_spin`] with no
    /// spin only ever sleeps on the event.
    pub fn wait_tick(&self, timeout: Duration) -> Result<u64, Error> {
        self.shared.refresh()?;
        let seen = self.shared.current_tick();
        let last = self
            .shared
            .latest
            .borrow()
            .as_ref()
            .map(|s| *s.user_header());
        let Some((due, period)) = last.and_then(|h| {
            let mut landing = self.shared.landing.borrow_mut();
            landing.follow(&h);
            Some((landing.next_end_ns(&h)?, crate::spin::period_ns(&h)? as u64))
        }) else {
            return self.wait_tick_after(seen, timeout, Duration::ZERO);
        };
        let window = self.shared.landing.borrow().window();
        let deadline = Instant::now() + timeout;
        let tick = loop {
            self.shared.refresh()?;
            match self.shared.current_tick() {
                Some(t) if Some(t) != seen => break t,
                _ => {}
            }
            let left = deadline.saturating_duration_since(Instant::now());
            match crate::spin::phase_in(shm_layout::monotonic_ns(), due, window) {
                // Yield rather than spin: the daemon may need this core to publish.
                crate::spin::Phase::Poll if !left.is_zero() => std::thread::yield_now(),
                crate::spin::Phase::Doze(d) if !left.is_zero() => {
                    let d = d.min(left).min(LIVENESS_PERIOD);
                    if d > crate::spin::COARSE {
                        // Far from the moment: sleep on the tick event (an early tick wakes
                        // us), stopping COARSE short of the window.
                        self.tick_listener()
                            .map_err(|e| self.via().0.check_daemon().err().unwrap_or(e))?;
                        if let Some(l) = self.shared.ticks.borrow().as_ref() {
                            l.timed_wait(d - crate::spin::COARSE);
                        }
                    } else {
                        // The event's timed wait ends on the kernel's coarse socket timer
                        // (rounded up by milliseconds: past the window, and the tick then
                        // wakes the reader through the scheduler). A plain sleep ends on
                        // time.
                        std::thread::sleep(d);
                    }
                }
                // Past the window (or the time is up): the plain wait, which also watches
                // the daemon's liveness and reports the timeout.
                _ => break self.wait_tick_after(seen, left, Duration::ZERO)?,
            }
        };
        // The tick right after the one the prediction came from teaches the window.
        let end = self
            .shared
            .latest
            .borrow()
            .as_ref()
            .map(|s| *s.user_header())
            .filter(|h| seen.is_some_and(|s| h.tick == s + 1))
            .map(|h| h.tick_end_ns);
        if let Some(end) = end {
            self.shared.landing.borrow_mut().observe(due, end, period);
        }
        Ok(tick)
    }

    /// Like [`Plane::wait_tick`], but first polls the shared-memory queue for up to `spin`
    /// (no syscall, one core busy) before sleeping on the tick event. A reader that must
    /// react within microseconds trades that core for the scheduler's wake-up latency
    /// (tens to hundreds of microseconds on a loaded machine).
    pub fn wait_tick_spin(&self, timeout: Duration, spin: Duration) -> Result<u64, Error> {
        self.shared.refresh()?;
        let seen = self.shared.current_tick();
        self.wait_tick_after(seen, timeout, spin)
    }

    /// [`Plane::wait_tick_spin`] for a tick other than `seen`.
    fn wait_tick_after(
        &self,
        seen: Option<u64>,
        timeout: Duration,
        spin: Duration,
    ) -> Result<u64, Error> {
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
                // A plane that moved is switched over here (its ticks come from elsewhere).
                self.look_for_move()?;
                last_check = now;
            }
            // A failure to reach the tick event most likely means the daemon is gone.
            self.tick_listener()
                .map_err(|e| self.via().0.check_daemon().err().unwrap_or(e))?;
            let wait = (deadline - now).min(LIVENESS_PERIOD);
            if let Some(l) = self.shared.ticks.borrow().as_ref() {
                l.timed_wait(wait);
            }
        }
    }

    fn tick_listener(&self) -> Result<(), Error> {
        if self.shared.ticks.borrow().is_some() {
            return Ok(());
        }
        let (via, id) = self.via();
        let listener = via.transport().plane_ticks(id)?;
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

/// A client's ways to get a plane handle.
impl Client {
    /// Creates a plane owned by this client (released when the client goes away).
    pub fn create_plane(&self, options: &PlaneOptions) -> Result<Plane, Error> {
        let info = match self.call(Command::CreatePlane {
            kind: options.kind.unwrap_or_default(),
            props: options.props(),
        })? {
            Reply::Plane(info) => info,
            other => return Err(unexpected(other)),
        };
        let id = info.id;
        let plane = match self.attach_plane(id) {
            Ok(plane) => plane,
            Err(e) => {
                // A plane nobody can read (a remote session at its streaming bound, say) is
                // not left behind.
                let _ = self.call(Command::plane(id, PlaneOp::Destroy));
                return Err(e);
            }
        };
        plane.shared.note_info(&info);
        *plane.shared.mirror.borrow_mut() =
            crate::mirror::Mirror::exclusive(info, options.shared == Some(true));
        self.note_owned(id);
        let table = self.groups(CollisionGroups::clone);
        if table != CollisionGroups::default() {
            self.queue(Command::plane(id, PlaneOp::CollisionGroups(table)), None);
        }
        Ok(plane)
    }

    /// Opens an existing plane (created by any client) for reading and writing. Returns once
    /// the plane's newest tick is readable.
    pub fn attach_plane(&self, id: PlaneId) -> Result<Plane, Error> {
        if let Some(shared) = self.attached(id) {
            return Ok(Plane::new(self.clone(), shared));
        }
        let shared = match PlaneShared::open(self.transport(), id) {
            Ok(s) => Rc::new(s),
            // No such service: let the daemon say why (unknown plane, or gone).
            Err(e) => {
                self.call(Command::plane(id, PlaneOp::Info))?;
                return Err(e);
            }
        };
        // Asking after subscribing makes the daemon hand the newest tick to the new reader.
        if let Reply::Plane(info) = self.call(Command::plane(id, PlaneOp::Info))? {
            shared.note_info(&info);
        }
        self.remember_plane(id, shared.clone());
        Ok(Plane::new(self.clone(), shared))
    }
}
