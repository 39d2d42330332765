//! `fabkit groundtruth` end to end (filled in below).
