#pragma once
// Helpers shared by the tests: paths, a scratch directory, running the CLI.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace bouncefit {
struct BallPreset;
}

namespace bouncefit::testing {

// A fresh, empty directory under the build tree for this test case
// (scratch/<Suite.Test>/<name>); kept after the test for inspection, wiped when the same
// test asks for it again.
std::filesystem::path ScratchDir(const std::string& name);

// Runs a shell command line, captures stdout+stderr into *output; returns the exit status
// (128+signal if killed by a signal).
int RunCommand(const std::string& command_line, std::string* output);

// The bouncefit executable under test, quoted for a shell.
std::string BouncefitExe();

// A 1.5 s synth drop at 120 fps, 320x240, from 0.5 m (`bouncefit synth`), rendered once into
// the build tree and reused by every test that asks (written under a temporary name, then
// renamed: ctest runs test cases in parallel).
std::string ShortDropClip();

// The drop height, then the first n apex heights of a point-mass ball dropped from it: a
// recording whose coefficients are known.
std::vector<double> DropHeights(const BallPreset& ball, double drop, int n);

// Directory of the shared real clips ("" when absent on this machine).
std::filesystem::path RealClipsDir();

// A UDP multicast URL with ttl=0 on a port unique to this process, so tests never collide.
std::string UniqueUdpmUrl();

// A whole file's bytes ("" when it cannot be read).
std::string ReadFile(const std::filesystem::path& path);

// A CSV file with a header line (a run's track.csv, peaks.csv, impacts.csv) as rows of
// column name -> cell; a cell a line lacks is "".
std::vector<std::map<std::string, std::string>> ReadCsv(const std::filesystem::path& path);

}  // namespace bouncefit::testing
