// Process-wide settings that every monomap program (the `monomap` binary,
// the benchmarks) applies once at start, so that all of them measure and
// run the same way.
#pragma once

namespace monomap {

struct RuntimeReport {
  // glibc accepted the allocator settings (false on other C libraries).
  bool allocator_tuned = false;
};

// - One OpenCV thread: parallelism comes from oneTBB. OpenCV's own pool,
//   called from inside TBB tasks, oversubscribes the cores and its idle
//   workers spin.
// - The allocator keeps freed memory for reuse instead of returning it to
//   the kernel. Image pipelines allocate and free buffers of a few hundred
//   kilobytes to a few megabytes per frame (pyramids, gradients, corner
//   maps inside OpenCV); with glibc's defaults each of them is a fresh
//   mmap whose pages fault in again, which cost a quarter of the tracking
//   time on desk_vamr_a (1.9 million page faults for 300 frames).
// Call before any other thread starts.
RuntimeReport ConfigureRuntime();

}  // namespace monomap
