//! Throughput of the OpenTopoData client against the mock server at 50 ms latency:
//! 100,000 points in batches of 100 with 8 concurrent requests. The batches need
//! 1000 / 8 x 50 ms = 6.25 s; the sum of their latencies is 50 s.
//!
//! cargo bench -p terramesh-web --bench mock_throughput
//! (one timed run per setting: the run is long, so criterion's repetitions are not used)

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use terramesh_web::mock::{Fault, MockServer};
use terramesh_web::{fetch, Endpoint, FetchOptions, ServiceKind};

fn main() {
    let latency = Duration::from_millis(50);
    let n = 100_000;
    let pts: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            [
                48.0 + (i / 1000) as f64 * 1e-3,
                7.0 + (i % 1000) as f64 * 1e-3,
            ]
        })
        .collect();
    for concurrency in [8, 16] {
        let s = MockServer::start(
            ServiceKind::OpenTopoData,
            latency,
            |_, _| Fault::None,
            Default::default(),
        );
        let e = Endpoint::parse(&format!("opentopodata:{}/v1/bench", s.url()), None).unwrap();
        let opts = FetchOptions {
            concurrency,
            ..FetchOptions::default()
        };
        let t = Instant::now();
        let (z, stats) = fetch(&e, &pts, &opts, &|_, _| {}, &AtomicBool::new(false)).unwrap();
        let took = t.elapsed().as_secs_f64();
        assert!(z.iter().all(|z| z.is_ok()));
        let batches = stats.requests as f64;
        let ideal = (batches / concurrency as f64).ceil() * latency.as_secs_f64();
        println!(
            "opentopodata {n} points, {} requests, concurrency {concurrency}, latency 50 ms: \
             {took:.2} s (batches need {ideal:.2} s; sum of latencies {:.1} s)",
            stats.requests,
            batches * latency.as_secs_f64()
        );
    }
}
