//! A profiling timer: with `TERRAMESH_PASS_STATS` set, each step's time since the previous
//! one on stderr; without it, nothing. One piece for the kernel's `check` and the facade's
//! geology stage, which time their steps the same way under different prefixes.

use std::cell::Cell;
use std::time::Instant;

/// Says each step's time since the previous one (or since [`Lap::new`]) as
/// `<prefix>: <step>: <seconds> s (cpu <seconds> s)`, only where `TERRAMESH_PASS_STATS` is
/// set; nothing else changes.
pub struct Lap {
    prefix: &'static str,
    last: Option<Cell<(Instant, f64)>>,
}

/// The process's CPU time so far (user + system, all threads), in seconds, from
/// `/proc/self/stat` (100 clock ticks a second); 0 where that cannot be read. For the
/// profiling lines only: on a shared machine the CPU time of a step says more than its wall
/// clock.
pub(crate) fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // The fields after the command's name (in parentheses, which may hold spaces): state is
    // the first, utime the 12th, stime the 13th.
    let Some(rest) = stat.rfind(')').map(|i| &stat[i + 1..]) else {
        return 0.0;
    };
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|x| x.parse().ok())
        .collect();
    f.iter().sum::<f64>() / 100.0
}

impl Lap {
    /// A timer whose lines start with `prefix`, started now.
    #[must_use]
    pub fn new(prefix: &'static str) -> Lap {
        Lap {
            prefix,
            last: std::env::var_os("TERRAMESH_PASS_STATS")
                .map(|_| Cell::new((Instant::now(), cpu_seconds()))),
        }
    }

    /// Says `what` took the time since the previous step, and starts the next.
    pub fn say(&self, what: &str) {
        if let Some(t) = &self.last {
            let (now, cpu) = (Instant::now(), cpu_seconds());
            let (then, cpu_then) = t.get();
            eprintln!(
                "{}: {what}: {:.2} s (cpu {:.2} s)",
                self.prefix,
                now.duration_since(then).as_secs_f64(),
                cpu - cpu_then
            );
            t.set((now, cpu));
        }
    }
}
