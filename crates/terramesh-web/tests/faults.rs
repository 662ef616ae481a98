//! The web client against the fault-injecting mock server on 127.0.0.1.

use std::collections::HashSet;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use terramesh_web::mock::{elevation_at, Fault, MockServer};
use terramesh_web::{fetch, Endpoint, FetchOptions, PointError, ServiceKind, WebError};

/// Fast timeouts and backoffs so that fault tests run in seconds.
fn quick() -> FetchOptions {
    FetchOptions {
        concurrency: 4,
        retries: 6,
        timeout: Duration::from_millis(400),
        backoff: Duration::from_millis(5),
        backoff_max: Duration::from_millis(1500),
        ..FetchOptions::default()
    }
}

/// `n` seeded pseudo-random points around the paper's study area.
fn points(n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n).map(|_| [48.0 + r(), 7.0 + r()]).collect()
}

/// What the server computes for a point sent with 7 decimals.
fn expected(p: [f64; 2]) -> f64 {
    let q = |v: f64| format!("{v:.7}").parse::<f64>().unwrap();
    elevation_at(q(p[0]), q(p[1])).unwrap()
}

fn endpoint(kind: ServiceKind, s: &MockServer) -> Endpoint {
    let spec = match kind {
        ServiceKind::Google => format!("google:{}/maps/api/elevation/json", s.url()),
        ServiceKind::OpenTopoData => format!("opentopodata:{}/v1/srtm30m", s.url()),
        ServiceKind::OpenElevation => format!("open-elevation:{}/api/v1/lookup", s.url()),
    };
    Endpoint::parse(&spec, Some("SECRET-KEY-123".into())).unwrap()
}

fn check_all(pts: &[[f64; 2]], z: &[Result<f64, PointError>]) {
    assert_eq!(z.len(), pts.len());
    for (p, z) in pts.iter().zip(z) {
        assert_eq!(*z, Ok(expected(*p)), "{p:?}");
    }
}

#[test]
fn every_service_batches_to_its_limit_and_keeps_order() {
    for (kind, limit) in [
        (ServiceKind::Google, 512),
        (ServiceKind::OpenTopoData, 100),
        (ServiceKind::OpenElevation, 200),
    ] {
        let s = MockServer::start(kind, Duration::ZERO, |_, _| Fault::None, Default::default());
        let pts = points(1234, 1);
        let stop = AtomicBool::new(false);
        let (z, stats) = fetch(&endpoint(kind, &s), &pts, &quick(), &|_, _| {}, &stop).unwrap();
        check_all(&pts, &z);
        let reqs = s.requests();
        assert_eq!(reqs.len(), 1234_usize.div_ceil(limit), "{kind:?}");
        assert!(reqs.iter().all(|r| r.locations.len() <= limit));
        assert_eq!(stats.fetched, 1234);
        // coordinates travel with 7 decimals: the server reads the point rounded to 1e-7
        let q = |v: f64| format!("{v:.7}").parse::<f64>().unwrap();
        let first = [q(pts[0][0]), q(pts[0][1])];
        assert!(reqs.iter().any(|r| r.locations.first() == Some(&first)));
        assert_ne!(
            q(pts[0][0]),
            format!("{:.6}", pts[0][0]).parse::<f64>().unwrap()
        );
        let q = &reqs[0].query;
        if kind == ServiceKind::Google {
            assert!(q.contains("key=SECRET-KEY-123"));
        }
    }
}

#[test]
fn every_fault_is_retried_and_nothing_is_lost() {
    let s = MockServer::start(
        ServiceKind::OpenTopoData,
        Duration::ZERO,
        |i, _| match i {
            0 => Fault::Status(500, None),
            1 => Fault::Status(429, Some(1)),
            2 => Fault::Drop,
            3 => Fault::CutReply,
            4 => Fault::TruncatedJson,
            5 => Fault::WrongLength,
            6 => Fault::Slow(Duration::from_millis(900)),
            7 => Fault::Reordered,
            8 => Fault::Hang,
            9 => Fault::Status(503, None),
            _ => Fault::None,
        },
        Default::default(),
    );
    let pts = points(1000, 2);
    let stop = AtomicBool::new(false);
    let opts = FetchOptions {
        concurrency: 1, // faults hit requests in a known order: all ten the first batch's
        retries: 12,
        ..quick()
    };
    let (z, stats) = fetch(
        &endpoint(ServiceKind::OpenTopoData, &s),
        &pts,
        &opts,
        &|_, _| {},
        &stop,
    )
    .unwrap();
    check_all(&pts, &z);
    assert_eq!(stats.retries, 10);
    assert_eq!(stats.requests, 20);
    // the 429 asked for Retry-After: 1 s; the retry came no sooner
    let r = s.requests();
    assert!(
        r[2].at - r[1].at >= Duration::from_millis(990),
        "{:?}",
        r[2].at - r[1].at
    );
}

#[test]
fn a_batch_that_always_fails_gets_explicit_errors() {
    let pts = points(500, 3);
    let bad = pts[250];
    let s = MockServer::start(
        ServiceKind::OpenTopoData,
        Duration::ZERO,
        move |_, r| {
            if r.locations.iter().any(|p| (p[0] - bad[0]).abs() < 1e-6) {
                Fault::Status(502, None)
            } else {
                Fault::None
            }
        },
        Default::default(),
    );
    let stop = AtomicBool::new(false);
    let opts = FetchOptions {
        retries: 2,
        ..quick()
    };
    let (z, _) = fetch(
        &endpoint(ServiceKind::OpenTopoData, &s),
        &pts,
        &opts,
        &|_, _| {},
        &stop,
    )
    .unwrap();
    let failed: Vec<usize> = (0..500).filter(|&i| z[i].is_err()).collect();
    assert_eq!(failed, (200..300).collect::<Vec<_>>());
    assert_eq!(
        z[250],
        Err(PointError::Failed {
            attempts: 3,
            last: "HTTP 502".into()
        })
    );
    for i in (0..500).filter(|i| !(200..300).contains(i)) {
        assert_eq!(z[i], Ok(expected(pts[i])));
    }
}

#[test]
fn refusal_stops_the_run_without_leaking_the_key() {
    let s = MockServer::start(
        ServiceKind::Google,
        Duration::ZERO,
        |_, _| Fault::Status(403, None),
        Default::default(),
    );
    let dir = tempfile::tempdir().unwrap();
    let opts = FetchOptions {
        cache: Some(dir.path().join("cache.txt")),
        ..quick()
    };
    let stop = AtomicBool::new(false);
    let e = fetch(
        &endpoint(ServiceKind::Google, &s),
        &points(10, 4),
        &opts,
        &|_, _| {},
        &stop,
    )
    .unwrap_err();
    assert!(matches!(e, WebError::Refused(_)), "{e}");
    let msg = format!("{e} {e:?}");
    assert!(
        msg.contains("403") && !msg.contains("SECRET-KEY-123"),
        "{msg}"
    );
    assert!(!format!("{:?}", endpoint(ServiceKind::Google, &s)).contains("SECRET"));
    assert!(!std::fs::read_to_string(dir.path().join("cache.txt"))
        .unwrap_or_default()
        .contains("SECRET"));
}

#[test]
fn connection_errors_name_the_url_without_the_key() {
    // A port with nothing listening: bind, note the port, close.
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let e = Endpoint::parse(
        &format!("google:http://127.0.0.1:{port}/elevation"),
        Some("SECRET-KEY-123".into()),
    )
    .unwrap();
    let opts = FetchOptions {
        retries: 1,
        ..quick()
    };
    let stop = AtomicBool::new(false);
    let (z, stats) = fetch(&e, &[[48.5, 7.5]], &opts, &|_, _| {}, &stop).unwrap();
    assert_eq!(stats.requests, 2);
    let Err(PointError::Failed { attempts: 2, last }) = &z[0] else {
        panic!("{:?}", z[0])
    };
    assert!(
        last.contains("127.0.0.1") && last.contains("<key>") && !last.contains("SECRET"),
        "{last}"
    );
}

#[test]
fn missing_data_is_an_explicit_error_and_duplicates_are_asked_once() {
    let s = MockServer::start(
        ServiceKind::OpenElevation,
        Duration::ZERO,
        |_, _| Fault::None,
        Default::default(),
    );
    let pts = vec![[48.5, 7.5], [89.5, 10.0], [48.5, 7.5], [48.6, 7.6]];
    let stop = AtomicBool::new(false);
    let (z, _) = fetch(
        &endpoint(ServiceKind::OpenElevation, &s),
        &pts,
        &quick(),
        &|_, _| {},
        &stop,
    )
    .unwrap();
    assert_eq!(z[1], Err(PointError::NoData));
    assert_eq!(z[0], z[2]);
    assert_eq!(z[3], Ok(expected(pts[3])));
    assert_eq!(s.requests()[0].locations.len(), 3);
}

#[test]
fn the_cache_answers_a_rerun_without_any_request() {
    let s = MockServer::start(
        ServiceKind::OpenTopoData,
        Duration::ZERO,
        |_, _| Fault::None,
        Default::default(),
    );
    let dir = tempfile::tempdir().unwrap();
    let opts = FetchOptions {
        cache: Some(dir.path().join("c.txt")),
        ..quick()
    };
    let pts = points(777, 5);
    let stop = AtomicBool::new(false);
    let e = endpoint(ServiceKind::OpenTopoData, &s);
    let (a, _) = fetch(&e, &pts, &opts, &|_, _| {}, &stop).unwrap();
    let n = s.requests().len();
    let (b, stats) = fetch(&e, &pts, &opts, &|_, _| {}, &stop).unwrap();
    assert_eq!(a, b);
    assert_eq!(s.requests().len(), n);
    assert_eq!((stats.requests, stats.from_store), (0, 777));
    let text = std::fs::read_to_string(dir.path().join("c.txt")).unwrap();
    assert_eq!(text.lines().count(), 777);
}

#[test]
fn an_interrupted_run_resumes_without_asking_twice() {
    let s = MockServer::start(
        ServiceKind::OpenTopoData,
        Duration::from_millis(5),
        |_, _| Fault::None,
        Default::default(),
    );
    let dir = tempfile::tempdir().unwrap();
    let opts = FetchOptions {
        journal: Some(dir.path().join("run.journal")),
        concurrency: 3,
        ..quick()
    };
    let pts = points(3000, 6);
    let e = endpoint(ServiceKind::OpenTopoData, &s);
    let stop = AtomicBool::new(false);
    // Interrupt once a third of the points are in.
    let (first, _) = fetch(
        &e,
        &pts,
        &opts,
        &|done, _| {
            if done >= 1000 {
                stop.store(true, Ordering::SeqCst);
            }
        },
        &stop,
    )
    .unwrap();
    let answered: HashSet<usize> = (0..pts.len()).filter(|&i| first[i].is_ok()).collect();
    assert!(
        answered.len() >= 1000 && answered.len() < 3000,
        "{}",
        answered.len()
    );
    assert!((0..pts.len()).all(|i| answered.contains(&i) || first[i] == Err(PointError::Cancelled)));
    let asked_first = s.requests().len();
    let go = AtomicBool::new(false);
    let (second, stats) = fetch(
        &e,
        &pts,
        &FetchOptions {
            resume: true,
            ..opts.clone()
        },
        &|_, _| {},
        &go,
    )
    .unwrap();
    check_all(&pts, &second);
    assert_eq!(stats.from_store, answered.len());
    // The resumed run asked only for the points the first did not get.
    let q = |v: f64| format!("{v:.7}").parse::<f64>().unwrap();
    let asked_again: Vec<[f64; 2]> = s.requests()[asked_first..]
        .iter()
        .flat_map(|r| r.locations.clone())
        .collect();
    assert_eq!(asked_again.len(), 3000 - answered.len());
    for i in &answered {
        let p = [q(pts[*i][0]), q(pts[*i][1])];
        assert!(!asked_again.contains(&p));
    }
    // Without --resume the journal starts afresh.
    let (_, fresh) = fetch(&e, &pts[..10], &opts, &|_, _| {}, &go).unwrap();
    assert_eq!(fresh.from_store, 0);
}

#[test]
fn concurrency_is_bounded_and_the_rate_is_limited() {
    let s = MockServer::start(
        ServiceKind::OpenTopoData,
        Duration::from_millis(40),
        |_, _| Fault::None,
        Default::default(),
    );
    let pts = points(2000, 7);
    let stop = AtomicBool::new(false);
    let e = endpoint(ServiceKind::OpenTopoData, &s);
    let (z, _) = fetch(
        &e,
        &pts,
        &FetchOptions {
            concurrency: 4,
            ..quick()
        },
        &|_, _| {},
        &stop,
    )
    .unwrap();
    check_all(&pts, &z);
    assert!(
        s.max_in_flight() <= 4 && s.max_in_flight() >= 2,
        "{}",
        s.max_in_flight()
    );

    let s = MockServer::start(
        ServiceKind::OpenTopoData,
        Duration::ZERO,
        |_, _| Fault::None,
        Default::default(),
    );
    let e = endpoint(ServiceKind::OpenTopoData, &s);
    let opts = FetchOptions {
        concurrency: 4,
        rate: Some(25.0),
        batch: Some(10),
        ..quick()
    };
    fetch(&e, &points(100, 8), &opts, &|_, _| {}, &stop).unwrap();
    let mut at: Vec<_> = s.requests().iter().map(|r| r.at).collect();
    at.sort();
    assert_eq!(at.len(), 10);
    // 10 requests at 25/s are spread over at least 9 x 40 ms (less a little clock slack)
    assert!(
        at[9] - at[0] >= Duration::from_millis(340),
        "{:?}",
        at[9] - at[0]
    );
}
