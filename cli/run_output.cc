#include "cli/run_output.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "msgs/msg_json.h"

namespace bouncefit::cli {
namespace {

std::filesystem::path Prepared(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create output directory '" + dir.string() + "': " +
                                   ec.message());
  return dir;
}

std::ofstream OpenForWrite(const std::filesystem::path& path) {
  std::ofstream f(path, std::ios::trunc);
  if (!f) throw std::runtime_error("cannot write '" + path.string() + "'");
  return f;
}

// Empty cell for unknown values, as docs/FORMATS.md says.
std::string Cell(double v, const char* format) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// A reader never sees half a file: write a temporary, then rename over the old one.
void WriteJsonAtomically(const std::filesystem::path& path, const nlohmann::json& j) {
  const std::string tmp = path.string() + ".tmp";
  std::ofstream f = OpenForWrite(tmp);
  f << j.dump(2) << '\n';
  f.close();
  std::filesystem::rename(tmp, path);
}

}  // namespace

RunOutput::RunOutput(const std::filesystem::path& dir)
    : dir_(Prepared(dir)),
      track_(OpenForWrite(dir_ / "track.csv")),
      peaks_(OpenForWrite(dir_ / "peaks.csv")),
      fits_(OpenForWrite(dir_ / "fit.jsonl")),
      log_((dir_ / "session.lcm").string()) {
  track_ << "frame,t_s,found,cx_px,cy_px,x_px,y_px,w_px,h_px,camera_dx_px,camera_dy_px\n" << std::flush;
  peaks_ << "bounce,t_s,height_m,height_px,flight_height_m,emitted_t_s\n" << std::flush;
}

void RunOutput::OnBox(const ball_box_t& m) {
  track_ << m.frame << ',' << Cell(SecondsSince(m.utime, t0_), "%.6f") << ','
         << (m.found ? 1 : 0);
  if (m.found) {
    track_ << ',' << Cell(m.cx, "%.3f") << ',' << Cell(m.cy, "%.3f") << ','
           << Cell(m.x, "%.0f") << ',' << Cell(m.y, "%.0f") << ',' << Cell(m.w, "%.0f") << ','
           << Cell(m.h, "%.0f");
  } else {
    track_ << ",,,,,,";
  }
  track_ << ',' << Cell(m.camera_dx, "%.2f") << ',' << Cell(m.camera_dy, "%.2f") << '\n';
  track_.flush();
}

void RunOutput::OnCalibration(const calibration_t& m) {
  WriteJsonAtomically(dir_ / "calibration.json", ToJson(m, t0_));
}

void RunOutput::OnPeak(const bounce_peak_t& m) {
  peaks_ << m.bounce << ',' << Cell(SecondsSince(m.apex_utime, t0_), "%.6f") << ','
         << Cell(m.height_m, "%.5f") << ',' << Cell(m.height_px, "%.3f") << ','
         << Cell(m.flight_height_m, "%.5f") << ','
         << Cell(SecondsSince(m.emitted_utime, t0_), "%.6f") << '\n';
  peaks_.flush();
}

void RunOutput::OnFit(const fit_update_t& m, int64_t published_utime) {
  auto j = ToJson(m, t0_);
  j["published_t_s"] = SecondsSince(published_utime, t0_);
  fits_ << j.dump() << '\n';
  fits_.flush();
}

void RunOutput::WriteSummary(const nlohmann::json& summary) {
  WriteJsonAtomically(dir_ / "summary.json", summary);
}

std::pair<int64_t, int64_t> RunOutput::CloseLog() {
  log_.Close();
  return {log_.written(), log_.dropped()};
}

void WriteSimulatedCsv(const std::filesystem::path& dir, double t_release_s,
                       const std::vector<TrajectorySample>& trajectory) {
  std::ofstream f(dir / "simulated.csv", std::ios::trunc);
  f << "t_s,height_m\n";
  for (const auto& s : trajectory)
    f << Cell(t_release_s + s.t_s, "%.6f") << ',' << Cell(s.bottom_height_m, "%.5f") << '\n';
}

}  // namespace bouncefit::cli
