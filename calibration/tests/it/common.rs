//! Helpers shared by the calibration tests.

/// The seed set of the seeded tests (`FABKIT_TEST_SEED_SET`, 0 unless set; `.ci/run` cycles
/// 0, 1 and 2): their seeds start at `1000 x set`, so a bound must hold on every set.
pub fn seed_set() -> u64 {
    let set = std::env::var("FABKIT_TEST_SEED_SET").ok();
    set.and_then(|s| s.parse().ok()).unwrap_or(0)
}
