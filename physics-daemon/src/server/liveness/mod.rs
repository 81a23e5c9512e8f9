//! Noticing gone clients cheaply, and telling clients the daemon lives: when to list nodes
//! ([`schedule`]), process watches through pidfds ([`pidwatch`]), the loop's wake-up when a
//! watched process exits ([`alarm`]), wake-ups on node folder changes ([`folder_watch`]),
//! and the daemon's heartbeat ([`heartbeat`]).

pub mod alarm;
pub mod folder_watch;
pub mod heartbeat;
pub mod pidwatch;
pub mod schedule;
