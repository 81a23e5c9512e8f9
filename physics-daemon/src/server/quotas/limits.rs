//! Per-client quotas: defaults no game reaches but an attack does. Each is a daemon flag;
//! an exceeded quota is a `Quota` error naming the quota, its value and the flag. A client
//! is a process: all connections of one process share its quotas, so opening more
//! connections does not multiply them.

use shm_layout::{CommandError, ErrorKind};

/// Clients one daemon serves at once by default (`--max-clients`): with the default
/// `--max-clients-per-process` of 16, sixteen processes at their cap before the table is
/// full, so a few processes cannot lock everyone else out.
pub const MAX_CLIENTS: usize = 256;

/// The daemon's per-client and per-request limits.
#[derive(Debug, Clone, Copy, PartialEq, clap::Args)]
pub struct Limits {
    /// Clients (connections) one process may hold at once.
    #[arg(long = "max-clients-per-process", default_value_t = Limits::DEFAULT.clients_per_process)]
    pub clients_per_process: usize,
    /// Planes one client process may own at once (all its connections together).
    #[arg(long = "max-planes-per-client", default_value_t = Limits::DEFAULT.planes_per_client)]
    pub planes_per_client: usize,
    /// Objects in the planes one client process owns, all planes together.
    #[arg(long = "max-objects-per-client", default_value_t = Limits::DEFAULT.objects_per_client)]
    pub objects_per_client: u64,
    /// Vertices of one mesh part.
    #[arg(long = "max-mesh-vertices", default_value_t = Limits::DEFAULT.mesh_vertices_per_object)]
    pub mesh_vertices_per_object: u64,
    /// Mesh vertices in the planes one client process owns, all parts together.
    #[arg(
        long = "max-mesh-vertices-per-client",
        default_value_t = Limits::DEFAULT.mesh_vertices_per_client
    )]
    pub mesh_vertices_per_client: u64,
    /// Bytes of one request.
    #[arg(long = "max-request-bytes", default_value_t = Limits::DEFAULT.request_bytes)]
    pub request_bytes: usize,
    /// Commands in one request.
    #[arg(
        long = "max-commands-per-request",
        default_value_t = Limits::DEFAULT.commands_per_request
    )]
    pub commands_per_request: usize,
    /// Bytes of other state in the planes one client process owns (controller paths: 12
    /// bytes a 3D waypoint, 8 a GUI one).
    #[arg(
        long = "max-state-bytes-per-client",
        default_value_t = Limits::DEFAULT.state_bytes_per_client
    )]
    pub state_bytes_per_client: u64,
    /// Memory the daemon admits, all clients together, in MiB: planes (11 MiB each, measured:
    /// mostly their shared-memory output) and what they hold (4 KiB an object, 32 bytes a
    /// mesh vertex, controller paths). 0: half of the machine's memory.
    #[arg(long = "max-memory-mb", default_value_t = Limits::DEFAULT.memory_mb)]
    pub memory_mb: u64,
    /// Bytes of the reply to one request: results past it are refused with `Quota` (the
    /// overlap queries' own cap is `MAX_QUERY_RESULTS` objects a query).
    #[arg(long = "max-reply-bytes", default_value_t = Limits::DEFAULT.reply_bytes)]
    pub reply_bytes: usize,
    /// Milliseconds a node may hold places in the daemon's services without saying Hello.
    #[arg(long = "hello-timeout-ms", default_value_t = Limits::DEFAULT.hello_timeout_ms)]
    pub hello_timeout_ms: u64,
    /// iceoryx2 nodes one process may keep in the daemon's domain (never fewer than its
    /// clients).
    #[arg(
        long = "max-nodes-per-process",
        default_value_t = Limits::DEFAULT.nodes_per_process
    )]
    pub nodes_per_process: usize,
    /// iceoryx2 ports (request ports, subscribers, listeners) one process may hold in one
    /// service of the daemon (never fewer than its clients).
    #[arg(
        long = "max-ports-per-process",
        default_value_t = Limits::DEFAULT.ports_per_process
    )]
    pub ports_per_process: usize,
    /// Clients (connections) the daemon serves at once, all processes together. The
    /// request, wake-up and heartbeat services are sized for it (twice as many ports, for
    /// ports that never say Hello), so it cannot be raised while the daemon runs.
    #[arg(long = "max-clients", default_value_t = Limits::DEFAULT.max_clients,
          value_parser = clap::builder::TypedValueParser::map(
              clap::value_parser!(u32).range(1..=4096), |v| v as usize))]
    pub max_clients: usize,
}

impl Limits {
    /// The defaults: far above a game's needs (the benchmarks run 50,000 bodies in one
    /// plane and 1,000 writes per frame), far below what exhausts the daemon.
    pub const DEFAULT: Limits = Limits {
        clients_per_process: 16,
        planes_per_client: 64,
        objects_per_client: 250_000,
        mesh_vertices_per_object: 16_384,
        mesh_vertices_per_client: 1_000_000,
        request_bytes: 16 << 20,
        commands_per_request: 262_144,
        reply_bytes: 8 << 20,
        memory_mb: 0,
        state_bytes_per_client: 64 << 20,
        hello_timeout_ms: 5_000,
        nodes_per_process: 32,
        ports_per_process: 16,
        max_clients: MAX_CLIENTS,
    };
}

impl Limits {
    /// `--max-memory-mb` in bytes (0: half of MemTotal; without /proc/meminfo, no limit).
    pub fn memory_bytes(&self) -> u64 {
        if self.memory_mb > 0 {
            return self.memory_mb.saturating_mul(1 << 20);
        }
        std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|m| {
                let line = m.lines().find(|l| l.starts_with("MemTotal:"))?;
                line.split_whitespace().nth(1)?.parse::<u64>().ok()
            })
            .map_or(u64::MAX, |kib| kib * 1024 / 2)
    }
}

impl Default for Limits {
    fn default() -> Self {
        Limits::DEFAULT
    }
}

/// The error for an exceeded quota: names it, its value and its flag.
pub fn exceeded(
    what: &str,
    limit: impl std::fmt::Display,
    flag: &str,
    got: impl std::fmt::Display,
) -> CommandError {
    CommandError::new(
        ErrorKind::Quota,
        format!("quota exceeded: {what} is limited to {limit} (daemon flag --{flag}), this would make {got}"),
    )
}
