#include "fit/fit_notes.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "model/bounce_standard.h"

namespace bouncefit {

namespace {

double Value(const CoefficientValues& v, const std::string& name) {
  auto it = v.find(name);
  return it == v.end() ? std::nan("") : it->second;
}

}  // namespace

double FittedRestitutionAt(const CoefficientValues& values, double v) {
  double e0 = Value(values, "rebound_restitution"), k = Value(values, "rebound_restitution_per_mps");
  if (!(e0 > 0)) e0 = Value(values, "restitution"), k = Value(values, "restitution_per_mps");
  if (!std::isfinite(e0) || !(e0 > 0)) return std::nan("");
  if (!std::isfinite(k)) k = 0;
  return std::clamp(e0 - k * v, 0.0, 1.0);
}

std::vector<std::string> FinalFitNotices(const FitUpdate& u, const BallPreset& ball) {
  std::vector<std::string> out;
  if (!u.no_answer.empty()) out.push_back("no fit: " + u.no_answer);
  if (u.start_bounce > 0)
    out.push_back("fit: started from apex #" + std::to_string(u.start_bounce) +
                  " (the release was not seen: the ball at that height, at rest vertically)");
  for (const auto& h : u.held) out.push_back("fit: " + h);
  for (const auto& b : u.restitution.suspect) out.push_back("fit: doubtful " + b);
  const RestitutionConsistency& r = u.restitution;
  if (r.drop_e.size() > 1 && r.drops_agree) {
    std::string each;
    for (size_t d = 0; d < r.drop_e.size(); ++d)
      each += fmt::format("{}drop {} {:.3f} +- {:.3f}", d ? ", " : "", d + 1, r.drop_e[d], r.drop_e_sigma[d]);
    out.push_back(fmt::format("fit: the drops agree: e at {:.1f} m/s is {}", r.reference_mps, each));
  }
  if (!u.warning.empty()) out.push_back("fit: warning: " + u.warning);
  const double e1 = FittedRestitutionAt(u.values, 1.0), e4 = FittedRestitutionAt(u.values, 4.0);
  if (std::isfinite(e1)) {
    std::string line = fmt::format("fit: restitution e {:.2f} at 1 m/s, {:.2f} at 4 m/s", e1, e4);
    if (const auto s = BounceStandardOf(ball.name)) {
      const StandardRestitution sr = StandardRestitutionOf(*s, ball);
      const double e = FittedRestitutionAt(u.values, sr.impact_mps);
      line += fmt::format("; {:.2f} at {:.1f} m/s, where the ball's standard ({}: {}) gives {:.2f}-{:.2f} on {}", e,
                          sr.impact_mps, s->body, s->measured, sr.e_lo, sr.e_hi, s->surface) +
              (e < sr.e_lo - 0.15  ? " (far less than a softer floor explains: check the scale, the clock and the ball)"
               : e < sr.e_lo       ? " (a softer floor gives less)"
               : e > sr.e_hi + 0.03 ? " (more than the standard allows: check the scale, the clock and the ball)"
                                    : "");
    }
    out.push_back(line);
  }
  return out;
}

}  // namespace bouncefit
