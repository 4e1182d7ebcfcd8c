#include "fit/recorded_drop.h"

#include <algorithm>
#include <limits>

namespace bouncefit {

RecordedDrop::RecordedDrop(double min_bounce_height_m, double default_sigma_m)
    : min_bounce_height_m_(min_bounce_height_m), default_sigma_m_(default_sigma_m) {}

void RecordedDrop::Clear() {
  apexes_.clear();
  start_bounce_ = 0;
  drop_height_m_ = 0;
  heights_.clear();
  sigmas_.clear();
  impacts_before_.clear();
  fitted_heights_.clear();
  fitted_flights_.clear();
  flight_clock_ratio_ = std::nan("");
}

void RecordedDrop::Add(int bounce, const Apex& apex) {
  apexes_[bounce] = apex;
  ChooseStart();
  MeasureFlights();
}

void RecordedDrop::ChooseStart() {
  // Runs of consecutive bounces, each apex high enough to fit and none higher than the one
  // before it (a ball picked up and dropped again, or a lock on something else, is not a
  // rebound); bounce 0 (the release) starts a run at any height. The start is the release
  // when it begins a run with a rebound after it, else the first apex of the longest run
  // (the earliest of equal ones).
  const double min_h = min_bounce_height_m_;
  auto usable = [&](int b) {
    auto it = apexes_.find(b);
    return it != apexes_.end() && (b == 0 || it->second.height_m >= min_h);
  };
  auto follows = [&](int b) {  // apex b is a rebound of apex b - 1
    return b > 0 && usable(b) && usable(b - 1) &&
           apexes_.at(b).height_m <= 1.05 * apexes_.at(b - 1).height_m + 0.002;
  };
  int best_start = -1, best_len = 0;
  for (const auto& [b, a] : apexes_) {
    if (!usable(b) || follows(b)) continue;  // not a run's first apex
    int len = 0;
    while (follows(b + len + 1)) ++len;
    const bool release = b == 0 && len > 0;
    if (release) {
      best_start = 0, best_len = len;
      break;
    }
    if (best_start < 0 || len > best_len) best_start = b, best_len = len;
  }
  heights_.clear();
  sigmas_.clear();
  impacts_before_.clear();
  if (best_start < 0) {
    start_bounce_ = 0;
    drop_height_m_ = 0;
    return;
  }
  start_bounce_ = best_start;
  drop_height_m_ = apexes_.at(best_start).height_m;
  for (int b = best_start + 1; b <= best_start + best_len; ++b) {
    const Apex& a = apexes_.at(b);
    heights_.push_back(a.height_m);
    sigmas_.push_back(a.sigma_m);
    impacts_before_.push_back(a.impact_before_s);
  }
  // The flight of the last arc needs the next bounce's impact_before, when that bounce was
  // seen (below the minimum or not) and is a rebound of it.
  auto next = apexes_.find(best_start + best_len + 1);
  if (next != apexes_.end() && next->second.height_m <= 1.05 * apexes_.at(best_start + best_len).height_m + 0.002)
    impacts_before_.push_back(next->second.impact_before_s);
}

void RecordedDrop::MeasureFlights() {
  fitted_heights_.clear();
  for (double h : heights_) {
    if (!std::isfinite(h) || h < min_bounce_height_m_) break;
    fitted_heights_.push_back(h);
  }
  const std::vector<double>& h = fitted_heights_;
  const size_t k = h.size();
  std::vector<double> f(k, std::numeric_limits<double>::quiet_NaN());
  for (size_t i = 0; i < k && i + 1 < impacts_before_.size(); ++i)
    f[i] = impacts_before_[i + 1] - impacts_before_[i];  // NaN when either is
  // Flights on another clock than the heights' (a slow-motion file's impacts on its slowed
  // timeline, heights from the real one): the flight a height gives, 2 sqrt(2 h / g) drag
  // aside, against the recorded one. Far off by their median: the heights alone are fitted.
  std::vector<double> ratios;
  for (size_t i = 0; i < k; ++i)
    if (std::isfinite(f[i]) && h[i] > 0) ratios.push_back(f[i] / (2 * std::sqrt(2 * h[i] / 9.81)));
  flight_clock_ratio_ = std::nan("");
  if (!ratios.empty()) {
    std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
    const double median = ratios[ratios.size() / 2];
    if (median < 0.8 || median > 1.2) {
      flight_clock_ratio_ = median;
      std::fill(f.begin(), f.end(), std::numeric_limits<double>::quiet_NaN());
    }
  }
  fitted_flights_ = std::move(f);
}

double RecordedDrop::StartFall() const {
  if (impacts_before_.empty() || !apexes_.count(start_bounce_)) return std::nan("");
  const double fall = impacts_before_[0] - apexes_.at(start_bounce_).apex_s;  // NaN when either is
  return fall > 0 ? fall : std::nan("");
}

double RecordedDrop::MeasurementSigma() const {
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < fitted_heights_.size(); ++i)
    if (sigmas_[i] > 0) sum += sigmas_[i] * sigmas_[i], ++n;
  return n ? std::sqrt(sum / n) : default_sigma_m_;
}

KeptDrop RecordedDrop::Keep() const {
  const std::vector<double>& heights = fitted_heights_;
  std::vector<double> sigmas{apexes_.at(start_bounce_).sigma_m};
  sigmas.insert(sigmas.end(), sigmas_.begin(), sigmas_.begin() + static_cast<long>(heights.size()));
  return {drop_height_m_, heights, fitted_flights_, sigmas, start_bounce_};
}

std::vector<RestitutionPoint> DropsRestitution(const std::vector<KeptDrop>& drops,
                                               const CoefficientValues& values, double air_per_m_per_cd,
                                               double default_sigma_m) {
  double cd = 0;
  for (const char* name : {"drag", "drag_coefficient"})
    if (values.count(name)) cd = values.at(name);
  const double c = air_per_m_per_cd * cd;
  std::vector<RestitutionPoint> out;
  int numbered = 0;
  for (const KeptDrop& d : drops) {
    std::vector<double> apexes{d.drop_height_m};
    apexes.insert(apexes.end(), d.heights_m.begin(), d.heights_m.end());
    const auto points = MeasureRestitution(apexes, d.sigmas_m, c, numbered, d.start_bounce, default_sigma_m);
    out.insert(out.end(), points.begin(), points.end());
    numbered += !points.empty();
  }
  return out;
}

}  // namespace bouncefit
