//! Rollback (`RollbackTicks = K`, `PlaneOp::Rewind(n)`): a plane with K > 0 keeps its state
//! after each of its last K ticks (a snapshot body each, counted in the owner's state
//! bytes) and can go back n ≤ K ticks; the script then re-applies corrected inputs and
//! steps again (rollback netcode). With K = 0 (the default) nothing is kept and a step
//! pays nothing.

use std::collections::VecDeque;

use shm_layout::{CommandError, Reply};

use super::Plane;
use crate::backend::counted::CountedVec;

/// The kept states, oldest first: `(tick, body)`.
#[derive(Debug, Default)]
pub(super) struct Ring {
    kept: VecDeque<(u64, CountedVec<u8>)>,
}

impl Ring {
    /// Forgets every kept state.
    pub fn clear(&mut self) {
        self.kept.clear();
    }
}

impl Plane {
    /// After a step: keeps the state of the new tick when RollbackTicks > 0.
    pub(super) fn keep_for_rollback(&mut self) -> Result<(), CommandError> {
        let k = self.settings.rollback_ticks as usize;
        if k == 0 {
            if !self.rollback.kept.is_empty() {
                self.rollback.clear();
            }
            return Ok(());
        }
        let body = self.state_body()?;
        // Reuse the oldest buffer once the ring is full.
        let mut buf = match self.rollback.kept.len() > k {
            true => self.rollback.kept.pop_front().map(|(_, b)| b),
            false => None,
        }
        .unwrap_or_else(|| CountedVec::new(&self.state_bytes));
        buf.replace(body);
        self.rollback.kept.push_back((self.tick, buf));
        while self.rollback.kept.len() > k + 1 {
            self.rollback.kept.pop_front();
        }
        Ok(())
    }

    /// Goes back `n` ticks (1 ≤ n ≤ RollbackTicks and ticks kept so far). The state of the
    /// tick gone back to stays kept (a second rewind to it works); later ones are dropped.
    pub(super) fn rewind(&mut self, n: u32) -> Result<Reply, CommandError> {
        let k = self.settings.rollback_ticks;
        if k == 0 {
            return Err(CommandError::invalid_field(
                "Rewind",
                "Rewind needs RollbackTicks > 0 (set it when creating the plane or before the \
                 ticks to go back over)",
            ));
        }
        let target = self.tick.checked_sub(n as u64);
        let at = target.and_then(|t| self.rollback.kept.iter().position(|(tick, _)| *tick == t));
        let (Some(target), Some(at), true) = (target, at, n <= k) else {
            let oldest = self.rollback.kept.front().map_or(self.tick, |(t, _)| *t);
            return Err(CommandError::invalid_field(
                "Rewind",
                format!(
                    "Rewind({n}) goes further back than the plane keeps: RollbackTicks = {k}, \
                     ticks {oldest}..={} kept",
                    self.tick
                ),
            ));
        };
        if n == 0 {
            return Ok(Reply::Applied { tick: self.tick });
        }
        self.rollback.kept.truncate(at + 1);
        let (_, body) = self.rollback.kept.pop_back().expect("found above");
        let result = self.adopt_body(&body);
        self.rollback.kept.push_back((target, body));
        result?;
        Ok(Reply::Applied { tick: self.tick })
    }
}
