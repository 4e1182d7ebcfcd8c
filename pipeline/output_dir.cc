#include "pipeline/output_dir.h"

#include <fstream>
#include <stdexcept>

namespace bouncefit {

const std::vector<std::string>& CaptureOutputFiles() {
  static const std::vector<std::string> files = {"track.csv", "session.lcm", "waveform.csv"};
  return files;
}

const std::vector<std::string>& DetectOutputFiles() {
  static const std::vector<std::string> files = {"peaks.csv", "impacts.csv", "calibration.json",
                                                 "summary.json"};
  return files;
}

const std::vector<std::string>& FitOutputFiles() {
  static const std::vector<std::string> files = {"fit.jsonl", "coefficients.json", "simulated.csv",
                                                 "fitted_ball", "fitted_ball.glb", "drops.csv"};
  return files;
}

std::vector<std::string> RunOutputFiles() {
  std::vector<std::string> all = CaptureOutputFiles();
  for (const auto* list : {&DetectOutputFiles(), &FitOutputFiles()}) all.insert(all.end(), list->begin(), list->end());
  // What `report DIR` draws from them.
  for (const char* f : {"report.html", "report_plots", "report_*.png"}) all.push_back(f);
  return all;
}

namespace {

// The entries of `dir` that `name` names: itself, or with a trailing '*' every entry it begins.
std::vector<std::filesystem::path> Matches(const std::filesystem::path& dir, const std::string& name) {
  std::vector<std::filesystem::path> out;
  if (name.empty() || name.back() != '*') {
    if (std::filesystem::exists(dir / name)) out.push_back(dir / name);
    return out;
  }
  const std::string prefix = name.substr(0, name.size() - 1);
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().filename().string().rfind(prefix, 0) == 0) out.push_back(e.path());
  return out;
}

}  // namespace

void ClaimOutputDir(const std::filesystem::path& dir, const std::vector<std::string>& clear,
                    bool overwrite) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create output directory '" + dir.string() + "': " + ec.message());
  std::string found;
  std::vector<std::filesystem::path> there;
  for (const auto& f : clear)
    for (const auto& p : Matches(dir, f)) {
      there.push_back(p);
      found += (found.empty() ? "" : ", ") + p.filename().string();
    }
  if (found.empty()) return;
  if (!overwrite)
    throw std::runtime_error(dir.string() + " holds an earlier run (" + found +
                             "): --overwrite clears it first, or choose another --out");
  for (const auto& p : there) {
    std::filesystem::remove_all(p, ec);
    if (ec) throw std::runtime_error("cannot remove '" + p.string() + "': " + ec.message());
  }
}

void RemoveOutputFiles(const std::filesystem::path& dir, const std::vector<std::string>& files) {
  std::error_code ec;
  for (const auto& f : files)
    for (const auto& p : Matches(dir, f)) std::filesystem::remove_all(p, ec);
}

void WriteJsonAtomically(const std::filesystem::path& path, const nlohmann::json& j) {
  const std::string tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    if (!f) throw std::runtime_error("cannot write '" + tmp + "'");
    f << j.dump(2) << '\n';
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace bouncefit
