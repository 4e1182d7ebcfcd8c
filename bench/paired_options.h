#pragma once
// Options of the benches that read them in pairs (--name value, every option takes one): the
// usage, and the words that end the parse before any work is done.
#include <cstdio>
#include <cstring>
#include <optional>

namespace bouncefit::bench {

// Prints the usage (a printf format with one %s, the program's name) and gives the exit code:
// on stdout and 0 when it was asked for, on stderr and 2 after a mistake.
inline int PrintUsage(const char* format, const char* program, bool asked) {
  std::fprintf(asked ? stdout : stderr, format, program);
  return asked ? 0 : 2;
}

// Whether argv[i] ends the parse: --help or -h, or a last option without its value (read in
// pairs, it would be skipped and the whole bench run). The exit code, the usage printed.
inline std::optional<int> HelpOrMissingValue(int argc, char** argv, int i, const char* usage) {
  const bool help = !std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h");
  if (!help && i + 1 < argc) return std::nullopt;
  return PrintUsage(usage, argv[0], help);
}

}  // namespace bouncefit::bench
