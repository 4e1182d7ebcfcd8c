#include "capture/v4l2_io.h"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace bouncefit {
namespace {

class SystemIo final : public V4l2Io {
 public:
  int Open(const std::string& path, int flags) override { return ::open(path.c_str(), flags); }
  int Close(int fd) override { return ::close(fd); }
  int Ioctl(int fd, unsigned long request, void* arg) override {
    int r;
    do {
      r = ::ioctl(fd, request, arg);
    } while (r == -1 && errno == EINTR);
    return r;
  }
  void* Mmap(std::size_t length, int prot, int flags, int fd, off_t offset) override {
    return ::mmap(nullptr, length, prot, flags, fd, offset);
  }
  int Munmap(void* addr, std::size_t length) override { return ::munmap(addr, length); }
  int Poll(pollfd* fds, nfds_t count, int timeout_ms) override {
    return ::poll(fds, count, timeout_ms);
  }
  ssize_t Read(int fd, void* buffer, std::size_t size) override {
    return ::read(fd, buffer, size);
  }
  std::vector<std::string> DevicePaths() override {
    std::vector<std::pair<int, std::string>> found;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("video", 0) != 0 || name.size() == 5) continue;
      const std::string digits = name.substr(5);
      if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
        continue;
      found.emplace_back(std::stoi(digits), entry.path().string());
    }
    std::sort(found.begin(), found.end());
    std::vector<std::string> paths;
    for (auto& f : found) paths.push_back(f.second);
    return paths;
  }
};

}  // namespace

V4l2Io& SystemV4l2Io() {
  static SystemIo io;
  return io;
}

std::string V4l2ErrnoText(int err) {
  if (err == ENODEV) return "No such device (ENODEV)";
  if (err == EAGAIN) return "Resource temporarily unavailable (EAGAIN)";
  return std::strerror(err);
}

}  // namespace bouncefit
