#pragma once
// Runs gnuplot (Debian gnuplot-nox) as a child process on a script file, with a timeout.
#include <filesystem>
#include <string>

namespace bouncefit {

struct GnuplotOptions {
  std::string executable = "gnuplot";  // looked up on PATH unless it contains a '/'
  double timeout_s = 30;               // a plot taking longer is killed and reported
};

// The full path of the gnuplot executable, or "" when it cannot be found.
std::string FindGnuplot(const GnuplotOptions& options);

// Runs `gnuplot script` with the script's folder as working directory. Throws
// std::runtime_error with one line (gnuplot's first error line, or the timeout, or
// "gnuplot not found") on failure.
void RunGnuplot(const std::filesystem::path& script, const GnuplotOptions& options);

}  // namespace bouncefit
