//! Pipelined flushes: a frame's writes sent without waiting for the reply, which a later
//! request, frame or read collects (at most [`MAX_IN_FLIGHT`] wait at once).

use std::time::Instant;

use shm_layout::Request;

use crate::error::Error;

use super::{Client, InFlight, MAX_IN_FLIGHT};

impl Client {
    /// Sends the queued writes without waiting for the reply, which the next request, the
    /// next frame ([`Client::begin_frame`]) or the next read of a new sample collects
    /// (`collect_in_flight`). At most [`MAX_IN_FLIGHT`] such requests wait for their
    /// replies: a flush past that waits for the oldest (a daemon more than a frame behind
    /// slows its client's frames rather than gathering requests). Only on this host's
    /// transport; elsewhere a plain send.
    pub(super) fn send_pipelined(&self) -> Result<(), Error> {
        let Some(local) = self.inner.transport.local() else {
            return self.send(Vec::new()).map(|_| ());
        };
        self.collect_in_flight(false)?;
        while self.inner.in_flight.borrow().len() >= MAX_IN_FLIGHT {
            self.collect_oldest(true)?;
        }
        if self.inner.state.borrow().gone {
            return Err(self.inner.gone());
        }
        let (sent, commands) = self.take_queue(Vec::new());
        let request = Request { commands };
        let bytes = self.inner.encode(&request);
        let pending = local.send(&bytes, self.inner.transport.id())?;
        self.inner.in_flight.borrow_mut().push_back(InFlight {
            pending,
            sent,
            commands: request.commands,
            since: Instant::now(),
        });
        Ok(())
    }

    /// Applies the replies of pipelined flushes, in order: every one (`wait`), or those
    /// that have arrived. An error met while applying them without a caller to tell (a
    /// frame's start) is kept for the next call that waits.
    pub(crate) fn collect_in_flight(&self, wait: bool) -> Result<(), Error> {
        if let Some(e) = self.inner.in_flight_error.borrow_mut().take() {
            return Err(e);
        }
        loop {
            match self.collect_oldest(wait) {
                Ok(true) => {}
                Ok(false) => return Ok(()),
                Err(e) if wait => return Err(e),
                Err(e) => {
                    *self.inner.in_flight_error.borrow_mut() = Some(e);
                    return Ok(());
                }
            }
        }
    }

    /// Applies the oldest pipelined flush's reply: waiting for it (`wait`), or only when it
    /// has arrived. False when there was none to apply.
    pub(super) fn collect_oldest(&self, wait: bool) -> Result<bool, Error> {
        let Some(local) = self.inner.transport.local() else {
            return Ok(false);
        };
        let reply = {
            let in_flight = self.inner.in_flight.borrow();
            let Some(f) = in_flight.front() else {
                return Ok(false);
            };
            match wait {
                true => Some(self.inner.await_reply(local, &f.pending, f.since)),
                false => local.try_reply(&f.pending).map_err(Error::from).transpose(),
            }
        };
        let Some(reply) = reply else {
            return Ok(false);
        };
        let f = self
            .inner
            .in_flight
            .borrow_mut()
            .pop_front()
            .expect("checked above");
        let results = self.inner.results_of(&reply?, f.commands.len())?;
        let results = self.inner.rejoin_if_forgotten(&f.commands, results)?;
        self.apply_results(f.sent, f.commands, results)?;
        Ok(true)
    }

    /// Whether a pipelined flush's reply has not been applied yet.
    pub(crate) fn has_in_flight(&self) -> bool {
        !self.inner.in_flight.borrow().is_empty()
    }
}
