//! What the geostat examples share (not an example itself: Cargo builds only `examples/*.rs`
//! and `examples/*/main.rs`).

/// CPU seconds (user + system) of this process so far, from /proc/self/stat (Linux; 0 elsewhere).
pub fn cpu() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let f: Vec<&str> = s
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let t = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (t(11) + t(12)) / 100.0
}
