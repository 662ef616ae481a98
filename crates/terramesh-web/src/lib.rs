//! Elevation web services for **terramesh**: the modern replacement of the paper's Google
//! Earth step. Google Maps Elevation API, OpenTopoData and Open-Elevation clients with
//! batching to each service's limit, bounded concurrency, a request rate limit, retries with
//! exponential backoff and jitter (timeouts, connection errors, HTTP 429 and 5xx, malformed or
//! short replies), an on-disk cache and a resumable journal; and Terrarium terrain tiles
//! fetched from a URL template with a disk cache.
//!
//! [`mock`] is a fault-injecting HTTP server on 127.0.0.1 for tests and benchmarks; the
//! example asks it for two points, the way a client asks OpenTopoData:
//!
//! ```
//! # fn main() -> Result<(), terramesh_web::WebError> {
//! use std::sync::atomic::AtomicBool;
//! use std::time::Duration;
//! use terramesh_web::mock::{elevation_at, Fault, MockServer};
//! use terramesh_web::{fetch, Endpoint, FetchOptions, PointError, ServiceKind};
//! let server = MockServer::start(ServiceKind::OpenTopoData, Duration::ZERO, |_, _| Fault::None, Default::default());
//! let service = Endpoint::parse(&format!("opentopodata:{}/v1/srtm30m", server.url()), None)?;
//! let points = [[48.7242, 7.3386], [89.5, 0.0]]; // [lat, lon]; the mock has no data north of 89 N
//! let (z, stats) = fetch(&service, &points, &FetchOptions::default(), &|_, _| {}, &AtomicBool::new(false))?;
//! assert_eq!(z[0], Ok(elevation_at(48.7242, 7.3386).unwrap()));
//! assert!(matches!(z[1], Err(PointError::NoData)));
//! assert_eq!(stats.requests, 1);
//! # Ok(()) }
//! ```
#![warn(missing_docs)]

mod endpoint;
mod fetch;
pub mod mock;
mod store;
mod tiles;

pub use endpoint::{Endpoint, Reply, ServiceKind};
pub use fetch::{fetch, FetchOptions, FetchStats, PointError};
pub use store::PointStore;
pub use tiles::{fetch_tiles, TileOptions};

/// Errors that stop a whole fetch.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WebError {
    /// A bad source specification or option.
    #[error("{0}")]
    Config(String),
    /// The service refused the requests (bad key, invalid request); retrying will not help.
    #[error("the elevation service refused the request: {0}")]
    Refused(String),
    /// The cache or journal could not be read or written.
    #[error("{file}: {source}")]
    Store {
        /// The file.
        file: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A tile could not be fetched.
    #[error("tile {tile}: {message}")]
    Tile {
        /// `z/x/y`.
        tile: String,
        /// What went wrong.
        message: String,
    },
}
