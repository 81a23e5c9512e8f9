//! The request loop: the transport ports and the WaitSet loop in named stages (`serve`),
//! each client's queue of requests (`queue`), decoding and routing each command to its
//! plane by id (`dispatch`), the answers the loop gives on its own (`refusals`), the bytes
//! of a request copied out of the sender's memory (`request_bytes`), who sent it
//! (`origin`), and the connected clients ([`clients`]).

pub mod clients;
mod dispatch;
pub(crate) mod origin;
mod queue;
pub(crate) mod refusals;
mod request_bytes;
pub(crate) mod serve;
