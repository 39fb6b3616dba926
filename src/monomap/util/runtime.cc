#include "monomap/util/runtime.h"

#include <opencv2/core/utility.hpp>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace monomap {

RuntimeReport ConfigureRuntime() {
  RuntimeReport report;
  cv::setNumThreads(1);
#if defined(__GLIBC__)
  // Serve blocks up to 32 MB (glibc's largest mmap threshold) from the heap
  // and only give back more than 256 MB of free heap top; grow the heap in
  // 16 MB steps. Peak memory is unchanged, freed buffers are simply reused.
  constexpr int kMiB = 1 << 20;
  report.allocator_tuned = mallopt(M_MMAP_THRESHOLD, 32 * kMiB) == 1 &&
                           mallopt(M_TRIM_THRESHOLD, 256 * kMiB) == 1 &&
                           mallopt(M_TOP_PAD, 16 * kMiB) == 1;
#endif
  return report;
}

}  // namespace monomap
