#include "report/report_gnuplot.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace bouncefit {

std::string FindGnuplot(const GnuplotOptions& options) {
  const std::string& exe = options.executable;
  if (exe.find('/') != std::string::npos) {
    return ::access(exe.c_str(), X_OK) == 0 ? exe : std::string();
  }
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = dir + "/" + exe;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return {};
}

void RunGnuplot(const std::filesystem::path& script, const GnuplotOptions& options) {
  const std::string exe = FindGnuplot(options);
  if (exe.empty()) {
    throw std::runtime_error("gnuplot not found ('" + options.executable +
                             "'); install the Debian package gnuplot-nox");
  }
  // Absolute: the child changes directory before it opens the log.
  const std::filesystem::path dir = std::filesystem::absolute(script).parent_path();
  const std::filesystem::path log = std::filesystem::absolute(script).string() + ".log";
  const std::string script_name = script.filename().string();

  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("cannot start gnuplot: fork failed");
  if (pid == 0) {
    // Child: only async-signal-safe calls until exec.
    if (::chdir(dir.c_str()) != 0) ::_exit(126);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, STDOUT_FILENO);
      ::dup2(fd, STDERR_FILENO);
      ::close(fd);
    }
    const int null_fd = ::open("/dev/null", O_RDONLY);
    if (null_fd >= 0) ::dup2(null_fd, STDIN_FILENO);
    ::execl(exe.c_str(), exe.c_str(), script_name.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }

  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<long>(options.timeout_s * 1000));
  int status = 0;
  for (;;) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0) throw std::runtime_error("lost the gnuplot child process");
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      throw std::runtime_error("gnuplot took longer than " + std::to_string(options.timeout_s) +
                               " s on " + script.string() + "; killed");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;

  // First meaningful line of gnuplot's complaint, for a one-line error.
  std::ifstream in(log);
  std::string line, reason;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t^") == std::string::npos) continue;
    reason = line;
    if (line.find("error") != std::string::npos || line.find("line") != std::string::npos) break;
  }
  if (reason.empty()) {
    reason = WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                               : "killed by signal " + std::to_string(WTERMSIG(status));
  }
  throw std::runtime_error("gnuplot failed on " + script.string() + ": " + reason);
}

}  // namespace bouncefit
