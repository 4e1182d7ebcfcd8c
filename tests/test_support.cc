#include "tests/test_support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "model/point_mass_drop.h"

namespace bouncefit::testing {

std::filesystem::path ScratchDir(const std::string& name) {
  // ctest runs each test case as a process of its own, in parallel: keying the directory by
  // the running test keeps two cases from wiping each other's files.
  std::string owner = "no-test";
  if (const auto* info = ::testing::UnitTest::GetInstance()->current_test_info())
    owner = std::string(info->test_suite_name()) + "." + info->name();
  for (char& ch : owner)
    if (ch == '/' || ch == '"') ch = '_';
  auto dir = std::filesystem::current_path() / "scratch" / owner / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

int RunCommand(const std::string& command_line, std::string* output) {
  const std::string full = command_line + " 2>&1";
  FILE* pipe = ::popen(full.c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buf{};
  std::string out;
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), n);
  const int status = ::pclose(pipe);
  if (output) *output = out;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

std::string BouncefitExe() { return fmt::format("'{}'", BOUNCEFIT_EXE); }

std::string ShortDropClip() {
  const auto dir = std::filesystem::current_path() / "scratch" / "short_drop_clip";
  const std::string path = (dir / "drop.avi").string();
  if (std::filesystem::exists(path)) return path;
  std::filesystem::create_directories(dir);
  const std::string tmp = (dir / ("drop." + std::to_string(::getpid()) + ".avi")).string();
  std::string out;
  const int rc = RunCommand(BouncefitExe() + " synth --duration 1.5 --fps 120 --size 320x240 "
                                             "--drop-height 0.5 -q -o '" + tmp + "'", &out);
  EXPECT_EQ(rc, 0) << out;
  std::filesystem::rename(tmp, path);
  return path;
}

std::vector<double> DropHeights(const BallPreset& ball, double drop, int n) {
  PointMassDropConfig c;
  c.ball = ball;
  c.drop_height_m = drop;
  c.end_time_s = 20;
  const auto r = SimulatePointMassDrop(c);
  std::vector<double> h{drop};
  for (size_t i = 1; i < r.apex_heights_m.size() && static_cast<int>(h.size()) <= n; ++i)
    h.push_back(r.apex_heights_m[i]);
  return h;
}

std::filesystem::path RealClipsDir() {
  std::filesystem::path dir = BOUNCEFIT_REAL_CLIPS_DIR;
  return std::filesystem::exists(dir) ? dir : std::filesystem::path();
}

std::string UniqueUdpmUrl() {
  const int port = 20000 + static_cast<int>(::getpid() % 20000);
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
}

std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::map<std::string, std::string>> ReadCsv(const std::filesystem::path& path) {
  std::ifstream f(path);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& s) {
    std::vector<std::string> cells;
    std::stringstream ss(s);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (!s.empty() && s.back() == ',') cells.push_back("");
    return cells;
  };
  if (std::getline(f, line)) header = split(line);
  while (std::getline(f, line)) {
    const auto cells = split(line);
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < header.size(); ++i) row[header[i]] = i < cells.size() ? cells[i] : "";
    rows.push_back(row);
  }
  return rows;
}

}  // namespace bouncefit::testing
