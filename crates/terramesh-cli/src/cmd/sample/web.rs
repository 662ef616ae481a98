//! Web services: the grid nodes' latitude/longitude sent in batches.

use std::sync::atomic::AtomicBool;

use anyhow::{Context, Result};
use terramesh_web::{fetch, Endpoint, FetchOptions, PointError, PointStore};

use super::settings::Settings;
use super::write::{Row, Samples};

fn fnv(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Asks the service for every node, with a progress bar.
pub fn sample_web(s: &Settings, endpoint: &Endpoint) -> Result<Samples> {
    let nodes = s.nodes()?;
    let latlon: Vec<[f64; 2]> = nodes
        .iter()
        .map(|n| n.latlon)
        .collect::<Option<_>>()
        .context("elevation services need a region in latitude/longitude")?;
    let opts = FetchOptions {
        cache: s
            .cache_dir
            .as_ref()
            .map(|d| d.join(format!("elevations-{:016x}.txt", fnv(&endpoint.cache_id())))),
        ..s.fetch.clone()
    };
    let bar = if s.progress {
        let b = indicatif::ProgressBar::new(latlon.len() as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} points  {per_sec}  ETA {eta}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let cancel = AtomicBool::new(false);
    let (z, stats) = fetch(
        endpoint,
        &latlon,
        &opts,
        &|done, _| bar.set_position(done as u64),
        &cancel,
    )?;
    bar.finish_and_clear();
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
    let rows = nodes
        .iter()
        .zip(z)
        .map(|(n, z)| Row {
            latlon: n.latlon,
            xy: n.xy,
            z: z.map_err(|e: PointError| e.to_string()),
        })
        .collect();
    Ok(Samples {
        zone: s.zone,
        rows,
        summary: format!(
            "{} ({}): {} from the journal/cache, {} fetched in {} requests ({} retries)",
            s.source_name,
            endpoint.base_url,
            stats.from_store,
            stats.fetched,
            stats.requests,
            stats.retries
        ),
    })
}
