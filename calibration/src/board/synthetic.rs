//! Synthetic board presses for the tests.
