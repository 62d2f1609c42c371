#pragma once
// Process-wide settings for programs built on sdfkit (the sdfkit CLI and benchmarks call it
// first thing in main). The library never calls it by itself: an embedding tool decides.

namespace sdfkit {

// Keeps up to 64 MiB of freed heap in the process instead of handing it back to the kernel
// (glibc's M_TRIM_THRESHOLD; a no-op on other C libraries). Software rasterizers (lavapipe)
// allocate and free their binned scene, megabytes, for every render pass; with glibc's default
// (128 KiB, adaptive) the freed pages went back to the kernel and were faulted in again on the
// next pass: 181k page faults in a 128-view call on bunny00, 33k with this setting, 10-15 % less
// CPU time. Returns false when the C library refused.
bool keep_freed_heap();

}  // namespace sdfkit
