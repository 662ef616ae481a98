//! Web services: the grid nodes' latitude/longitude sent in batches.

use std::sync::atomic::AtomicBool;

use terramesh_web::{fetch, Endpoint, FetchOptions, PointStore};

use super::plan::SamplePlan;
use super::table::SampleTable;
use crate::error::{Context, Error, Result};
use crate::progress::Progress;

fn fnv(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Asks the service for every node, reporting the points answered.
pub fn sample_web(
    s: &SamplePlan,
    endpoint: &Endpoint,
    progress: &dyn Progress,
) -> Result<SampleTable> {
    let nodes = s.nodes()?;
    let latlon: Vec<[f64; 2]> = nodes
        .iter()
        .map(|n| n.latlon)
        .collect::<Option<_>>()
        .ok_or(Error::ServiceNeedsLatLon)?;
    let opts = FetchOptions {
        cache: s
            .cache_dir
            .as_ref()
            .map(|d| d.join(format!("elevations-{:016x}.txt", fnv(&endpoint.cache_id())))),
        ..s.fetch.clone()
    };
    progress.task_start("points", latlon.len() as u64);
    let cancel = AtomicBool::new(false);
    let (z, stats) = fetch(
        endpoint,
        &latlon,
        &opts,
        &|done, _| progress.task_advance(done as u64),
        &cancel,
    )?;
    progress.task_end();
    let failed = z.iter().filter(|z| z.is_err()).count();
    // A finished run with every point answered needs no journal.
    if failed == 0 {
        if let Some(j) = &opts.journal {
            if j.exists() {
                PointStore::open(j, true)?
                    .remove()
                    .with_context(|| format!("removing {}", j.display()))?;
            }
        }
    }
    let rows = super::table::node_rows(&nodes, z);
    Ok(SampleTable {
        lacking: Vec::new(),
        zone: s.zone,
        rows,
        summary: format!(
            "{} ({}): {} from the journal/cache, {} fetched in {} requests ({} retries)",
            s.options.source,
            endpoint.base_url,
            stats.from_store,
            stats.fetched,
            stats.requests,
            stats.retries
        ),
    })
}
