//! A fault-injecting mock elevation server on 127.0.0.1, for tests and benchmarks.
//!
//! It answers the three services' protocols with [`elevation_at`], after a fixed latency, and
//! injects the fault that a callback chooses for each request: slow replies, HTTP errors with
//! `Retry-After`, dropped connections, cut or truncated replies, results of the wrong length.

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use crate::ServiceKind;

/// The mock terrain: a smooth surface, no data north of 89 N.
///
/// ```
/// assert_eq!(terramesh_web::mock::elevation_at(89.5, 0.0), None);
/// assert!(terramesh_web::mock::elevation_at(48.7, 7.3).is_some());
/// ```
pub fn elevation_at(lat: f64, lon: f64) -> Option<f64> {
    (lat < 89.0).then(|| {
        let z = 300.0 + 1000.0 * (lat.to_radians() * 7.0).sin() * (lon.to_radians() * 5.0).cos();
        (z * 100.0).round() / 100.0
    })
}

/// What the server does with one request.
#[derive(Debug, Clone, PartialEq)]
pub enum Fault {
    /// A correct reply.
    None,
    /// A correct reply after an extra delay.
    Slow(Duration),
    /// An HTTP error status, with an optional `Retry-After` in seconds.
    Status(u16, Option<u32>),
    /// Close the connection without replying.
    Drop,
    /// Announce the full length, send half the body, close.
    CutReply,
    /// A complete HTTP reply whose JSON is cut in the middle.
    TruncatedJson,
    /// A well-formed reply with one result too few.
    WrongLength,
    /// A well-formed reply whose results are in reverse order.
    Reordered,
    /// Stall until the client gives up.
    Hang,
}

/// A request the server received.
#[derive(Debug, Clone)]
pub struct Request {
    /// `GET` or `POST`.
    pub method: String,
    /// Path without the query.
    pub path: String,
    /// Locations asked, `[lat, lon]`, as the server read them.
    pub locations: Vec<[f64; 2]>,
    /// The raw query string.
    pub query: String,
    /// When the request arrived.
    pub at: std::time::Instant,
}

type FaultFn = dyn Fn(usize, &Request) -> Fault + Send + Sync;

/// A running mock server; stopped when dropped.
pub struct MockServer {
    addr: std::net::SocketAddr,
    stop: Arc<AtomicBool>,
    log: Arc<Mutex<Vec<Request>>>,
    gauge: Arc<[AtomicUsize; 2]>,
    accept: Option<JoinHandle<()>>,
}

impl MockServer {
    /// Starts a server speaking `kind`'s protocol with `latency` per reply; `faults(i, req)`
    /// picks the fault for the `i`-th request (0-based). `files` maps paths (e.g.
    /// `/tiles/11/385/803.png`) to bytes served as they are; other paths get 404.
    ///
    /// ```
    /// use std::time::Duration;
    /// use terramesh_web::mock::{Fault, MockServer};
    /// let s = MockServer::start(terramesh_web::ServiceKind::OpenTopoData, Duration::ZERO,
    ///     |_, _| Fault::None, Default::default());
    /// assert!(s.url().starts_with("http://127.0.0.1:"));
    /// ```
    pub fn start(
        kind: ServiceKind,
        latency: Duration,
        faults: impl Fn(usize, &Request) -> Fault + Send + Sync + 'static,
        files: HashMap<String, Vec<u8>>,
    ) -> MockServer {
        let listener = TcpListener::bind("127.0.0.1:0").expect("bind 127.0.0.1");
        let addr = listener.local_addr().expect("local address");
        let stop = Arc::new(AtomicBool::new(false));
        let log = Arc::new(Mutex::new(Vec::new()));
        let faults: Arc<FaultFn> = Arc::new(faults);
        let files = Arc::new(files);
        let counter = Arc::new(AtomicUsize::new(0));
        let gauge: Arc<[AtomicUsize; 2]> = Arc::new([AtomicUsize::new(0), AtomicUsize::new(0)]);
        let (stop2, log2, gauge2) = (stop.clone(), log.clone(), gauge.clone());
        let accept = std::thread::spawn(move || {
            for conn in listener.incoming() {
                if stop2.load(Ordering::Relaxed) {
                    return;
                }
                let Ok(conn) = conn else { continue };
                let (log, faults, files, counter, stop, gauge) = (
                    log2.clone(),
                    faults.clone(),
                    files.clone(),
                    counter.clone(),
                    stop2.clone(),
                    gauge2.clone(),
                );
                std::thread::spawn(move || {
                    serve(
                        conn, kind, latency, &*faults, &files, &counter, &log, &stop, &gauge,
                    )
                });
            }
        });
        MockServer {
            addr,
            stop,
            log,
            gauge,
            accept: Some(accept),
        }
    }

    /// `http://127.0.0.1:PORT`.
    pub fn url(&self) -> String {
        format!("http://{}", self.addr)
    }

    /// The most requests waiting out their latency at the same time (the replies are sent
    /// after it, so a client's concurrency bounds this).
    pub fn max_in_flight(&self) -> usize {
        self.gauge[1].load(Ordering::SeqCst)
    }

    /// The requests received so far.
    pub fn requests(&self) -> Vec<Request> {
        self.log.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

impl Drop for MockServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        let _ = TcpStream::connect(self.addr);
        if let Some(h) = self.accept.take() {
            let _ = h.join();
        }
    }
}

fn decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let Ok(v) = u8::from_str_radix(&s[i + 1..i + 3], 16) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(if b[i] == b'+' { b' ' } else { b[i] });
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn parse_locations(query: &str, body: &str) -> Vec<[f64; 2]> {
    if let Some(l) = query
        .split('&')
        .find_map(|kv| kv.strip_prefix("locations="))
    {
        return decode(l)
            .split('|')
            .filter_map(|p| {
                let (a, b) = p.split_once(',')?;
                Some([a.trim().parse().ok()?, b.trim().parse().ok()?])
            })
            .collect();
    }
    let v: serde_json::Value = serde_json::from_str(body).unwrap_or_default();
    v.get("locations")
        .and_then(|l| l.as_array())
        .map(|a| {
            a.iter()
                .filter_map(|p| Some([p.get("latitude")?.as_f64()?, p.get("longitude")?.as_f64()?]))
                .collect()
        })
        .unwrap_or_default()
}

fn reply_body(kind: ServiceKind, locs: &[[f64; 2]]) -> String {
    let items: Vec<String> = locs
        .iter()
        .map(|&[lat, lon]| {
            let z = elevation_at(lat, lon).map_or("null".to_string(), |z| z.to_string());
            match kind {
                ServiceKind::OpenElevation => {
                    format!("{{\"latitude\":{lat},\"longitude\":{lon},\"elevation\":{z}}}")
                }
                _ => format!(
                    "{{\"elevation\":{z},\"location\":{{\"lat\":{lat},\"lng\":{lon}}},\"resolution\":30.0}}"
                ),
            }
        })
        .collect();
    match kind {
        ServiceKind::OpenElevation => format!("{{\"results\":[{}]}}", items.join(",")),
        _ => format!("{{\"results\":[{}],\"status\":\"OK\"}}", items.join(",")),
    }
}

#[allow(clippy::too_many_arguments)]
fn serve(
    mut conn: TcpStream,
    kind: ServiceKind,
    latency: Duration,
    faults: &FaultFn,
    files: &HashMap<String, Vec<u8>>,
    counter: &AtomicUsize,
    log: &Mutex<Vec<Request>>,
    stop: &AtomicBool,
    gauge: &[AtomicUsize; 2],
) {
    let _ = conn.set_read_timeout(Some(Duration::from_secs(10)));
    let mut reader = BufReader::new(match conn.try_clone() {
        Ok(c) => c,
        Err(_) => return,
    });
    let mut line = String::new();
    if reader.read_line(&mut line).unwrap_or(0) == 0 || stop.load(Ordering::Relaxed) {
        return;
    }
    let mut parts = line.split_whitespace();
    let method = parts.next().unwrap_or("").to_string();
    let target = parts.next().unwrap_or("").to_string();
    let mut length = 0usize;
    loop {
        let mut h = String::new();
        if reader.read_line(&mut h).unwrap_or(0) == 0 || h == "\r\n" || h == "\n" {
            break;
        }
        if let Some((k, v)) = h.split_once(':') {
            if k.eq_ignore_ascii_case("content-length") {
                length = v.trim().parse().unwrap_or(0);
            }
        }
    }
    let mut body = vec![0; length];
    if reader.read_exact(&mut body).is_err() {
        return;
    }
    let body = String::from_utf8_lossy(&body).into_owned();
    let (path, query) = target.split_once('?').unwrap_or((&target, ""));
    let req = Request {
        method,
        path: path.to_string(),
        locations: parse_locations(query, &body),
        query: query.to_string(),
        at: std::time::Instant::now(),
    };
    let i = counter.fetch_add(1, Ordering::SeqCst);
    log.lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(req.clone());
    let fault = faults(i, &req);
    // Requests waiting out their latency at once: a client's concurrency bounds it.
    let now = gauge[0].fetch_add(1, Ordering::SeqCst) + 1;
    gauge[1].fetch_max(now, Ordering::SeqCst);
    std::thread::sleep(latency);
    gauge[0].fetch_sub(1, Ordering::SeqCst);
    let send = |conn: &mut TcpStream, status: &str, extra: &str, ctype: &str, body: &[u8]| {
        let head = format!(
            "HTTP/1.1 {status}\r\nContent-Type: {ctype}\r\nContent-Length: {}\r\n{extra}Connection: close\r\n\r\n",
            body.len()
        );
        let _ = conn.write_all(head.as_bytes());
        let _ = conn.write_all(body);
        let _ = conn.flush();
    };
    if let Some(bytes) = files.get(path) {
        send(&mut conn, "200 OK", "", "image/png", bytes);
        return;
    }
    if !files.is_empty() && req.locations.is_empty() {
        send(
            &mut conn,
            "404 Not Found",
            "",
            "text/plain",
            b"no such tile",
        );
        return;
    }
    let mut locs = req.locations.clone();
    match fault {
        Fault::None => {}
        Fault::Slow(d) => std::thread::sleep(d),
        Fault::Status(code, ra) => {
            let extra = ra.map_or(String::new(), |s| format!("Retry-After: {s}\r\n"));
            let status = format!("{code} Injected");
            send(
                &mut conn,
                &status,
                &extra,
                "application/json",
                b"{\"error\":\"injected\"}",
            );
            return;
        }
        Fault::Drop => {
            let _ = conn.shutdown(Shutdown::Both);
            return;
        }
        Fault::Hang => {
            std::thread::sleep(Duration::from_secs(5));
            return;
        }
        Fault::CutReply => {
            let b = reply_body(kind, &locs);
            let head = format!(
                "HTTP/1.1 200 OK\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
                b.len()
            );
            let _ = conn.write_all(head.as_bytes());
            let _ = conn.write_all(&b.as_bytes()[..b.len() / 2]);
            let _ = conn.shutdown(Shutdown::Both);
            return;
        }
        Fault::TruncatedJson => {
            let b = reply_body(kind, &locs);
            send(
                &mut conn,
                "200 OK",
                "",
                "application/json",
                &b.as_bytes()[..b.len() / 2],
            );
            return;
        }
        Fault::WrongLength => {
            locs.pop();
        }
        Fault::Reordered => locs.reverse(),
    }
    let b = reply_body(kind, &locs);
    send(&mut conn, "200 OK", "", "application/json", b.as_bytes());
}
