//! A profiling timer: with `TERRAMESH_PASS_STATS` set, each step's time since the previous
//! one on stderr; without it, nothing. One piece for the kernel's `check` and the facade's
//! geology stage, which time their steps the same way under different prefixes.

use std::cell::Cell;
use std::time::Instant;

/// Says each step's time since the previous one (or since [`Lap::new`]) as
/// `<prefix>: <step>: <seconds> s`, only where `TERRAMESH_PASS_STATS` is set; nothing else
/// changes.
pub struct Lap {
    prefix: &'static str,
    last: Option<Cell<Instant>>,
}

impl Lap {
    /// A timer whose lines start with `prefix`, started now.
    #[must_use]
    pub fn new(prefix: &'static str) -> Lap {
        Lap {
            prefix,
            last: std::env::var_os("TERRAMESH_PASS_STATS").map(|_| Cell::new(Instant::now())),
        }
    }

    /// Says `what` took the time since the previous step, and starts the next.
    pub fn say(&self, what: &str) {
        if let Some(t) = &self.last {
            let now = Instant::now();
            eprintln!(
                "{}: {what}: {:.2} s",
                self.prefix,
                now.duration_since(t.get()).as_secs_f64()
            );
            t.set(now);
        }
    }
}
