//! Why the daemon cannot join its cluster: the error every part of the cluster reports.

/// Why the daemon cannot join its cluster.
#[derive(Debug, thiserror::Error)]
pub enum ClusterError {
    /// A flag is missing, malformed or unsafe; the message names it.
    #[error("{0}")]
    Flags(String),
    /// A name is unusable.
    #[error(transparent)]
    Name(#[from] shm_layout::cluster::NameError),
    /// An endpoint is malformed.
    #[error(transparent)]
    Endpoint(#[from] shm_layout::cluster::EndpointError),
    /// Another daemon of the cluster already has the name.
    #[error(
        "a daemon named {name:?} is already alive in cluster {cluster:?}: choose another --name"
    )]
    NameTaken {
        /// The cluster.
        cluster: String,
        /// The name.
        name: String,
    },
    /// Zenoh failed (a port in use, a certificate that does not load, ...).
    #[error("cluster transport: {0}")]
    Zenoh(String),
}
