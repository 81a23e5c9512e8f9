//! What a client may hold and use: the per-client limits ([`limits`]), the per-process
//! quota counters ([`quota`]), fair CPU shares ([`fair`]), the load gauge a cluster reads
//! ([`gauge`]) and the guard of the iceoryx2 resources a process holds ([`resources`]).

pub mod fair;
pub mod gauge;
pub mod limits;
pub mod quota;
pub mod resources;
