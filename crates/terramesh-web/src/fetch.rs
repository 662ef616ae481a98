//! Fetching elevations for many points: batches, bounded concurrency, a rate limit, retries
//! with exponential backoff and jitter, the cache and the resume journal.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use crate::endpoint::Reply;
use crate::store::{key, Key, PointStore};
use crate::{Endpoint, WebError};

/// Settings of a fetch. Defaults: 4 concurrent requests, no rate limit, 5 retries, 30 s
/// timeout, backoff 0.5 s doubling up to 30 s, the service's batch limit, no cache, no journal.
///
/// ```
/// use std::time::Duration;
/// let o = terramesh_web::FetchOptions { concurrency: 8, rate: Some(1.0), ..Default::default() };
/// assert_eq!(o.retries, 5);
/// assert_eq!(o.backoff, Duration::from_millis(500));
/// ```
#[derive(Debug, Clone)]
pub struct FetchOptions {
    /// Requests in flight at once (`--concurrency`).
    pub concurrency: usize,
    /// Requests per second at most (`--rate`); `None`: no limit.
    pub rate: Option<f64>,
    /// Retries of a failed request before its points get an error.
    pub retries: u32,
    /// Timeout of one request (connect and whole reply).
    pub timeout: Duration,
    /// First backoff; each retry doubles it, with full jitter.
    pub backoff: Duration,
    /// Longest wait between retries, also the cap on a server's `Retry-After`.
    pub backoff_max: Duration,
    /// Locations per request; `None`: the service's limit.
    pub batch: Option<usize>,
    /// Cache file shared between runs.
    pub cache: Option<PathBuf>,
    /// Journal of this run.
    pub journal: Option<PathBuf>,
    /// Continue from the journal instead of starting it afresh.
    pub resume: bool,
}

impl Default for FetchOptions {
    fn default() -> Self {
        FetchOptions {
            concurrency: 4,
            rate: None,
            retries: 5,
            timeout: Duration::from_secs(30),
            backoff: Duration::from_millis(500),
            backoff_max: Duration::from_secs(30),
            batch: None,
            cache: None,
            journal: None,
            resume: false,
        }
    }
}

/// Why one point has no elevation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PointError {
    /// The service answered but has no data there (`null` elevation).
    #[error("the service has no data at this location")]
    NoData,
    /// Every attempt of the batch holding this point failed.
    #[error("request failed after {attempts} attempts: {last}")]
    Failed {
        /// Attempts made.
        attempts: u32,
        /// The last failure.
        last: String,
    },
    /// The run was cancelled before this point was asked.
    #[error("not fetched: the run was interrupted")]
    Cancelled,
}

/// Counts of a finished fetch.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct FetchStats {
    /// Points answered from the journal or cache.
    pub from_store: usize,
    /// Points answered by the service in this run.
    pub fetched: usize,
    /// HTTP requests sent (retries included).
    pub requests: usize,
    /// Retries.
    pub retries: usize,
}

/// The outcome of one request.
enum Attempt {
    /// The elevations, in order (`None`: no data there).
    Done(Vec<Option<f64>>),
    /// A failure worth retrying, with the server's `Retry-After` in seconds.
    Retry {
        why: String,
        retry_after: Option<f64>,
    },
    /// A refusal: stop the run.
    Fatal(String),
}

/// Sends one request for `pts` and judges the reply.
fn attempt_once(endpoint: &Endpoint, agent: &ureq::Agent, pts: &[[f64; 2]]) -> Attempt {
    let retry = |why: String| Attempt::Retry {
        why,
        retry_after: None,
    };
    match endpoint.send(agent, pts).map_err(|e| *e) {
        Ok(resp) => match resp.into_string() {
            Ok(body) => match endpoint.parse_reply(&body, pts) {
                Ok(z) => Attempt::Done(z),
                Err(Reply::Retry(m)) => retry(m),
                Err(Reply::Fatal(m)) => Attempt::Fatal(m),
            },
            Err(e) => retry(format!("reply cut short ({})", e.kind())),
        },
        Err(ureq::Error::Status(code, resp)) => {
            let retry_after = resp
                .header("Retry-After")
                .and_then(|v| v.trim().parse::<f64>().ok())
                .filter(|v| v.is_finite() && *v >= 0.0);
            if code == 429 || code >= 500 {
                return Attempt::Retry {
                    why: format!("HTTP {code}"),
                    retry_after,
                };
            }
            let body: String = resp
                .into_string()
                .unwrap_or_default()
                .chars()
                .take(200)
                .collect();
            Attempt::Fatal(
                endpoint.redact(&format!("HTTP {code} from {}: {body}", endpoint.base_url)),
            )
        }
        Err(ureq::Error::Transport(t)) => retry(endpoint.redact(&t.to_string())),
    }
}

/// A batch's index and its elevations (or why it has none).
type BatchOutcome = (usize, Result<Vec<Option<f64>>, PointError>);

/// Spaces requests `1/rate` seconds apart.
struct RateLimit {
    step: Option<Duration>,
    next: Mutex<Instant>,
}

impl RateLimit {
    fn wait(&self) {
        let Some(step) = self.step else { return };
        let slot = {
            let mut next = self.next.lock().unwrap_or_else(|e| e.into_inner());
            let now = Instant::now();
            let slot = (*next).max(now);
            *next = slot + step;
            slot
        };
        let now = Instant::now();
        if slot > now {
            std::thread::sleep(slot - now);
        }
    }
}

/// A small xorshift generator for backoff jitter (seeded per batch: deterministic runs).
fn jitter(seed: &mut u64) -> f64 {
    *seed ^= *seed << 13;
    *seed ^= *seed >> 7;
    *seed ^= *seed << 17;
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

/// Fetches the elevation of every `[lat, lon]` point, in order: each gets `Ok(z)` or an
/// explicit [`PointError`]; nothing is dropped, duplicated or reordered. Points already in
/// the journal (with `resume`) or the cache are not asked again; repeated points are asked
/// once. `progress(done, total)` is called as points complete; setting `cancel` stops
/// sending new requests (pending points get [`PointError::Cancelled`]).
///
/// Fails as a whole only when the service refuses the requests (bad key, invalid request) or
/// a store cannot be written.
///
/// ```no_run
/// # fn main() -> Result<(), terramesh_web::WebError> {
/// use std::sync::atomic::AtomicBool;
/// use terramesh_web::{fetch, Endpoint, FetchOptions};
/// let e = Endpoint::parse("opentopodata:srtm90m", None)?;
/// let (z, stats) = fetch(&e, &[[48.7242, 7.3386]], &FetchOptions::default(), &|_, _| {}, &AtomicBool::new(false))?;
/// println!("{:?} after {} requests", z[0], stats.requests);
/// # Ok(()) }
/// ```
pub fn fetch(
    endpoint: &Endpoint,
    points: &[[f64; 2]],
    opts: &FetchOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &AtomicBool,
) -> Result<(Vec<Result<f64, PointError>>, FetchStats), WebError> {
    for (i, p) in points.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite() && p[0].abs() <= 90.0 && p[1].abs() <= 180.0) {
            return Err(WebError::Config(format!(
                "point {} ({}, {}) is not a latitude/longitude",
                i + 1,
                p[0],
                p[1]
            )));
        }
    }
    let journal = match &opts.journal {
        Some(p) => Some(PointStore::open(p, opts.resume)?),
        None => None,
    };
    let cache = match &opts.cache {
        Some(p) => Some(PointStore::open(p, true)?),
        None => None,
    };
    let mut stats = FetchStats::default();
    // Answers by location; the unique locations still to ask, in first-seen order.
    let mut answers: HashMap<Key, Result<Option<f64>, PointError>> = HashMap::new();
    let mut todo: Vec<[f64; 2]> = Vec::new();
    let mut from_cache: Vec<([f64; 2], Option<f64>)> = Vec::new();
    for &p in points {
        let k = key(p);
        if answers.contains_key(&k) {
            continue;
        }
        let known = journal.as_ref().and_then(|j| j.get(p));
        let cached = || cache.as_ref().and_then(|c| c.get(p));
        if let Some(z) = known {
            answers.insert(k, Ok(z));
        } else if let Some(z) = cached() {
            answers.insert(k, Ok(z));
            from_cache.push((p, z));
        } else {
            answers.insert(k, Err(PointError::Cancelled));
            todo.push(p);
        }
    }
    if let Some(j) = &journal {
        j.append(&from_cache)?;
    }
    let todo_keys: std::collections::HashSet<Key> = todo.iter().map(|p| key(*p)).collect();
    let total = points.len();
    stats.from_store = points
        .iter()
        .filter(|p| !todo_keys.contains(&key(**p)))
        .count();
    let done_points = AtomicUsize::new(stats.from_store);
    progress(stats.from_store, total);
    let batch = opts
        .batch
        .unwrap_or(endpoint.max_batch())
        .clamp(1, endpoint.max_batch());
    let batches: Vec<&[[f64; 2]]> = todo.chunks(batch).collect();
    let agent = ureq::AgentBuilder::new()
        .timeout_connect(opts.timeout)
        .timeout(opts.timeout)
        .user_agent(concat!("terramesh/", env!("CARGO_PKG_VERSION")))
        .build();
    let rate = RateLimit {
        step: opts
            .rate
            .filter(|r| *r > 0.0)
            .map(|r| Duration::from_secs_f64(1.0 / r)),
        next: Mutex::new(Instant::now()),
    };
    // Multiplicity of each unique location, for progress in points.
    let mut mult: HashMap<Key, usize> = HashMap::new();
    for p in points {
        *mult.entry(key(*p)).or_default() += 1;
    }
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<BatchOutcome>> = Mutex::new(Vec::new());
    let fatal: Mutex<Option<WebError>> = Mutex::new(None);
    let requests = AtomicUsize::new(0);
    let retries = AtomicUsize::new(0);
    let stop =
        || cancel.load(Ordering::Relaxed) || fatal.lock().map(|f| f.is_some()).unwrap_or(true);
    std::thread::scope(|s| {
        for _ in 0..opts.concurrency.max(1).min(batches.len().max(1)) {
            s.spawn(|| loop {
                if stop() {
                    return;
                }
                let b = next.fetch_add(1, Ordering::Relaxed);
                let Some(pts) = batches.get(b) else { return };
                let mut seed =
                    0x9E37_79B9_7F4A_7C15u64 ^ (b as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03);
                let mut last = String::new();
                let mut outcome = None;
                for attempt in 0..=opts.retries {
                    if attempt > 0 {
                        retries.fetch_add(1, Ordering::Relaxed);
                    }
                    rate.wait();
                    requests.fetch_add(1, Ordering::Relaxed);
                    let retry_after = match attempt_once(endpoint, &agent, pts) {
                        Attempt::Done(z) => {
                            outcome = Some(Ok(z));
                            break;
                        }
                        Attempt::Retry { why, retry_after } => {
                            last = why;
                            retry_after
                        }
                        Attempt::Fatal(m) => {
                            *fatal.lock().unwrap_or_else(|e| e.into_inner()) =
                                Some(WebError::Refused(m));
                            return;
                        }
                    };
                    if attempt == opts.retries || stop() {
                        break;
                    }
                    let cap = opts
                        .backoff
                        .saturating_mul(1u32 << attempt.min(20))
                        .min(opts.backoff_max);
                    let mut wait = cap.mul_f64(jitter(&mut seed));
                    if let Some(ra) = retry_after {
                        wait = wait.max(Duration::from_secs_f64(ra).min(opts.backoff_max));
                    }
                    std::thread::sleep(wait);
                }
                let outcome = outcome.unwrap_or_else(|| {
                    Err(if stop() && last.is_empty() {
                        PointError::Cancelled
                    } else {
                        PointError::Failed {
                            attempts: opts.retries + 1,
                            last: last.clone(),
                        }
                    })
                });
                if let Ok(z) = &outcome {
                    let answered: Vec<([f64; 2], Option<f64>)> =
                        pts.iter().copied().zip(z.iter().copied()).collect();
                    let stored = journal
                        .as_ref()
                        .map_or(Ok(()), |j| j.append(&answered))
                        .and_then(|_| cache.as_ref().map_or(Ok(()), |c| c.append(&answered)));
                    if let Err(e) = stored {
                        *fatal.lock().unwrap_or_else(|e| e.into_inner()) = Some(e);
                        return;
                    }
                }
                let n: usize = pts.iter().map(|p| mult[&key(*p)]).sum();
                let done = done_points.fetch_add(n, Ordering::Relaxed) + n;
                progress(done, total);
                results
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push((b, outcome));
            });
        }
    });
    if let Some(e) = fatal.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    for (b, outcome) in results.into_inner().unwrap_or_else(|e| e.into_inner()) {
        match outcome {
            Ok(z) => {
                stats.fetched += batches[b].len();
                for (p, z) in batches[b].iter().zip(z) {
                    answers.insert(key(*p), Ok(z));
                }
            }
            Err(e) => {
                for p in batches[b] {
                    answers.insert(key(*p), Err(e.clone()));
                }
            }
        }
    }
    stats.requests = requests.into_inner();
    stats.retries = retries.into_inner();
    let out = points
        .iter()
        .map(|p| match &answers[&key(*p)] {
            Ok(Some(z)) => Ok(*z),
            Ok(None) => Err(PointError::NoData),
            Err(e) => Err(e.clone()),
        })
        .collect();
    Ok((out, stats))
}
