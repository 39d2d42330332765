//! Hold points: where a test stops a fabkit process on purpose, to kill it at a known step
//! (an interrupted export or sweep must leave nothing half-written under a final name). A test
//! that killed after a delay depended on the machine's speed; a hold point does not.
//!
//! With `FABKIT_TEST_HOLD=<point>:<n>` in its environment, the process stops the `n`-th time it
//! reaches `point` ([`hold_point`]): it creates the file `FABKIT_TEST_HOLD_FILE` (when set)
//! and sleeps until it is killed. Without the variable (every user's run) a hold point is one
//! read of a cached environment value.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

/// The point and the count the environment asks to hold at, read once.
fn wanted() -> Option<&'static (String, usize)> {
    static WANTED: OnceLock<Option<(String, usize)>> = OnceLock::new();
    WANTED
        .get_or_init(|| {
            let spec = std::env::var("FABKIT_TEST_HOLD").ok()?;
            let (point, n) = spec.rsplit_once(':')?;
            Some((point.to_string(), n.parse().ok()?))
        })
        .as_ref()
}

/// Holds the process at `point` (see the module documentation); returns at once unless the
/// environment asks for this point and this is its `n`-th arrival.
pub fn hold_point(point: &str) {
    static ARRIVALS: AtomicUsize = AtomicUsize::new(0);
    let Some((p, n)) = wanted() else {
        return;
    };
    if p != point || ARRIVALS.fetch_add(1, Ordering::SeqCst) + 1 != *n {
        return;
    }
    if let Some(file) = std::env::var_os("FABKIT_TEST_HOLD_FILE") {
        let _ = std::fs::write(file, point);
    }
    loop {
        std::thread::sleep(std::time::Duration::from_secs(1));
    }
}
