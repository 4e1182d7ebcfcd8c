#include "capture/frame_memory.h"

#include <malloc.h>

namespace bouncefit {

void KeepFreedFrameMemory() {
  // Blocks up to 32 MiB (a 4K BGR frame is 25 MiB) from the heap, not mmap: an mmapped block
  // is unmapped at free. And the heap's top is given back only past 512 MiB free: the peak a
  // run reaches (17 frames of history at 1080p, about 100 MiB) is reused, not re-faulted.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
}

}  // namespace bouncefit
