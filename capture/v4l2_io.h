#pragma once
// The few system calls the V4L2 camera makes, behind a thin seam: the real kernel in
// production, a scripted fake device (tests/v4l2_fake_device.h) in tests. Every call has
// the system call's own contract: -1 (or MAP_FAILED) with errno set on failure.
#include <poll.h>
#include <sys/types.h>

#include <cstddef>
#include <string>
#include <vector>

namespace bouncefit {

class V4l2Io {
 public:
  virtual ~V4l2Io() = default;
  virtual int Open(const std::string& path, int flags) = 0;
  virtual int Close(int fd) = 0;
  virtual int Ioctl(int fd, unsigned long request, void* arg) = 0;
  virtual void* Mmap(std::size_t length, int prot, int flags, int fd, off_t offset) = 0;
  virtual int Munmap(void* addr, std::size_t length) = 0;
  virtual int Poll(pollfd* fds, nfds_t count, int timeout_ms) = 0;
  virtual ssize_t Read(int fd, void* buffer, std::size_t size) = 0;
  // Candidate device nodes (/dev/video*), sorted by number.
  virtual std::vector<std::string> DevicePaths() = 0;
};

// The real kernel. Ioctl retries on EINTR as v4l2 applications should.
V4l2Io& SystemV4l2Io();

// A failed call's errno as the camera's errors say it (ENODEV and EAGAIN by name).
std::string V4l2ErrnoText(int err);

}  // namespace bouncefit
