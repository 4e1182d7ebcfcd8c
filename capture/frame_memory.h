#pragma once
// Video frames are megabytes each, allocated and freed every frame (decoder output, a turned
// copy, the tracker's work images). glibc hands freed blocks of that size back to the system
// (heap trimming above twice the largest block seen, mmap for new large blocks), so the next
// frame's buffers fault in every page again: on 1034x864 footage 1729 faults a frame, which
// slowed decoding by half beside the tracker (docs/PERFORMANCE.md, "Page faults"). Call once at
// the start of a program that decodes or tracks frames: freed blocks stay in the heap.
namespace bouncefit {

void KeepFreedFrameMemory();

}  // namespace bouncefit
