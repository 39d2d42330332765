fn main() {
    keep_freed_memory();
    std::process::exit(fabkit::cli::main());
}

/// Keeps the memory a command frees for its next allocations (glibc's malloc). A command
/// allocates and frees buffers of megabytes many times over (an image of 640 x 480 pixels
/// of three f64 channels is 7.4 MB, a pose's surface hits about as much), and glibc's defaults
/// give each one fresh pages from the kernel (mmap above a threshold that only grows after
/// such a buffer is freed, and the heap's top returned above twice that): the pages are
/// faulted in and zeroed every time. Buffers up to 32 MB (the highest threshold glibc
/// accepts) now come from the heap, which keeps up to 1 GB free rather than returning it and
/// grows 64 MB at a time. `calibrate photometric` on 30 captures spends half the system time
/// (1.29 -> 0.59 CPU-s) and 11 % less wall time (4.65 -> 4.12 s), its peak memory 2 % higher
/// (1144 -> 1164 MiB; docs/src/benchmarks.md, "The photometric fit"). Freed memory stays with
/// the process for its next allocations until it exits: the process keeps about its peak, it
/// does not grow with the number of allocations. Nothing changes where the user has set
/// glibc's own settings (`GLIBC_TUNABLES` or a `MALLOC_*_` variable), nor on other platforms.
fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        let user_set = std::env::vars_os().any(|(k, _)| {
            let k = k.to_string_lossy();
            k == "GLIBC_TUNABLES" || (k.starts_with("MALLOC_") && k.ends_with('_'))
        });
        if !user_set {
            // SAFETY: mallopt only sets the allocator's parameters; it is called before any
            // other thread exists. A value glibc refuses leaves its default (return 0).
            unsafe {
                libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
                libc::mallopt(libc::M_TRIM_THRESHOLD, 1 << 30);
                libc::mallopt(libc::M_TOP_PAD, 64 << 20);
            }
        }
    }
}
